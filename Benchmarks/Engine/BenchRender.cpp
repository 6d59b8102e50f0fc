// octoray_bench_render: how fast the engine ray-traces, per shading and
// blend mode. (What the quality knobs trade in image error for time is
// octoray_bench_quality's table.)
//
//   octoray_bench_render [--size 1920x1080] [--repeats 3] [--threads N]
//                        [--backend cpu|cuda|all] [--lidar PATH]
//                        [--sphere-points N] [--parts modes,off] [--json PATH]
//
// --parts picks what runs: `modes` (throughput per mode and scene), `off`
// (the everything-off frames), `normals` (the sphere field without its
// normals: the time to estimate them from the voxels, and the Phong
// picture by them and by occupancy against the one by the points' own
// radial normals), `traversal` (one core's primary rays in
// packets of eight, through Traverse one by one, and through the plain
// slab-test traversal of ReferenceTraversal.h, in the same run); default
// modes and off. Image error against time is
// octoray_bench_quality's.
//
// Scenes: the bundled LiDAR tile (Data/Particles/lidar_simple.particles, the
// thesis's x y z r g b reflectivity refraction columns) and a synthetic
// field of spheres (points on their surfaces, radial normals, reflectivity
// 0.4). Mrays/s counts primary and secondary (shadow, mirror) rays; the
// time is the median of the repeats after one warm-up frame.
#include "BenchScenes.h"
#include "BenchUtil.h"
#include "CommandLine.h"
#include "OrbitCamera.h"
#include "PointFile.h"

#include <octoray/Engine.h>
#include <octoray/Frame.h>
#include <octoray/PacketTraversal.h>
#include <octoray/ReferenceTraversal.h>
#include <octoray/RenderModes.h>

#include <algorithm>
#include <chrono>
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
    "usage: octoray_bench_render [--size WxH] [--repeats R] [--threads N] [--backend cpu|cuda|all]\n"
    "                            [--lidar PATH] [--sphere-points N] [--parts modes,off] [--json PATH]\n";

using Mode = NamedRenderMode;
const auto& kModes = kRenderModes;

RenderSettings MakeSettings(const PointCloudView& points, int w, int h, const Mode& m, int depth)
{
  RenderSettings s;
  s.width = w;
  s.height = h;
  double lo[3], hi[3];
  Bounds(points, lo, hi);
  OrbitCamera camera;
  camera.zoom = 1.3;
  camera.Apply(lo, hi, s);
  m.ApplyTo(s);
  if (m.shadows)
  {
    Light sun;
    OrbitCamera::Direction(camera.azimuth + 40, camera.elevation + 35, sun.position);
    sun.position[3] = 0;
    s.lights.push_back(sun);
  }
  if (m.blend == BlendMode::Composite)
  {
    // Node colours are opaque; a grey ramp at 30% opacity per 4 leaves of
    // length (over luminance, through the transfer function's scalar-less
    // path is not available, so opacity per unit distance does the work).
    double extent = 0;
    for (int a = 0; a < 3; ++a)
      extent = std::max(extent, hi[a] - lo[a]);
    s.opacityUnitDistance = static_cast<float>(4 * std::ldexp(extent, -depth));
  }
  if (m.blend == BlendMode::Additive)
  {
    s.transfer.range[1] = 0.05f; // path integrals in the unit cube are small
    for (int i = 0; i < 64; ++i)
      s.transfer.table.push_back(Rgba{ i / 63.0f, i / 63.0f, i / 63.0f, 1.0f });
  }
  return s;
}

double MraysPerSecond(const RenderStats& stats, double seconds)
{
  return static_cast<double>(stats.primaryRays + stats.secondaryRays) / seconds * 1e-6;
}

struct Scene
{
  std::string name;
  PointCloudView points;
  int depth;
};
}

