// octoray_bench_quality: what each quality knob trades in image error for
// render time. For every scene and backend, one knob at a time moves away
// from a reference setting while the others stay at theirs; each picture is
// compared with the reference picture of the same scene (RMSE, PSNR, SSIM;
// ImageMetrics.h) and timed.
//
//   octoray_bench_quality [--backend cpu|cuda|all] [--scenes DIR] [--lidar PATH]
//                         [--only ct5n,lidar,spheres] [--size WxH] [--repeats R]
//                         [--threads N] [--sphere-points N] [--json FILE] [--dump DIR]
//
// Scenes:
//   ct5n     DIR/ct5n.particles: the bundled CT series (Data/DICOM/CT5N)
//            read by vtkSliceStackReader, air removed (HU <= -500), written
//            as x y z HU by vtkParticleTextWriter (Benchmarks/Report/scenes.py);
//            coloured through a transfer function on HU. Skipped without
//            --scenes.
//   lidar    the bundled LiDAR tile (Data/Particles/lidar_simple.particles):
//            RGB, reflectivity from the return intensity.
//   spheres  a synthetic field of 48 spheres (BenchScenes.h): points on
//            their surfaces, radial normals, reflectivity 0.4.
//
// The reference setting: the depth the engine chooses from the data, level
// of detail off (k = 0), 8 bounces, shadows on, the picture at WxH; for the
// image-size knob, the picture rendered at 2W x 2H and box-filtered down
// (2x2 supersampled). Knobs and their values:
//   depth    auto-3 .. auto+3 (the octree rebuilt at each)
//   lod      k = 1, 2, 4, 8, 16, 32 pixels
//   bounces  0, 1, 2, 3, 4
//   shadows  off
//   size     rendered at s W x s H for s = 1/4, 1/2, 1, each pixel
//            repeated to WxH (nearest: what a viewer stretching a smaller
//            picture shows)
//   reference-check  (not a knob) the references against finer ones: 2x2
//            against 4x4 supersampling, 8 bounces against 16
// Every scene is lit by one directional light and shaded with Phong.
//
// Time: the median over R interleaved rounds (after an untimed one) of the
// engine's own frame time, RenderStats::seconds: on the CPU the whole
// frame; on CUDA the host clock around the kernel launch and the device
// synchronise, with the picture in device memory (the copy to the host,
// needed here only for the comparison, is outside it).
//
// --json FILE writes one flat record per row: scene, backend, device, knob,
// value, seconds, rmse, psnr (null when the pictures are identical), ssim,
// reference (what the row was compared with), is_reference, width, height,
// depth, points, repeats. --dump DIR also writes every compared pair as PFM
// files (named in the records' image and reference_image fields), which
// Testing/Python/test_bench_quality_metrics.py checks with scikit-image.
#include "BenchScenes.h"
#include "BenchUtil.h"
#include "CommandLine.h"
#include "ImageMetrics.h"
#include "OrbitCamera.h"
#include "PointFile.h"

