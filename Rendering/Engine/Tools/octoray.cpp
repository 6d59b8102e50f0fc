// octoray: the engine's command-line tool.
//   octoray stats FILE [--depth N] [--backend cpu|cuda|auto] [--threads N]
// builds the octree of a particle file and prints its statistics and costs;
//   octoray render FILE -o OUT.png [options]
// ray-traces it from a camera orbiting the data and writes the picture;
//   octoray --help
// prints the options.
#include "CommandLine.h"
#include "OrbitCamera.h"
#include "PointFile.h"

#include <octoray/Engine.h>
#include <octoray/Frame.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#if OCTORAY_HAVE_OIIO
#include <OpenImageIO/imageio.h>
#endif

namespace
{
// The usage, on `to`; the exit status.
int Usage(std::FILE* to = stderr)
{
  return octoray::CommandLine::PrintUsage(to,
    "usage: octoray stats FILE [--depth N] [--backend cpu|cuda|auto] [--threads N]\n"
    "  builds the octree of a particle text file (a header line naming x y z ..., or 3, 4, 6 or 8\n"
    "  columns) and prints its statistics\n"
    "       octoray render FILE -o OUT.png [--size WxH] [--mode MODE] [--depth N] [--lod K]\n"
    "                      [--shadows] [--bounces N] [--backend auto|cpu|cuda] [--threads N]\n"
    "                      [--azimuth DEG] [--elevation DEG] [--zoom F]\n"
    "  MODE: surface (flat colours, default), depthcue, phong, composite, mip, minip, average, additive;\n"
    "  phong lights points without normals by normals fitted to their voxels\n"
    "  the camera orbits the data's centre (azimuth about +z, elevation above the xy plane);\n"
    "  PNG through OpenImageIO where it was found at build time, else binary PPM\n");
}

// `--help` or `-h` anywhere, or `help` as the command.
bool AsksForHelp(int argc, char** argv)
{
  return (argc > 1 && std::string(argv[1]) == "help") || octoray::CommandLine::AsksForHelp(argc, argv);
}

double Seconds(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The options both commands take.
struct EngineOptions
{
  std::string backend = "auto";
  int threads = 0;
  octoray::BuildOptions build;

  void AddTo(octoray::CommandLine& options)
  {
    options.Choice("--backend", backend, { "auto", "cpu", "cuda" })
      .Integer("--threads", threads, 0)
      .Integer("--depth", build.depth); // its range is the engine's to check
  }
};

// A particle file loaded, and the engine its options ask for with its
// octree built.
struct Built
{
  std::string path;
  octoray::PointFile file;
  double loadSeconds = 0;
  std::unique_ptr<octoray::Engine> engine;
  std::string cudaNotUsed; // why "auto" took the CPU
  octoray::BuildStats stats;
};

Built LoadAndBuild(const std::string& path, const EngineOptions& o)
{
  Built b;
  b.path = path;
  const auto start = std::chrono::steady_clock::now();
  b.file = octoray::PointFile::Load(path);
  b.loadSeconds = Seconds(start);
  std::string why;
  const bool useCuda = o.backend == "cuda" || (o.backend == "auto" && octoray::CudaAvailable(&why));
  b.cudaNotUsed = (!useCuda && o.backend == "auto") ? why : "";
  b.engine = octoray::CreateEngine(useCuda ? octoray::Backend::CUDA : octoray::Backend::CPU);
  if (o.threads > 0)
  {
    b.engine->SetThreadCount(o.threads);
  }
  b.stats = b.engine->Build(b.file.View(), o.build);
  return b;
}

// The lines both commands print first: the file and the backend.
void PrintSource(const Built& b)
{
  std::printf("file            %s (%zu point%s, read in %.3f s)\n", b.path.c_str(), b.stats.points,
    b.stats.points == 1 ? "" : "s", b.loadSeconds);
  std::printf("backend         %s%s%s\n", b.engine->Description().c_str(),
    b.cudaNotUsed.empty() ? "" : ", CUDA not used: ", b.cudaNotUsed.c_str());
}

int Stats(int argc, char** argv)
{
  EngineOptions o;
  octoray::CommandLine options;
  o.AddTo(options);
  if (!options.Parse(argc, argv, 3))
  {
    return Usage();
  }
  const Built b = LoadAndBuild(argv[2], o);
  const octoray::BuildStats& stats = b.stats;
  const octoray::MemoryReport memory = b.engine->Memory();
  PrintSource(b);
  std::printf("depth           %d%s\n", stats.depth, o.build.depth ? "" : " (automatic)");
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
  return 0;
}

int Render(int argc, char** argv);
}

int main(int argc, char** argv)
{
  if (AsksForHelp(argc, argv))
  {
    return Usage(stdout);
  }
  const std::string command = argc > 1 ? argv[1] : "";
  if (command != "stats" && command != "render")
  {
    if (!command.empty())
    {
      std::fprintf(stderr, "octoray: unknown command '%s'\n", command.c_str());
    }
    return Usage();
  }
  if (argc < 3)
  {
    std::fprintf(stderr, "octoray: %s needs a FILE, the particle file to read\n", command.c_str());
    return Usage();
  }
  try
  {
    return command == "stats" ? Stats(argc, argv) : Render(argc, argv);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}

namespace
{
// 8-bit RGB, top row first, the premultiplied picture composited over a
// dark background (what a viewer shows; the engine's rows start at the bottom).
std::vector<unsigned char> Composite(const octoray::Image& image, float gain)
{
  const float background[3] = { 0.08f, 0.08f, 0.1f };
  std::vector<unsigned char> rgb(3 * static_cast<std::size_t>(image.width) * image.height);
  for (int y = 0; y < image.height; ++y)
  {
    for (int x = 0; x < image.width; ++x)
    {
      const std::size_t in = static_cast<std::size_t>(image.height - 1 - y) * image.width + x;
      const std::size_t out = static_cast<std::size_t>(y) * image.width + x;
      const float* p = &image.rgba[4 * in];
      for (int c = 0; c < 3; ++c)
      {
        const float v = gain * p[c] + (1.0f - std::min(1.0f, p[3])) * background[c];
        rgb[3 * out + c] = static_cast<unsigned char>(std::lround(255.0f * std::min(1.0f, std::max(0.0f, v))));
      }
    }
  }
  return rgb;
}

// Writes PNG (or whatever OIIO makes of the extension); without OIIO a
// binary PPM next to the requested name. Returns the path written.
std::string WriteImage(const std::string& path, int w, int h, const std::vector<unsigned char>& rgb)
{
#if OCTORAY_HAVE_OIIO
  auto out = OIIO::ImageOutput::create(path);
  if (!out)
  {
    throw octoray::Error(path + ": OpenImageIO cannot write this format: " + OIIO::geterror());
  }
  const OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
  if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgb.data()) || !out->close())
  {
    throw octoray::Error(path + ": " + out->geterror());
  }
  return path;
#else
  std::string ppm = path;
  const std::size_t dot = ppm.find_last_of('.');
  if (dot != std::string::npos && ppm.find('/', dot) == std::string::npos)
  {
    ppm.resize(dot);
  }
  ppm += ".ppm";
  std::ofstream out(ppm, std::ios::binary);
  out << "P6\n" << w << " " << h << "\n255\n";
  out.write(reinterpret_cast<const char*>(rgb.data()), static_cast<std::streamsize>(rgb.size()));
  if (!out)
  {
    throw octoray::Error(ppm + ": could not be written");
  }
  std::fprintf(stderr, "octoray: built without OpenImageIO, so the picture is binary PPM: %s\n", ppm.c_str());
  return ppm;
#endif
}

// What each --mode selects: a surface shading, or a blend mode.
struct ToolMode
{
  const char* name;
  octoray::ShadeMode shade;
  octoray::BlendMode blend;
};
constexpr ToolMode kToolModes[] = {
  { "surface", octoray::ShadeMode::Flat, octoray::BlendMode::Surface },
  { "depthcue", octoray::ShadeMode::DepthCue, octoray::BlendMode::Surface },
  { "phong", octoray::ShadeMode::Phong, octoray::BlendMode::Surface },
  { "composite", octoray::ShadeMode::Flat, octoray::BlendMode::Composite },
  { "mip", octoray::ShadeMode::Flat, octoray::BlendMode::Maximum },
  { "minip", octoray::ShadeMode::Flat, octoray::BlendMode::Minimum },
  { "average", octoray::ShadeMode::Flat, octoray::BlendMode::Average },
  { "additive", octoray::ShadeMode::Flat, octoray::BlendMode::Additive },
};

// The render command's options.
struct RenderOptions
{
  EngineOptions engine;
  std::string output;
  const ToolMode* mode = nullptr;
  int width = 1280, height = 720, bounces = 2;
  double azimuth = -60, elevation = 30, zoom = 1, lod = 0;
  bool shadows = false;