// One core tracing every pixel's primary ray to its first voxel with
// `traverse`, in a plain loop (no shading, no picture): what is left is
// the ray setup and the traversal. Returns the best of `repeats` in seconds
// and the hit voxels' sum, by which the traversals must agree.
template <typename TraverseFn>
double PrimaryRaySeconds(const FrameConstants& f, const OctreeView& tree, int repeats, TraverseFn traverse,
  std::uint64_t& hitSum)
{
  double best = 0.0;
  for (int r = 0; r <= repeats; ++r) // the first is a warm-up
  {
    hitSum = 0;
    const auto start = std::chrono::steady_clock::now();
    for (int y = 0; y < f.height; ++y)
    {
      for (int x = 0; x < f.width; ++x)
      {
        Ray ray;
        double tBase;
        FirstHitVisitor first;
        if (PrimaryRay(f, x, y, ray, tBase))
        {
          LevelOfDetail lod;
          traverse(tree, ray, lod, first);
        }
        hitSum += first.found ? first.hit.node + 1u : 0u;
      }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    best = r == 1 || (r > 1 && seconds < best) ? seconds : best;
  }
  return best;
}

// The same through packets of eight rays along a row (PacketTraversal.h),
// as the CPU engine traces its primary rays.
double PacketPrimaryRaySeconds(const FrameConstants& f, const OctreeView& tree, int repeats, std::uint64_t& hitSum)
{
  double best = 0.0;
  for (int r = 0; r <= repeats; ++r) // the first is a warm-up
  {
    hitSum = 0;
    const auto start = std::chrono::steady_clock::now();
    for (int y = 0; y < f.height; ++y)
    {
      for (int x0 = 0; x0 < f.width; x0 += kPacketLanes)
      {
        Ray rays[kPacketLanes];
        LevelOfDetail lods[kPacketLanes];
        unsigned valid = 0;
        for (int lane = 0; lane < kPacketLanes && x0 + lane < f.width; ++lane)
        {
          double tBase;
          valid |= PrimaryRay(f, x0 + lane, y, rays[lane], tBase) ? 1u << lane : 0u;
        }
        FirstHitVisitor hits[kPacketLanes];
        TracePacket(tree, rays, lods, valid, hits);
        for (const FirstHitVisitor& first : hits)
        {
          hitSum += first.found ? first.hit.node + 1u : 0u;
        }
      }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    best = r == 1 || (r > 1 && seconds < best) ? seconds : best;
  }
  return best;
}

// The `traversal` part for one scene built on `engine`.
Record CompareTraversals(Engine& engine, const Scene& scene, int w, int h, int repeats)
{
  BuildOptions options;
  options.depth = scene.depth;
  const BuildStats build = engine.Build(scene.points, options);
  HostOctree tree;
  engine.CopyToHost(tree);
  const OctreeView view = tree.View();
  const FrameConstants f = MakeFrame(MakeSettings(scene.points, w, h, kModes[0], build.depth), view);
  std::uint64_t fastSum = 0, referenceSum = 0;
  const double fast = PrimaryRaySeconds(f, view, repeats,
    [](const OctreeView& t, const Ray& r, const LevelOfDetail& l, FirstHitVisitor& v) { Traverse(t, r, l, v); },
    fastSum);
  const double reference = PrimaryRaySeconds(f, view, repeats,
    [](const OctreeView& t, const Ray& r, const LevelOfDetail& l, FirstHitVisitor& v) { ReferenceTraverse(t, r, l, v); },
    referenceSum);
  std::uint64_t packetSum = 0;
  const double packets = PacketPrimaryRaySeconds(f, view, repeats, packetSum);
  const double rays = double(w) * h;
  std::printf("| %s | %zu | %d | %.2f | %.2f | %.2f | %.2fx | %.2fx | %s |\n", scene.name.c_str(), build.points,
    build.depth, rays / packets * 1e-6, rays / fast * 1e-6, rays / reference * 1e-6, fast / packets, reference / fast,
    fastSum == referenceSum && packetSum == referenceSum ? "yes" : "NO");
  std::fflush(stdout);
  Record r{ "traversal." + scene.name, "cpu-1-core", std::size_t(w) * h, build.depth, fast,
    "reference slab-test traversal", reference };
  r.With("same_first_hits", fastSum == referenceSum && packetSum == referenceSum ? 1.0 : 0.0)
    .With("nodes", double(build.nodes))
    .With("packet_seconds", packets);
  return r;
}

// The mean over the pixels of the largest channel difference, in 1/255.
double MeanDifference(const Image& a, const Image& b)
{
  double sum = 0.0;
  const std::size_t pixels = a.rgba.size() / 4;
  for (std::size_t i = 0; i < pixels; ++i)
  {
    float worst = 0.0f;
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::fabs(a.rgba[4 * i + c] - b.rgba[4 * i + c]));
    sum += worst;
  }
  return 255.0 * sum / pixels;
}

// The sphere field's Phong picture by its radial normals, and without them
// by the normals estimated from its voxels and by occupancy: how long the
// estimate takes and how far each picture is from the first.
Record CompareNormals(Engine& engine, const std::string& backendName, const SphereField& spheres, int w, int h,
  int repeats)
{
  const Mode& phong =
    *std::find_if(std::begin(kModes), std::end(kModes), [](const Mode& m) { return std::string(m.name) == "phong"; });
  BuildOptions options{ 8 };
  RenderSettings s = MakeSettings(spheres.View(false, true), w, h, phong, 8);
  Image given, estimated, occupancy;
  engine.Build(spheres.View(false, true), options);
  const Timing tGiven = Measure([&] { engine.Render(s, given); }, 1, repeats);
  // Each build's first frame estimates them (the first build's is a warm-up).
  s.estimateNormals = true;
  std::vector<double> estimates;
  for (int r = 0; r <= repeats; ++r)
  {
    engine.Build(spheres.View(false, false), options);
    estimates.push_back(engine.Render(s, estimated).normalSeconds);
  }
  estimates.erase(estimates.begin());
  const double estimate = Summarise(estimates).median;
  const Timing tEstimated = Measure([&] { engine.Render(s, estimated); }, 1, repeats);
  s.estimateNormals = false;
  engine.Render(s, occupancy);
  std::printf("\nnormals of the spheres (%zu points, depth 8, Phong, %dx%d): the points' own, estimated from the "
              "voxels, occupancy\n",
    spheres.xyz.size() / 3, w, h);
  std::printf("| normals | estimate ms | frame ms | mean difference from the "
              "points' own, 1/255 |\n| --- | ---: | ---: | ---: |\n");
  std::printf("| the points' own (radial) | - | %.1f | 0 |\n", tGiven.median * 1e3);
  std::printf("| estimated from the voxels | %.1f | %.1f | %.2f |\n", estimate * 1e3,
    tEstimated.median * 1e3, MeanDifference(estimated, given));
  std::printf("| occupancy of six neighbours | - | - | %.2f |\n", MeanDifference(occupancy, given));
  return Record{ "render.spheres.normal-estimate", backendName + "-" + engine.Description(), spheres.xyz.size() / 3, 8,
    estimate,
    "render.spheres.phong", tGiven.median };
}

int main(int argc, char** argv)
{
  int w = 1920, h = 1080, repeats = 3, threads = 0;
  std::size_t spherePoints = 1000000;
  std::string backend = "cpu", lidar = OCTORAY_LIDAR_FILE, json, parts = "modes,off";
  CommandLine options;
  options.Size("--size", w, h)
    .Integer("--repeats", repeats, 1)
    .Integer("--threads", threads, 0)
    .Choice("--backend", backend, { "cpu", "cuda", "all" })
    .Text("--lidar", lidar)
    .Count("--sphere-points", spherePoints)
    .Text("--parts", parts)
    .Text("--json", json);
  if (const std::optional<int> stop = options.ParseOrStop(argc, argv, kUsage))
  {
    return *stop;
  }
  parts = "," + parts + ",";
  const auto wanted = [&](const char* part) { return parts.find(std::string(",") + part + ",") != std::string::npos; };

  const std::vector<Backend> backends = RequestedBackends(backend);

  try
  {
    const PointFile file = PointFile::Load(lidar);
    const SphereField spheres = MakeSphereField(spherePoints);
    const Scene scenes[] = { { "lidar", file.View(), 0 }, { "spheres", spheres.View(true, true), 8 } };
    std::vector<Record> records;
    for (Backend b : backends)
    {
      auto engine = CreateEngine(b);
      if (threads > 0)
        engine->SetThreadCount(threads);
      const std::string backendName = b == Backend::CPU ? "cpu" : "cuda";
      std::printf("\n%s, %dx%d, median of %d after a warm-up frame\n", engine->Description().c_str(), w, h,
        repeats);
      for (const Scene& scene : scenes)
      {
        if (!wanted("modes"))
          break;
        BuildOptions options;
        options.depth = scene.depth;
        const BuildStats build = engine->Build(scene.points, options);
        std::printf("\nscene %s: %zu points, depth %d, %zu nodes\n", scene.name.c_str(), build.points, build.depth,
          build.nodes);
        std::printf("| mode | ms / frame | Mrays/s (all rays) | Mrays/s (primary) | secondary rays / pixel |\n");
        std::printf("| --- | ---: | ---: | ---: | ---: |\n");
        for (const Mode& m : kModes)
        {
          const RenderSettings s = MakeSettings(scene.points, w, h, m, build.depth);
          Image image;
          RenderStats stats;
          const Timing t = Measure([&] { stats = engine->Render(s, image); }, 1, repeats);
          std::printf("| %s | %.1f | %.2f | %.2f | %.2f |\n", m.name, t.median * 1e3, MraysPerSecond(stats, t.median),
            stats.primaryRays / t.median * 1e-6, double(stats.secondaryRays) / stats.primaryRays);
          std::fflush(stdout);
          Record r{ "render." + scene.name + "." + m.name, backendName + "-" + engine->Description(),
            std::size_t(w) * h, build.depth, t.median, "", 0.0 };
          r.With("primary_rays", double(stats.primaryRays))
            .With("secondary_rays", double(stats.secondaryRays))
            .With("min_seconds", t.min)
            .With("points", double(build.points))
            .With("nodes", double(build.nodes));
          records.push_back(r);
        }
      }

      if (wanted("traversal") && b == Backend::CPU)
      {
        std::printf("\nprimary rays on one core, %dx%d, best of %d after a warm-up: packets of %d rays "
                    "(PacketTraversal.h), Traverse, and the plain slab-test traversal (ReferenceTraversal.h)\n",
          w, h, repeats, kPacketLanes);
        std::printf("| scene | points | depth | Mrays/s, packets | Mrays/s, Traverse | Mrays/s, reference | "
                    "packets / Traverse | Traverse / reference | same first hits |\n");
        std::printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |\n");
        for (const Scene& scene : scenes)
        {
          records.push_back(CompareTraversals(*engine, scene, w, h, repeats));
        }
      }

      if (wanted("normals"))
      {
        records.push_back(CompareNormals(*engine, backendName, spheres, w, h, repeats));
      }

      // Everything off: the sphere field without reflectivity, rendered
      // with settings that ask for bounces and shadows but give no light,
      // against the plain primary-ray path (flat, nothing asked for).
      if (wanted("off"))
      {
        const PointCloudView plainPoints = spheres.View(false, true);
        engine->Build(plainPoints, BuildOptions{ 8 });
        const Mode flat = kModes[0];
        RenderSettings plain = MakeSettings(plainPoints, w, h, flat, 8);
        RenderSettings asked = plain;
        asked.maxBounces = 4;
        asked.shadows = true;
        Image image;
        const Timing tp = Measure([&] { engine->Render(plain, image); }, 1, repeats);
        const Timing ta = Measure([&] { engine->Render(asked, image); }, 1, repeats);
        // The same points with reflectivity present but zero everywhere:
        // the per-hit read of a zero weight.
        SphereField zero = spheres;
        std::fill(zero.reflectivity.begin(), zero.reflectivity.end(), 0.0f);
        engine->Build(zero.View(true, true), BuildOptions{ 8 });
        const Timing tz = Measure([&] { engine->Render(asked, image); }, 1, repeats);
        std::printf("\neverything off (spheres, flat, %dx%d):\n", w, h);
        std::printf("| frame | ms / frame |\n| --- | ---: |\n");
        std::printf("| plain primary rays (bounces 0, no shadows) | %.1f |\n", tp.median * 1e3);
        std::printf("| bounces 4 + shadows asked, no reflectivity attribute, no lights | %.1f |\n", ta.median * 1e3);
        std::printf("| bounces 4 + shadows asked, reflectivity attribute all 0, no lights | %.1f |\n", tz.median * 1e3);
        records.push_back(Record{ "render.spheres.everything-off", backendName + "-" + engine->Description(),
          std::size_t(w) * h, 8, ta.median, "render.spheres.plain-primary", tp.median });
      }
    }
    SaveRecords(json, records);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
