// octoray_bench_quantisation: the octree's geometric error against its
// depth. For each leaf depth, the largest and the mean distance from a point
// to the centre of its leaf voxel (data units), beside the build time, the
// node count and the engine's memory, on three scenes:
//   ct      a CT stack as points (a particle file, --ct PATH; the report
//           writes Data/DICOM/CT5N through vtkSliceStackReader and
//           vtkParticleTextWriter),
//   lidar   the bundled LiDAR tile (Data/Particles/lidar_simple.particles),
//   spheres the synthetic sphere field of the render benchmark.
// The distances are measured on the engine's own octree (Quantisation.h)
// and checked against the analytic bound, half the leaf voxel's diagonal;
// a distance past it fails the run. Where the scene has 8-bit colours,
// scalars, normals or reflectivity, their rounding in the nodes (to bytes;
// to 16 bits over the range; to the octahedron's 4-byte code; the points'
// reflectivities to 16-bit unit steps) is measured too, against the exact
// means, and checked against its bound (Attributes.h).
//
//   octoray_bench_quantisation [--backend cpu|cuda] [--depths 1-21]
//                              [--ct PATH] [--lidar PATH] [--sphere-points N]
//                              [--repeats 3] [--json PATH]
#include "BenchScenes.h"
#include "BenchUtil.h"
#include "CommandLine.h"
#include "PointFile.h"
#include <octoray/Quantisation.h>

#include <octoray/Engine.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace
{
using namespace octoray;
using namespace octoray::bench;

// The usage, printed for --help or -h and after a wrong argument.
constexpr const char* kUsage =
    "usage: octoray_bench_quantisation [--backend cpu|cuda] [--depths FIRST-LAST] [--ct PATH] [--lidar PATH]\n"
    "                                  [--sphere-points N] [--repeats R] [--json PATH]\n";

struct Scene
{
  std::string name;
  PointCloudView points;
};
}