  // Parses argv from argv[3]; false, having said why, where it does not.
  bool Parse(int argc, char** argv)
  {
    std::vector<std::string> modes;
    for (const ToolMode& m : kToolModes)
    {
      modes.push_back(m.name);
    }
    std::string modeName = modes.front();
    octoray::CommandLine options;
    engine.AddTo(options);
    options.Text("-o", output)
      .Size("--size", width, height)
      .Choice("--mode", modeName, modes)
      .Real("--lod", lod)
      .Integer("--bounces", bounces, 0)
      .Flag("--shadows", shadows)
      .Real("--azimuth", azimuth)
      .Real("--elevation", elevation)
      .Real("--zoom", zoom, true);
    if (!options.Parse(argc, argv, 3))
    {
      return false;
    }
    mode = &kToolModes[std::find(modes.begin(), modes.end(), modeName) - modes.begin()];
    if (output.empty())
    {
      std::fprintf(stderr, "octoray: render needs -o OUT.png, the picture to write\n");
      return false;
    }
    return true;
  }
};

// The render settings for a picture of the points `points` (an octree of
// depth `depth`): the camera orbiting their bounding box's centre, whose
// bounding sphere fills the vertical field of view at zoom 1, a sun for
// the shadows, and an opacity for composite.
octoray::RenderSettings SceneSettings(const RenderOptions& o, const octoray::PointCloudView& points,
  const octoray::BuildStats& built)
{
  const int depth = built.depth;
  octoray::RenderSettings s;
  s.width = o.width;
  s.height = o.height;
  s.maxBounces = o.bounces;
  s.lodPixels = static_cast<float>(o.lod);
  s.shadows = o.shadows;
  s.estimateNormals = true; // as the VTK mapper does by default
  s.shade = o.mode->shade;
  s.blend = o.mode->blend;
  // The camera frames the leaves that hold the points, not the points
  // alone: points at one place (whose leaf is an eighth of the root cube,
  // with a corner at them) are seen from outside their voxel, whole.
  double lo[3], hi[3];
  octoray::Bounds(points, lo, hi);
  const double leaf = std::ldexp(built.cube.size, -depth);
  for (int k = 0; k < 3; ++k)
  {
    const double origin = built.cube.origin[k];
    lo[k] = origin + leaf * std::floor((lo[k] - origin) / leaf);
    hi[k] = origin + leaf * (std::floor((hi[k] - origin) / leaf) + 1);
  }
  octoray::OrbitCamera camera;
  camera.azimuth = o.azimuth;
  camera.elevation = o.elevation;
  camera.zoom = o.zoom;
  if (!camera.Apply(lo, hi, s))
  {
    throw octoray::Error("octoray: the camera matrix is singular");
  }
  if (o.shadows)
  {
    // Shadows need a light other than the headlight: a sun above and to
    // the left of the camera, so shadows fall visibly down and right.
    octoray::Light sun;
    octoray::OrbitCamera::Direction(o.azimuth + 40, std::min(80.0, o.elevation + 35), sun.position);
    sun.position[3] = 0;
    s.lights.push_back(sun);
  }
  if (s.blend == octoray::BlendMode::Composite)
  {
    // Node colours with an opacity per unit length, so composite is not
    // merely the first hit: a ramp over the node colours' luminance would
    // need scalars; the points' colours at 20% opacity per voxel do.
    const double radius = 0.5 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
      (hi[2] - lo[2]) * (hi[2] - lo[2]));
    s.opacityUnitDistance = static_cast<float>(5.0 * std::ldexp(radius * 2, -depth));
  }
  return s;
}