#include <octoray/Engine.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace
{
using namespace octoray;
using namespace octoray::bench;

// The usage, printed for --help or -h and after a wrong argument.
constexpr const char* kUsage =
    "usage: octoray_bench_quality [--backend cpu|cuda|all] [--scenes DIR] [--lidar PATH]\n"
    "                             [--only ct5n,lidar,spheres] [--size WxH] [--repeats R]\n"
    "                             [--threads N] [--sphere-points N] [--json FILE] [--dump DIR]\n";

struct Scene
{
  std::string name;
  PointCloudView points;
  TransferFunction transfer; // empty: the points' own colours
  double lo[3], hi[3];
};

// HU -> colour for the CT slab, which holds fat and soft tissue (HU -500 to
// about 100 after the air is removed; no bone in these five slices): dark
// red through fat yellow to tissue pink and red, so that the tissue classes
// differ in the picture and a coarser octree's averaged HU shows as a
// change of colour.
TransferFunction CtTransfer()
{
  struct Stop
  {
    float hu, r, g, b;
  };
  const Stop stops[] = { { -500, 0.35f, 0.12f, 0.10f }, { -150, 0.95f, 0.85f, 0.45f },
    { -50, 0.95f, 0.65f, 0.50f }, { 30, 0.90f, 0.40f, 0.35f }, { 100, 0.75f, 0.15f, 0.12f } };
  TransferFunction t;
  t.range[0] = stops[0].hu;
  t.range[1] = stops[4].hu;
  const int n = 128;
  for (int i = 0; i < n; ++i)
  {
    const float hu = t.range[0] + (t.range[1] - t.range[0]) * i / (n - 1);
    int k = 0;
    while (k < 3 && hu > stops[k + 1].hu)
    {
      ++k;
    }
    const float u = std::min(1.0f, std::max(0.0f, (hu - stops[k].hu) / (stops[k + 1].hu - stops[k].hu)));
    t.table.push_back(Rgba{ stops[k].r + u * (stops[k + 1].r - stops[k].r),
      stops[k].g + u * (stops[k + 1].g - stops[k].g), stops[k].b + u * (stops[k + 1].b - stops[k].b), 1.0f });
  }
  return t;
}

// One knob's setting: every field at its reference value unless the knob
// moves it.
struct Quality
{
  int depth = 0; // 0: the engine's choice
  float lod = 0.0f;
  int bounces = 8;
  bool shadows = true;
  int width = 0, height = 0;
};

RenderSettings MakeSettings(const Scene& scene, const Quality& q)
{
  RenderSettings s;
  s.width = q.width;
  s.height = q.height;
  OrbitCamera camera;
  camera.zoom = 1.3;
  camera.Apply(scene.lo, scene.hi, s);
  s.blend = BlendMode::Surface;
  s.shade = ShadeMode::Phong;
  Light sun;
  OrbitCamera::Direction(camera.azimuth + 40, camera.elevation + 35, sun.position);
  sun.position[3] = 0;
  s.lights.push_back(sun);
  s.shadows = q.shadows;
  s.maxBounces = q.bounces;
  s.lodPixels = q.lod;
  s.transfer = scene.transfer;
  return s;
}

struct Row
{
  std::string scene, backend, device, knob, value, reference;
  bool isReference = false;
  double seconds = 0, rmse = 0, psnr = 0, ssim = 0;
  int width = 0, height = 0, depth = 0, repeats = 0;
  std::size_t points = 0;
  std::string image, referenceImage; // --dump file names
};

std::string ToJson(const Row& r)
{
  std::ostringstream o;
  o << "{\"scene\": " << detail::Quote(r.scene) << ", \"backend\": " << detail::Quote(r.backend)
    << ", \"device\": " << detail::Quote(r.device) << ", \"knob\": " << detail::Quote(r.knob)
    << ", \"value\": " << detail::Quote(r.value) << ", \"seconds\": " << detail::Number(r.seconds)
    << ", \"rmse\": " << detail::Number(r.rmse) << ", \"psnr\": " << detail::Number(r.psnr)
    << ", \"ssim\": " << detail::Number(r.ssim) << ", \"reference\": " << detail::Quote(r.reference)
    << ", \"is_reference\": " << (r.isReference ? "true" : "false") << ", \"width\": " << r.width
    << ", \"height\": " << r.height << ", \"depth\": " << r.depth << ", \"points\": " << r.points
    << ", \"repeats\": " << r.repeats;
  if (!r.image.empty())
  {
    o << ", \"image\": " << detail::Quote(r.image) << ", \"reference_image\": " << detail::Quote(r.referenceImage);
  }
  o << "}";
  return o.str();
}

// The runs of one scene on one backend. Every setting is a job; all jobs
// are rendered once untimed, then `repeats` rounds render each job once in
// turn, and a job's time is the median of its rounds. Interleaved rounds
// rather than one job's repeats back to back: on a shared machine the load
// drifts over a run, and a drift then shifts every job alike instead of
// favouring whichever ran in a quiet moment. Each leaf depth has its own
// engine (octree), so the depth jobs join the same rounds.
class SceneRun
{
public:
  SceneRun(Backend backend, int threads, const Scene& scene, int width, int height, int repeats,
    const std::string& dump, std::vector<Row>& rows)
    : TheBackend(backend)
    , Threads(threads)
    , BackendName(backend == Backend::CPU ? "cpu" : "cuda")
    , TheScene(scene)
    , Width(width)
    , Height(height)
    , Repeats(repeats)
    , Dump(dump)
    , Rows(rows)
  {
  }

  void Run()
  {
    Engine& automatic = EngineAt(0);
    std::printf("\n%s on %s: %zu points, depth %d (the engine's choice), %zu nodes, %dx%d, median of %d rounds\n",
      TheScene.name.c_str(), automatic.Description().c_str(), TheScene.points.count, AutoDepth, AutoNodes, Width,
      Height, Repeats);

    // The jobs. Every quality field sits at its reference value unless the
    // knob moves it.
    const Quality base = Base();
    const std::size_t reference = AddJob(base);
    std::vector<std::pair<float, std::size_t>> lod;
    for (float k : { 1.0f, 2.0f, 4.0f, 8.0f, 16.0f, 32.0f })
    {
      Quality q = base;
      q.lod = k;
      lod.emplace_back(k, AddJob(q));
    }
    std::vector<std::pair<int, std::size_t>> bounces;
    for (int b : { 0, 1, 2, 3, 4 })
    {
      Quality q = base;
      q.bounces = b;
      bounces.emplace_back(b, AddJob(q));
    }
    Quality noShadows = base;
    noShadows.shadows = false;
    const std::size_t shadowsOff = AddJob(noShadows);
    // Image size: s W x s H, each pixel repeated back to W x H, against the
    // 2W x 2H picture box-filtered to W x H (2x2 supersampled).
    Quality super = base;
    super.width = 2 * Width;
    super.height = 2 * Height;
    const std::size_t supersampled = AddJob(super, 1, 2);
    std::vector<std::pair<int, std::size_t>> sizes;
    for (int divisor : { 4, 2, 1 })
    {
      Quality q = base;
      q.width = Width / divisor;
      q.height = Height / divisor;
      sizes.emplace_back(divisor, AddJob(q, divisor, 1));
    }
    std::vector<std::pair<int, std::size_t>> depths;
    for (int d = AutoDepth - 3; d <= AutoDepth + 3; ++d)
    {
      if (d >= 1 && d <= kMaxLevel && d != AutoDepth)
      {
        Quality q = base;
        q.depth = d;
        depths.emplace_back(d, AddJob(q));
      }
    }

    for (Job& job : Jobs) // warm-up: buffers grown, caches filled; keeps the picture
    {
      Render(job, false);
    }
    for (int round = 0; round < Repeats; ++round)
    {
      for (Job& job : Jobs)
      {
        Render(job, true);
      }
    }

    const std::string refName =
      Format("depth %d (auto), lod k 0, 8 bounces, shadows on, %dx%d", AutoDepth, Width, Height);
    const std::string superName =
      Format("%dx%d, box-filtered from %dx%d (2x2 supersampled)", Width, Height, 2 * Width, 2 * Height);
    const std::string refFile = Save(Jobs[reference].picture, "reference");
    const std::string superFile = Save(Jobs[supersampled].picture, "size-reference");

    std::printf("| knob | value | ms | RMSE | PSNR (dB) | SSIM |\n| --- | --- | ---: | ---: | ---: | ---: |\n");
    bool autoRow = false;
    for (const auto& [d, job] : depths)
    {
      if (d > AutoDepth && !autoRow)
      {
        Add("depth", Format("%d (auto)", AutoDepth), reference, reference, refName, refFile, true);
        autoRow = true;
      }
      Add("depth", Format("%d (auto%+d)", d, d - AutoDepth), job, reference, refName, refFile, false);
    }
    if (!autoRow)
    {
      Add("depth", Format("%d (auto)", AutoDepth), reference, reference, refName, refFile, true);
    }
    Add("lod", "0", reference, reference, refName, refFile, true);
    for (const auto& [k, job] : lod)
    {
      Add("lod", Format("%g", k), job, reference, refName, refFile, false);
    }
    for (const auto& [b, job] : bounces)
    {
      Add("bounces", Format("%d", b), job, reference, refName, refFile, false);
    }
    Add("bounces", "8", reference, reference, refName, refFile, true);
    Add("shadows", "off", shadowsOff, reference, refName, refFile, false);
    Add("shadows", "on", reference, reference, refName, refFile, true);
    for (const auto& [divisor, job] : sizes)
    {
      Add("size", Format("%g", 1.0 / divisor), job, supersampled, superName, superFile, false);
    }
    Add("size", "2", supersampled, supersampled, superName, superFile, true);

    // How far the references themselves are from converged, from one
    // (untimed) frame each: 2x2 against 4x4 supersampling, 8 bounces
    // against 16. The rows carry the reference's time.
    Quality finer = base;
    finer.width = 4 * Width;
    finer.height = 4 * Height;
    const std::size_t super4 = AddJob(finer, 1, 4);
    Quality more = base;
    more.bounces = 16;
    const std::size_t bounces16 = AddJob(more);
    Render(Jobs[super4], false);
    Render(Jobs[bounces16], false);
    Add("reference-check", "size: 2x2 against 4x4 supersampled", supersampled, super4,
      Format("%dx%d, box-filtered from %dx%d (4x4 supersampled)", Width, Height, 4 * Width, 4 * Height),
      Save(Jobs[super4].picture, "size-check"), false);
    Add("reference-check", "bounces: 8 against 16", reference, bounces16,
      Format("depth %d (auto), lod k 0, 16 bounces, shadows on, %dx%d", AutoDepth, Width, Height),
      Save(Jobs[bounces16].picture, "bounces-check"), false);
  }

private:
  struct Job
  {
    Quality quality;
    int upsample = 1, downsample = 1; // how the picture is brought to W x H
    std::vector<double> seconds;
    RgbImage picture;
    double Median() const { return Summarise(seconds).median; }
  };

  // The engine holding the octree of leaf depth `depth` (0: the engine's
  // choice), built on first use.
  Engine& EngineAt(int depth)
  {
    if (depth == AutoDepth && AutoDepth)
    {
      depth = 0;
    }
    for (auto& e : Engines)
    {
      if (e.first == depth)
      {
        return *e.second;
      }
    }
    std::unique_ptr<Engine> engine = CreateEngine(TheBackend);
    if (Threads > 0)
    {
      engine->SetThreadCount(Threads);
    }
    const BuildStats built = engine->Build(TheScene.points, BuildOptions{ depth });
    if (depth == 0)
    {
      AutoDepth = built.depth;
      AutoNodes = built.nodes;
    }
    Engines.emplace_back(depth, std::move(engine));
    return *Engines.back().second;
  }

  std::size_t AddJob(const Quality& q, int upsample = 1, int downsample = 1)
  {
    Job job;
    job.quality = q;
    job.upsample = upsample;
    job.downsample = downsample;
    Jobs.push_back(job);
    return Jobs.size() - 1;
  }

  void Render(Job& job, bool timed)
  {
    Image image;
    const RenderStats stats = EngineAt(job.quality.depth).Render(MakeSettings(TheScene, job.quality), image);
    if (timed)
    {
      job.seconds.push_back(stats.seconds);
    }
    else
    {
      job.picture = ToRgb(image);
      if (job.upsample > 1)
      {
        job.picture = UpsampleNearest(job.picture, job.upsample);
      }
      if (job.downsample > 1)
      {
        job.picture = DownsampleBox(job.picture, job.downsample);
      }
    }
  }

  Quality Base() const
  {
    Quality q;
    q.width = Width;
    q.height = Height;
    return q;
  }

  template <typename... Args>
  static std::string Format(const char* format, Args... args)
  {
    char text[160];
    std::snprintf(text, sizeof text, format, args...);
    return text;
  }

  std::string Save(const RgbImage& picture, const std::string& what)
  {
    if (Dump.empty())
    {
      return "";
    }
    std::string name = TheScene.name + "-" + BackendName + "-" + what + ".pfm";
    for (char& c : name)
    {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.')
      {
        c = '_';
      }
    }
    WritePfm(Dump + "/" + name, picture);
    return name;
  }

  void Add(const std::string& knob, const std::string& value, std::size_t job, std::size_t referenceJob,
    const std::string& referenceName, const std::string& referenceFile, bool isReference)
  {
    const Job& j = Jobs[job];
    const RgbImage& reference = Jobs[referenceJob].picture;
    Row r;
    r.scene = TheScene.name;
    r.backend = BackendName;
    r.device = EngineAt(0).Description();
    r.knob = knob;
    r.value = value;
    r.reference = referenceName;
    r.isReference = isReference;
    r.seconds = j.Median();
    r.rmse = Rmse(j.picture, reference);
    r.psnr = Psnr(j.picture, reference);
    r.ssim = Ssim(j.picture, reference);
    r.width = j.quality.width;
    r.height = j.quality.height;
    r.depth = j.quality.depth ? j.quality.depth : AutoDepth;
    r.points = TheScene.points.count;
    r.repeats = static_cast<int>(j.seconds.size());
    if (!Dump.empty())
    {
      r.image = isReference ? referenceFile : Save(j.picture, knob + "-" + value);
      r.referenceImage = referenceFile;
    }
    std::printf("| %s | %s | %.2f | %.5f | %.2f | %.5f |\n", knob.c_str(), value.c_str(), r.seconds * 1e3, r.rmse,
      r.psnr, r.ssim);
    std::fflush(stdout);
    Rows.push_back(r);
  }

  Backend TheBackend;
  int Threads;
  std::string BackendName;
  const Scene& TheScene;
  int Width, Height, Repeats;
  std::string Dump;
  std::vector<Row>& Rows;
  std::vector<std::pair<int, std::unique_ptr<Engine>>> Engines;
  std::vector<Job> Jobs;
  int AutoDepth = 0;
  std::size_t AutoNodes = 0;
};

bool Wanted(const std::string& only, const std::string& name)
{
  return only.empty() || ("," + only + ",").find("," + name + ",") != std::string::npos;
}
}

