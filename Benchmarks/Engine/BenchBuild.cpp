// octoray_bench_build: how long the engine takes to build the octree, on the
// CPU with one thread and with all of them, and on CUDA where a GPU is
// usable. Engine only (no VTK, no PCL), so it runs on a GPU machine too; the
// comparison with PCL and VTK is octoray_bench_peers.
//
//   octoray_bench_build [--points 1000000,10000000] [--sets uniform,clustered,narrow]
//                       [--depth 0] [--backend cpu|cuda|all] [--threads N]
//                       [--repeats 5] [--json PATH]
#include "BenchUtil.h"
#include "CommandLine.h"

#include <octoray/Engine.h>
#include <octoray/Octree.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <numeric>
#include <sstream>
#include <thread>

namespace
{
using namespace octoray;
using namespace octoray::bench;

// The usage, printed for --help or -h and after a wrong argument.
constexpr const char* kUsage =
    "usage: octoray_bench_build [--points N[,N...]] [--sets uniform,clustered,narrow] [--depth L (0: automatic)]\n"
    "                           [--backend cpu|cuda|all] [--threads N] [--repeats R] [--json PATH]\n";


// The clusters' spread of a clustered set: "narrow" clusters, a two-hundredth
// as wide, are so deep that the automatic depth lands on level 17 at 10 M
// points and on 19 at 100 M, and so dense that it sorts full-depth keys
// right after its provisional ones (DepthChoice.h's NextSortDepth).
double SigmaOf(const std::string& set)
{
  return set == "narrow" ? 1e-4 : 0.02;
}

std::string CpuBackendName(int threads)
{
  return "cpu-" + std::to_string(threads) + (threads == 1 ? "thread" : "threads");
}

struct Run
{
  std::string backend;
  std::string description;
  Timing timing;
  BuildStats stats;                 // of the last timed build
  double keySeconds = 0.0;          // medians over the timed builds
  double sortSeconds = 0.0;
  double levelSeconds = 0.0;
  std::size_t engineBytes = 0;      // everything the engine holds
  std::size_t nodeBytes = 0;        // the octree's node arrays alone
};

// How the points spread over the leaves of the engine's octree: the leaf
// loop gives each leaf a thread that walks its points, so a warp of 32
// consecutive leaves runs as long as its longest; laneStepsUsed is the share
// of lane-steps that reach a point (1: every leaf in a warp alike).
struct LeafLengths
{
  std::size_t leaves = 0, median = 0, p99 = 0, most = 0;
  double mean = 0.0, laneStepsUsed = 0.0;
};

LeafLengths MeasureLeafLengths(const Engine& engine)
{
  HostOctree t;
  engine.CopyToHost(t);
  std::vector<std::uint32_t> points(
    t.pointCount.begin() + t.levelBegin[t.depth], t.pointCount.begin() + t.levelBegin[t.depth + 1]);
  LeafLengths l;
  l.leaves = points.size();
  if (points.empty())
  {
    return l;
  }
  double used = 0.0, run = 0.0;
  for (std::size_t w = 0; w < points.size(); w += 32)
  {
    const auto warp = points.begin() + static_cast<std::ptrdiff_t>(w);
    const auto end = points.begin() + static_cast<std::ptrdiff_t>(std::min(points.size(), w + 32));
    used += std::accumulate(warp, end, 0.0);
    run += 32.0 * *std::max_element(warp, end);
  }
  l.mean = used / points.size();
  l.laneStepsUsed = used / run;
  std::sort(points.begin(), points.end());
  l.median = points[points.size() / 2];
  l.p99 = points[points.size() * 99 / 100];
  l.most = points.back();
  return l;
}

Run Time(Engine& engine, const std::string& backend, const PointCloudView& cloud, const BuildOptions& options,
  int repeats)
{
  Run run;
  run.backend = backend;
  run.description = engine.Description();
  std::vector<double> keys, sorts, levels;
  bool warm = false;
  run.timing = Measure(
    [&] {
      run.stats = engine.Build(cloud, options);
      if (warm)
      {
        keys.push_back(run.stats.keySeconds);
        sorts.push_back(run.stats.sortSeconds);
        levels.push_back(run.stats.levelSeconds);
      }
      warm = true; // the first call is Measure's warm-up
    },
    1, repeats);
  run.keySeconds = Summarise(keys).median;
  run.sortSeconds = Summarise(sorts).median;
  run.levelSeconds = Summarise(levels).median;
  const MemoryReport memory = engine.Memory();
  run.engineBytes = memory.Total();
  run.nodeBytes = memory.NodeBytes();
  return run;
}
}