int main(int argc, char** argv)
{
  std::string backend = "cpu", ct, lidar = OCTORAY_LIDAR_FILE, json;
  int first = 1, last = kMaxLevel, repeats = 3;
  std::size_t spherePoints = 200000;
  CommandLine options;
  options.Choice("--backend", backend, { "cpu", "cuda" })
    .Option("--depths", "a range FIRST-LAST within 1-" + std::to_string(kMaxLevel),
      [&](const std::string& v) {
        char rest = 0;
        return std::sscanf(v.c_str(), "%d-%d%c", &first, &last, &rest) == 2 && first >= 1 && last <= kMaxLevel &&
          first <= last;
      })
    .Text("--ct", ct)
    .Text("--lidar", lidar)
    .Count("--sphere-points", spherePoints)
    .Integer("--repeats", repeats, 1)
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
    std::printf("octoray_bench_quantisation: %s; build time median of %d after a warm-up\n",
      engine->Description().c_str(), repeats);

    PointFile ctFile, lidarFile = PointFile::Load(lidar);
    const SphereField spheres = MakeSphereField(spherePoints);
    std::vector<Scene> scenes;
    if (!ct.empty())
    {
      ctFile = PointFile::Load(ct);
      scenes.push_back({ "ct", ctFile.View() });
    }
    scenes.push_back({ "lidar", lidarFile.View() });
    scenes.push_back({ "spheres", spheres.View(true, true) });

    std::vector<Record> records;
    bool withinBound = true;
    for (const Scene& scene : scenes)
    {
      std::printf("\nscene %s, %zu points\n", scene.name.c_str(), scene.points.count);
      std::printf("| depth | leaf side | max distance | mean distance | bound | max/bound | nodes | build ms | MB | "
                  "colour steps leaf / inner / bound | scalar steps leaf / inner / bound | "
                  "normal distance x1e-3 leaf / inner / bound | reflectivity x1e-6 leaf / inner / bound |\n");
      std::printf("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
      for (int depth = first; depth <= last; ++depth)
      {
        // A fresh engine per depth: one reused across depths keeps the
        // largest buffers it ever needed, and its memory would not be this
        // depth's.
        engine = CreateEngine(backend == "cuda" ? Backend::CUDA : Backend::CPU);
        BuildOptions options;
        options.depth = depth;
        BuildStats stats;
        const Timing t = Measure([&] { stats = engine->Build(scene.points, options); }, 1, repeats);
        HostOctree tree;
        engine->CopyToHost(tree);
        const QuantisationError q = MeasureQuantisation(tree, scene.points);
        const double bytes = double(engine->Memory().Total());
        const bool colours = !tree.color8.empty(), scalars = !tree.scalar.empty(), normals = !tree.normal.empty();
        const bool mirrors = !tree.reflectivity.empty();
        const RoundingError colour = colours ? MeasureColourQuantisation(tree, scene.points) : RoundingError{};
        const RoundingError scalar = scalars ? MeasureScalarQuantisation(tree, scene.points) : RoundingError{};
        const RoundingError normal = normals ? MeasureNormalQuantisation(tree, scene.points) : RoundingError{};
        const RoundingError mirror = mirrors ? MeasureReflectivityQuantisation(tree, scene.points) : RoundingError{};
        // The bound, less a relative 1e-12 for the rounding of the centre.
        const bool ok = q.max <= q.bound * (1 + 1e-12) && colour.withinBound && scalar.withinBound &&
          normal.withinBound && mirror.withinBound;
        withinBound = withinBound && ok;
        char colourText[64] = "-", scalarText[64] = "-", normalText[64] = "-", mirrorText[64] = "-";
        if (colours)
        {
          std::snprintf(colourText, sizeof colourText, "%.3f / %.3f / %.1f", colour.leafMax, colour.innerMax,
            colour.rootBound);
        }
        if (scalars)
        {
          std::snprintf(scalarText, sizeof scalarText, "%.3f / %.3f / %.1f", scalar.leafMax, scalar.innerMax,
            scalar.rootBound);
        }
        if (normals)
        {
          std::snprintf(normalText, sizeof normalText, "%.2f / %.2f / %.1f", 1e3 * normal.leafMax,
            1e3 * normal.innerMax, 1e3 * normal.rootBound);
        }
        if (mirrors)
        {
          std::snprintf(mirrorText, sizeof mirrorText, "%.2f / %.2f / %.1f", 1e6 * mirror.leafMax,
            1e6 * mirror.innerMax, 1e6 * mirror.rootBound);
        }
        std::printf("| %d | %.6g | %.6g | %.6g | %.6g | %.3f | %zu | %.2f | %.2f | %s | %s | %s | %s |%s\n", depth,
          q.leafSide, q.max, q.mean, q.bound, q.max / q.bound, stats.nodes, t.median * 1e3, bytes / 1e6, colourText,
          scalarText, normalText, mirrorText, ok ? "" : " PAST THE BOUND");
        std::fflush(stdout);
        Record r{ "quantisation/" + scene.name, backend, scene.points.count, depth, t.median, "", 0.0 };
        r.With("max_distance", q.max)
          .With("mean_distance", q.mean)
          .With("bound", q.bound)
          .With("leaf_side", q.leafSide)
          .With("cube_size", tree.cube.size)
          .With("nodes", double(stats.nodes))
          .With("bytes", bytes)
          .With("min_seconds", t.min);
        if (colours)
        {
          r.With("colour_leaf_steps", colour.leafMax)
            .With("colour_inner_steps", colour.innerMax)
            .With("colour_root_bound_steps", colour.rootBound);
        }
        if (scalars)
        {
          r.With("scalar_leaf_steps", scalar.leafMax)
            .With("scalar_inner_steps", scalar.innerMax)
            .With("scalar_root_bound_steps", scalar.rootBound)
            .With("scalar_range", double(tree.scalarRange.hi) - tree.scalarRange.lo);
        }
        if (normals)
        {
          r.With("normal_leaf_distance", normal.leafMax)
            .With("normal_inner_distance", normal.innerMax)
            .With("normal_root_bound", normal.rootBound);
        }
        if (mirrors)
        {
          r.With("reflectivity_leaf_error", mirror.leafMax)
            .With("reflectivity_inner_error", mirror.innerMax)
            .With("reflectivity_root_bound", mirror.rootBound);
        }
        records.push_back(r);
      }
    }
    SaveRecords(json, records);
    if (!withinBound)
    {
      std::fprintf(stderr, "octoray_bench_quantisation: a distance exceeds half the leaf diagonal, or a colour, "
                           "a scalar, a normal or a reflectivity its bound\n");
      return 1;
    }
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "octoray_bench_quantisation: %s\n", e.what());
    return 1;
  }
  return 0;
}