// The scale of the picture's colours: 1, but for the integrals (additive,
// average), which have no natural scale and are normalised to their
// brightest pixel.
float Gain(const octoray::Image& image, octoray::BlendMode blend)
{
  if (blend != octoray::BlendMode::Additive && blend != octoray::BlendMode::Average)
  {
    return 1.0f;
  }
  float most = 0;
  for (std::size_t i = 0; i < image.depth.size(); ++i)
  {
    most = std::max(most, std::max(image.rgba[4 * i], std::max(image.rgba[4 * i + 1], image.rgba[4 * i + 2])));
  }
  return most > 0 ? 1.0f / most : 1.0f;
}

int Render(int argc, char** argv)
{
  RenderOptions o;
  if (!o.Parse(argc, argv))
  {
    return Usage();
  }
  const Built b = LoadAndBuild(argv[2], o.engine);
  const octoray::RenderSettings s = SceneSettings(o, b.file.View(), b.stats);
  octoray::Image image;
  const octoray::RenderStats first = b.engine->Render(s, image); // buffers, caches, estimated normals
  const octoray::RenderStats stats = b.engine->Render(s, image);
  const auto start = std::chrono::steady_clock::now();
  const std::string written = WriteImage(o.output, o.width, o.height, Composite(image, Gain(image, s.blend)));
  const double writeSeconds = Seconds(start);

  const double rays = static_cast<double>(stats.primaryRays + stats.secondaryRays);
  PrintSource(b);
  std::printf("build           %.3f ms (depth %d, %zu nodes)\n", b.stats.seconds * 1e3, b.stats.depth,
    b.stats.nodes);
  if (first.normalSeconds > 0)
  {
    std::printf("normals         %.3f ms, estimated from the voxels (the points have none)\n",
      first.normalSeconds * 1e3);
  }
  std::printf("render          %.3f ms, %dx%d, mode %s%s, %zu primary + %zu secondary rays\n", stats.seconds * 1e3,
    o.width, o.height, o.mode->name, o.shadows ? " + shadows" : "", stats.primaryRays, stats.secondaryRays);
  std::printf("throughput      %.2f Mrays/s (%.2f Mrays/s primary)\n", rays / stats.seconds * 1e-6,
    static_cast<double>(stats.primaryRays) / stats.seconds * 1e-6);
  std::printf("wrote           %s (%.3f s)\n", written.c_str(), writeSeconds);
  return 0;
}
}
