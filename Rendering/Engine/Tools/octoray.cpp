// octoray: the engine's command-line tool.
//   octoray stats FILE [--depth N] [--backend cpu|cuda|auto] [--threads N]
// builds the octree of a particle file and prints its statistics and costs.
#include "PointFile.h"

#include <octoray/Engine.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>

namespace
{
int Usage()
{
  std::fprintf(stderr,
    "usage: octoray stats FILE [--depth N] [--backend cpu|cuda|auto] [--threads N]\n"
    "  builds the octree of a particle file (3, 4, 6 or 8 columns) and prints its statistics\n");
  return 2;
}
}

int main(int argc, char** argv)
{
  if (argc < 3 || std::strcmp(argv[1], "stats") != 0)
  {
    return Usage();
  }
  const std::string path = argv[2];
  octoray::BuildOptions options;
  std::string backend = "auto";
  int threads = 0;
  for (int a = 3; a < argc; ++a)
  {
    const std::string arg = argv[a];
    if (a + 1 >= argc)
    {
      return Usage();
    }
    if (arg == "--depth")
    {
      options.depth = std::atoi(argv[++a]);
    }
    else if (arg == "--backend")
    {
      backend = argv[++a];
    }
    else if (arg == "--threads")
    {
      threads = std::atoi(argv[++a]);
    }
    else
    {
      return Usage();
    }
  }
  try
  {
    const auto t0 = std::chrono::steady_clock::now();
    const octoray::PointFile file = octoray::PointFile::Load(path);
    const double loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    std::string why;
    const bool useCuda = backend == "cuda" || (backend == "auto" && octoray::CudaAvailable(&why));
    auto engine = octoray::CreateEngine(useCuda ? octoray::Backend::CUDA : octoray::Backend::CPU);
    if (threads > 0)
    {
      engine->SetThreadCount(threads);
    }
    const octoray::BuildStats stats = engine->Build(file.View(), options);
    const octoray::MemoryReport memory = engine->Memory();

    std::printf("file            %s (%zu points, read in %.3f s)\n", path.c_str(), stats.points, loadSeconds);
    std::printf("backend         %s%s%s\n", engine->Description().c_str(),
      (!useCuda && backend == "auto") ? ", CUDA not used: " : "", (!useCuda && backend == "auto") ? why.c_str() : "");
    std::printf("depth           %d%s\n", stats.depth, options.depth ? "" : " (automatic)");
    std::printf("nodes           %zu\n", stats.nodes);
    std::printf("nodes per level");
    for (std::size_t l = 0; l < stats.nodesPerLevel.size(); ++l)
    {
      std::printf(" %u", stats.nodesPerLevel[l]);
    }
    std::printf("\n");
    std::printf("build           %.3f ms (keys %.3f, sort %.3f, levels %.3f)\n", stats.seconds * 1e3,
      stats.keySeconds * 1e3, stats.sortSeconds * 1e3, stats.levelSeconds * 1e3);
    std::printf("memory          %zu bytes, %.1f bytes per point\n", memory.Total(),
      static_cast<double>(memory.Total()) / static_cast<double>(stats.points));
    for (const auto& array : memory.arrays)
    {
      std::printf("  %-24s %zu\n", array.first.c_str(), array.second);
    }
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