int main(int argc, char** argv)
{
  int width = 512, height = 288, repeats = 0, threads = 0;
  std::size_t spherePoints = 300000;
  std::string backend = "cpu", scenesDir, lidar = OCTORAY_LIDAR_FILE, only, json, dump;
  CommandLine options;
  options.Choice("--backend", backend, { "cpu", "cuda", "all" })
    .Text("--scenes", scenesDir)
    .Text("--lidar", lidar)
    .Text("--only", only)
    .Size("--size", width, height)
    .Integer("--repeats", repeats, 0) // 0: by backend
    .Integer("--threads", threads, 0)
    .Count("--sphere-points", spherePoints)
    .Text("--json", json)
    .Text("--dump", dump);
  if (const std::optional<int> stop = options.ParseOrStop(argc, argv, kUsage))
  {
    return *stop;
  }
  // Quarter-size pictures repeat each pixel 4x4 times onto the full size,
  // and SSIM's window needs 11 pixels.
  if (width % 4 || height % 4 || width < 44 || height < 44)
  {
    std::fprintf(stderr, "octoray_bench_quality: --size must be multiples of 4, at least 44x44\n");
    return 2;
  }

  const std::vector<Backend> backends = RequestedBackends(backend);
  if (backends.empty())
  {
    // Asked for CUDA alone: an empty file would read as a GPU run.
    std::fprintf(stderr, "octoray_bench_quality: CUDA not available\n");
    return 1;
  }

  try
  {
    std::vector<Scene> scenes;
    PointFile ct, lidarFile;
    SphereField spheres;
    if (Wanted(only, "ct5n"))
    {
      if (scenesDir.empty())
      {
        std::printf("ct5n skipped: no --scenes DIR holding ct5n.particles (Benchmarks/Report/scenes.py writes it)\n");
      }
      else
      {
        ct = PointFile::Load(scenesDir + "/ct5n.particles");
        if (ct.scalar.empty())
        {
          throw Error(scenesDir + "/ct5n.particles: expected x y z HU columns");
        }
        scenes.push_back(Scene{ "ct5n", ct.View(), CtTransfer(), {}, {} });
      }
    }
    if (Wanted(only, "lidar"))
    {
      lidarFile = PointFile::Load(lidar);
      scenes.push_back(Scene{ "lidar", lidarFile.View(), {}, {}, {} });
    }
    if (Wanted(only, "spheres"))
    {
      spheres = MakeSphereField(spherePoints);
      scenes.push_back(Scene{ "spheres", spheres.View(true, true), {}, {}, {} });
    }
    for (Scene& s : scenes)
    {
      Bounds(s.points, s.lo, s.hi);
    }

    std::vector<Row> rows;
    for (Backend b : backends)
    {
      // GPU frames take milliseconds: more rounds for the same confidence.
      const int r = repeats > 0 ? repeats : (b == Backend::CPU ? 5 : 15);
      for (const Scene& s : scenes)
      {
        SceneRun(b, threads, s, width, height, r, dump, rows).Run();
      }
    }
    if (!json.empty())
    {
      const std::string temporary = json + ".tmp";
      {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out << "[\n";
        for (std::size_t i = 0; i < rows.size(); ++i)
        {
          out << "  " << ToJson(rows[i]) << (i + 1 < rows.size() ? ",\n" : "\n");
        }
        out << "]\n";
        if (!out)
        {
          throw std::runtime_error(temporary + ": could not be written");
        }
      }
      if (std::rename(temporary.c_str(), json.c_str()) != 0)
      {
        throw std::runtime_error(json + ": could not be replaced");
      }
      std::printf("\n%zu records written to %s\n", rows.size(), json.c_str());
    }
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