int main(int argc, char** argv)
{
  std::vector<std::size_t> counts = { 1000000, 10000000 };
  std::vector<std::string> sets = { "uniform", "clustered" };
  int depth = 0;
  std::string backend = "all";
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  int repeats = 5;
  std::string json;
  CommandLine options;
  options
    .Counts("--points", counts, 1)
    .Option("--sets", "a list of uniform, clustered and narrow",
      [&](const std::string& v) {
        sets = SplitList(v);
        return std::all_of(sets.begin(), sets.end(),
          [](const std::string& set) { return set == "uniform" || set == "clustered" || set == "narrow"; });
      })
    .Integer("--depth", depth)
    .Choice("--backend", backend, { "cpu", "cuda", "all" })
    .Integer("--threads", threads, 1)
    .Integer("--repeats", repeats, 1)
    .Text("--json", json);
  if (const std::optional<int> stop = options.ParseOrStop(argc, argv, kUsage))
  {
    return *stop;
  }

  std::string why;
  const bool cuda = backend != "cpu" && CudaAvailable(&why);
  std::printf("octoray_bench_build: median of %d builds after 1 warm-up; depth %s; %u hardware threads\n",
    repeats, depth ? std::to_string(depth).c_str() : "automatic", std::thread::hardware_concurrency());
  if (backend != "cpu" && !cuda)
  {
    std::printf("CUDA skipped: %s\n", why.c_str());
  }
  // Milliseconds, so that a GPU's phases (tens of microseconds at 10 M points) show.
  std::printf("\n%-10s %-9s %-13s %5s %10s %10s %10s %10s %8s %24s %8s %8s %10s\n", "points", "set", "backend", "depth",
    "leaves", "nodes", "median ms", "min ms", "Mpts/s", "keys/sort/levels ms", "B/pt", "nodeB/pt", "dense");

  std::vector<Record> records;
  try
  {
    for (const std::size_t n : counts)
    {
      for (const std::string& set : sets)
      {
        const std::vector<float> xyz = set == "uniform" ? UniformCube(n) : GaussianClusters(n, 32, SigmaOf(set));
        PointCloudView cloud;
        cloud.count = n;
        cloud.xyzFloat = xyz.data();
        BuildOptions options;
        options.depth = depth;

        std::vector<Run> runs;
        LeafLengths leafLengths;
        if (backend != "cuda")
        {
          auto engine = CreateEngine(Backend::CPU);
          engine->SetThreadCount(1);
          runs.push_back(Time(*engine, CpuBackendName(1), cloud, options, repeats));
          leafLengths = MeasureLeafLengths(*engine);
          if (threads > 1)
          {
            engine->SetThreadCount(threads);
            runs.push_back(Time(*engine, CpuBackendName(threads), cloud, options, repeats));
          }
        }
        if (cuda)
        {
          auto engine = CreateEngine(Backend::CUDA);
          runs.push_back(Time(*engine, "cuda", cloud, options, repeats));
        }

        const Run* single = runs.empty() || runs[0].backend != CpuBackendName(1) ? nullptr : &runs[0];
        for (const Run& run : runs)
        {
          const BuildStats& s = run.stats;
          const std::size_t leaves = s.nodesPerLevel.empty() ? 0 : s.nodesPerLevel.back();
          char phases[64];
          std::snprintf(phases, sizeof phases, "%.3f/%.3f/%.3f", 1e3 * run.keySeconds, 1e3 * run.sortSeconds,
            1e3 * run.levelSeconds);
          std::printf("%-10zu %-9s %-13s %5d %10zu %10zu %10.3f %10.3f %8.1f %24s %8.1f %8.1f %10s\n", n, set.c_str(),
            run.backend.c_str(), s.depth, leaves, s.nodes, 1e3 * run.timing.median, 1e3 * run.timing.min,
            n / run.timing.median * 1e-6, phases, double(run.engineBytes) / n, double(run.nodeBytes) / n,
            HumanBytes(DenseSkeletonBytes(s.depth)).c_str());

          Record r;
          r.name = "octree_build/" + set;
          r.backend = run.backend;
          r.n = n;
          r.depth = s.depth;
          r.seconds = run.timing.median;
          r.With("min_seconds", run.timing.min)
            .With("leaves", double(leaves))
            .With("nodes", double(s.nodes))
            .With("key_seconds", run.keySeconds)
            .With("sort_seconds", run.sortSeconds)
            .With("level_seconds", run.levelSeconds)
            .With("engine_bytes", double(run.engineBytes))
            .With("node_bytes", double(run.nodeBytes))
            .With("dense_skeleton_bytes", DenseSkeletonBytes(s.depth));
          if (single && &run != single)
          {
            // Speed-ups are read against the single-threaded CPU build.
            r.peer = "octoray " + single->backend;
            r.peerSeconds = single->timing.median;
          }
          records.push_back(r);
        }
        for (const Run& run : runs)
        {
          if (single && &run != single)
          {
            std::printf("%-10s %-9s %-13s speed-up over 1 thread: %.2fx (%s)\n", "", "", run.backend.c_str(),
              single->timing.median / run.timing.median, run.description.c_str());
          }
        }
        if (leafLengths.leaves)
        {
          std::printf("%-10s %-9s points a leaf: mean %.2f, median %zu, 99th percentile %zu, most %zu; a thread a "
                      "leaf, warps of 32 leaves use %.0f%% of their lane-steps\n",
            "", "", leafLengths.mean, leafLengths.median, leafLengths.p99, leafLengths.most,
            100.0 * leafLengths.laneStepsUsed);
        }
      }
    }
    std::printf("\nB/pt: all the engine holds (points, keys, sort buffers, nodes) per point; nodeB/pt: the node "
                "arrays alone;\ndense: the thesis's pointer skeleton of the same depth, 8 B x (8^(L+1)-1)/7.\n");
    SaveRecords(json, records);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "octoray_bench_build: %s\n", e.what());
    return 1;
  }
  return 0;
}
