// octoray_bench_thesis: the 2015 thesis's timings again, on this engine and
// either backend, with the thesis's scenes and settings:
//   - table 2: thresholded slice-stack clouds of 30 641 to 3 283 639 points
//     (BenchScenes.h, the generator octoray_bench_cuda uses), depth 7,
//     800x600 rays, Phong: build (whole call), ray tracing per image, memory;
//   - two spheres: two solid spheres of grid points, one a mirror, depth 7,
//     800x600: build, Phong, and Phong with a shadowed light and one bounce.
// Build: median of the repeats after a warm-up on one engine (buffers
// reused, as the thesis rebuilt per frame); trace: RenderStats.seconds, the
// frame up to the picture in the backend's memory (CUDA: left on the
// device), median of the repeats after a warm-up frame.
//
//   octoray_bench_thesis [--backend cpu|cuda] [--repeats 5]
//                        [--sphere-points 1000000] [--json PATH]
#include "BenchScenes.h"
#include "BenchUtil.h"
#include "CommandLine.h"

#include <octoray/Engine.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace
{
using namespace octoray;
using namespace octoray::bench;

// The usage, printed for --help or -h and after a wrong argument.
constexpr const char* kUsage =
    "usage: octoray_bench_thesis [--backend cpu|cuda] [--repeats R] [--sphere-points N] [--json PATH]\n";

// A build's record: its median, fastest time, memory and nodes (depth 7, the
// thesis's).
Record BuildRecord(const char* name, const std::string& backend, std::size_t n, const Timing& build, double bytes,
  std::size_t nodes)
{
  return Record{ name, backend, n, 7, build.median, "", 0.0 }
    .With("bytes", bytes)
    .With("nodes", double(nodes))
    .With("min_seconds", build.min);
}

// Median frame time from the engine's own RenderStats after a warm-up frame.
Timing TraceTime(Engine& engine, const RenderSettings& s, int repeats, RenderStats& stats)
{
  Image image;
  engine.Render(s, image);
  std::vector<double> seconds;
  for (int r = 0; r < repeats; ++r)
  {
    stats = engine.Render(s, image);
    seconds.push_back(stats.seconds);
  }
  return Summarise(std::move(seconds));
}
}

// Builds `c` at the thesis's depth 7 (median of `repeats` after a warm-up)
// and returns the thesis's view of it: 800x600, Phong, the picture left in
// the backend's memory.
RenderSettings BuildThesisScene(
  Engine& engine, const ColouredCloud& c, int repeats, Timing& build, BuildStats& stats)
{
  BuildOptions o;
  o.depth = 7;
  build = Measure([&] { stats = engine.Build(c.View(), o); }, 1, repeats);
  HostOctree t;
  engine.CopyToHost(t);
  RenderSettings s = CubeCamera(t.cube, 800, 600);
  s.shade = ShadeMode::Phong;
  s.copyToHost = false;
  return s;
}

int main(int argc, char** argv)
{
  std::string backend = "cpu", json;
  int repeats = 5;
  std::size_t spherePoints = 1000000;
  CommandLine options;
  options.Choice("--backend", backend, { "cpu", "cuda" })
    .Integer("--repeats", repeats, 1)
    .Count("--sphere-points", spherePoints)
    .Text("--json", json);
  if (const std::optional<int> stop = options.ParseOrStop(argc, argv, kUsage))
  {
    return *stop;
  }

  try
  {
    std::unique_ptr<Engine> engine = RequestedEngine(backend);
    if (!engine)
    {
      return 0;
    }
    const std::string name = engine->Description();
    std::printf("octoray_bench_thesis: %s; medians of %d after a warm-up\n", name.c_str(), repeats);
    std::vector<Record> records;

    std::printf("\nthesis table 2 (depth 7, 800x600, Phong)\n");
    std::printf("| points | build ms | trace ms / image | memory MB |\n| ---: | ---: | ---: | ---: |\n");
    for (const std::size_t n : ThesisTable2Counts())
    {
      const ColouredCloud c = ThesisSliceStack(n);
      Timing build;
      BuildStats stats;
      const RenderSettings s = BuildThesisScene(*engine, c, repeats, build, stats);
      RenderStats rs;
      const Timing trace = TraceTime(*engine, s, repeats, rs);
      const double bytes = double(engine->Memory().Total());
      std::printf("| %zu | %.2f | %.2f | %.1f |\n", c.Size(), build.median * 1e3, trace.median * 1e3, bytes / 1e6);
      std::fflush(stdout);
      records.push_back(BuildRecord("thesis/table2/build", backend, c.Size(), build, bytes, stats.nodes));
      records.push_back(Record{ "thesis/table2/trace_800x600", backend, c.Size(), 7, trace.median, "", 0.0 }
                          .With("min_seconds", trace.min)
                          .With("rays", double(rs.primaryRays + rs.secondaryRays)));
    }

    {
      // A fresh engine: its memory is then this scene's alone.
      engine = CreateEngine(backend == "cuda" ? Backend::CUDA : Backend::CPU);
      const ColouredCloud c = TwoSpheres(spherePoints);
      Timing build;
      BuildStats stats;
      RenderSettings s = BuildThesisScene(*engine, c, repeats, build, stats);
      s.maxBounces = 0;
      RenderStats phongStats, fullStats;
      const Timing phong = TraceTime(*engine, s, repeats, phongStats);
      Light sun;
      sun.position[0] = 1, sun.position[1] = -1, sun.position[2] = 2, sun.position[3] = 0;
      s.lights.push_back(sun);
      s.shadows = true;
      s.maxBounces = 1;
      const Timing full = TraceTime(*engine, s, repeats, fullStats);
      const double bytes = double(engine->Memory().Total());
      std::printf("\ntwo spheres, %zu points, depth 7, %zu nodes, 800x600: build %.2f ms; Phong %.2f ms / image; "
                  "Phong + shadows + 1 bounce %.2f ms / image (%zu secondary rays); %.1f MB\n",
        c.Size(), stats.nodes, build.median * 1e3, phong.median * 1e3, full.median * 1e3, fullStats.secondaryRays,
        bytes / 1e6);
      records.push_back(BuildRecord("thesis/two_spheres/build", backend, c.Size(), build, bytes, stats.nodes));
      records.push_back(Record{ "thesis/two_spheres/phong_800x600", backend, c.Size(), 7, phong.median, "", 0.0 }
                          .With("min_seconds", phong.min)
                          .With("rays", double(phongStats.primaryRays + phongStats.secondaryRays)));
      records.push_back(
        Record{ "thesis/two_spheres/shadows_bounce_800x600", backend, c.Size(), 7, full.median, "", 0.0 }
          .With("min_seconds", full.min)
          .With("rays", double(fullStats.primaryRays + fullStats.secondaryRays)));
    }

    SaveRecords(json, records);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "octoray_bench_thesis: %s\n", e.what());
    return 1;
  }
  return 0;
}
