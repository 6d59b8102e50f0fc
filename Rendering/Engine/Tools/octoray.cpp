// octoray: the engine's command-line tool.
//   octoray stats FILE [--depth N] [--backend cpu|cuda|auto] [--threads N]
// builds the octree of a particle file and prints its statistics and costs;
//   octoray render FILE -o OUT.png [options]
// ray-traces it from a camera orbiting the data and writes the picture.
#include "OrbitCamera.h"
#include "PointFile.h"

#include <octoray/Engine.h>
#include <octoray/Frame.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>

#if OCTORAY_HAVE_OIIO
#include <OpenImageIO/imageio.h>
#endif

namespace
{
int Usage()
{
  std::fprintf(stderr,
    "usage: octoray stats FILE [--depth N] [--backend cpu|cuda|auto] [--threads N]\n"
    "  builds the octree of a particle file (3, 4, 6 or 8 columns) and prints its statistics\n"
    "       octoray render FILE -o OUT.png [--size WxH] [--mode MODE] [--depth N] [--lod K]\n"
    "                      [--shadows] [--bounces N] [--backend auto|cpu|cuda] [--threads N]\n"
    "                      [--azimuth DEG] [--elevation DEG] [--zoom F]\n"
    "  MODE: surface (flat colours, default), depthcue, phong, composite, mip, minip, average, additive\n"
    "  the camera orbits the data's centre (azimuth about +z, elevation above the xy plane);\n"
    "  PNG through OpenImageIO where it was found at build time, else binary PPM\n");
  return 2;
}

int Render(int argc, char** argv);
}

int main(int argc, char** argv)
{
  if (argc >= 3 && std::strcmp(argv[1], "render") == 0)
  {
    return Render(argc, argv);
  }
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

namespace
{
double Seconds(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

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

int Render(int argc, char** argv)
{
  const std::string path = argv[2];
  std::string output, mode = "surface", backend = "auto";
  int width = 1280, height = 720, bounces = 2, threads = 0;
  double azimuth = -60, elevation = 30, zoom = 1;
  float lod = 0;
  bool shadows = false;
  octoray::BuildOptions options;
  for (int a = 3; a < argc; ++a)
  {
    const std::string arg = argv[a];
    if (arg == "--shadows")
    {
      shadows = true;
      continue;
    }
    if (a + 1 >= argc)
    {
      return Usage();
    }
    const char* value = argv[++a];
    if (arg == "-o")
      output = value;
    else if (arg == "--size")
    {
      if (std::sscanf(value, "%dx%d", &width, &height) != 2 || width <= 0 || height <= 0)
        return Usage();
    }
    else if (arg == "--mode")
      mode = value;
    else if (arg == "--depth")
      options.depth = std::atoi(value);
    else if (arg == "--lod")
      lod = static_cast<float>(std::atof(value));
    else if (arg == "--bounces")
      bounces = std::atoi(value);
    else if (arg == "--backend")
      backend = value;
    else if (arg == "--threads")
      threads = std::atoi(value);
    else if (arg == "--azimuth")
      azimuth = std::atof(value);
    else if (arg == "--elevation")
      elevation = std::atof(value);
    else if (arg == "--zoom")
      zoom = std::atof(value);
    else
      return Usage();
  }
  if (output.empty() || !(zoom > 0))
  {
    return Usage();
  }
  octoray::RenderSettings s;
  s.width = width;
  s.height = height;
  s.maxBounces = bounces;
  s.lodPixels = lod;
  s.shadows = shadows;
  if (mode == "surface")
    s.shade = octoray::ShadeMode::Flat;
  else if (mode == "depthcue")
    s.shade = octoray::ShadeMode::DepthCue;
  else if (mode == "phong")
    s.shade = octoray::ShadeMode::Phong;
  else if (mode == "composite")
    s.blend = octoray::BlendMode::Composite;
  else if (mode == "mip")
    s.blend = octoray::BlendMode::Maximum;
  else if (mode == "minip")
    s.blend = octoray::BlendMode::Minimum;
  else if (mode == "average")
    s.blend = octoray::BlendMode::Average;
  else if (mode == "additive")
    s.blend = octoray::BlendMode::Additive;
  else
    return Usage();

  try
  {
    auto start = std::chrono::steady_clock::now();
    const octoray::PointFile file = octoray::PointFile::Load(path);
    const double loadSeconds = Seconds(start);
    std::string why;
    const bool useCuda = backend == "cuda" || (backend == "auto" && octoray::CudaAvailable(&why));
    auto engine = octoray::CreateEngine(useCuda ? octoray::Backend::CUDA : octoray::Backend::CPU);
    if (threads > 0)
      engine->SetThreadCount(threads);
    const octoray::PointCloudView points = file.View();
    const octoray::BuildStats build = engine->Build(points, options);

    // Orbit the centre of the data's bounding box; its bounding sphere
    // fits the vertical field of view at zoom 1.
    double lo[3], hi[3];
    octoray::Bounds(points, lo, hi);
    octoray::OrbitCamera camera;
    camera.azimuth = azimuth;
    camera.elevation = elevation;
    camera.zoom = zoom;
    if (!camera.Apply(lo, hi, s))
    {
      throw octoray::Error("octoray: the camera matrix is singular");
    }
    const double radius = 0.5 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
      (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (shadows)
    {
      // Shadows need a light other than the headlight: a sun above and to
      // the left of the camera, so shadows fall visibly down and right.
      octoray::Light sun;
      octoray::OrbitCamera::Direction(azimuth + 40, std::min(80.0, elevation + 35), sun.position);
      sun.position[3] = 0;
      s.lights.push_back(sun);
    }
    if (s.blend == octoray::BlendMode::Composite)
    {
      // Node colours with an opacity per unit length, so composite is not
      // merely the first hit: a ramp over the node colours' luminance would
      // need scalars; the points' colours at 20% opacity per voxel do.
      s.opacityUnitDistance = static_cast<float>(5.0 * std::ldexp(radius * 2, -build.depth));
    }

    octoray::Image image;
    engine->Render(s, image); // first frame: buffers, caches
    const octoray::RenderStats stats = engine->Render(s, image);
    float gain = 1.0f;
    if (s.blend == octoray::BlendMode::Additive || s.blend == octoray::BlendMode::Average)
    {
      // Integrals have no natural scale: normalise the brightest pixel to 1.
      float most = 0;
      for (std::size_t i = 0; i < image.depth.size(); ++i)
        most = std::max(most, std::max(image.rgba[4 * i], std::max(image.rgba[4 * i + 1], image.rgba[4 * i + 2])));
      gain = most > 0 ? 1.0f / most : 1.0f;
    }
    start = std::chrono::steady_clock::now();
    const std::string written = WriteImage(output, width, height, Composite(image, gain));
    const double writeSeconds = Seconds(start);

    const double rays = static_cast<double>(stats.primaryRays + stats.secondaryRays);
    std::printf("file            %s (%zu points, read in %.3f s)\n", path.c_str(), build.points, loadSeconds);
    std::printf("backend         %s%s%s\n", engine->Description().c_str(),
      (!useCuda && backend == "auto") ? ", CUDA not used: " : "", (!useCuda && backend == "auto") ? why.c_str() : "");
    std::printf("build           %.3f ms (depth %d, %zu nodes)\n", build.seconds * 1e3, build.depth, build.nodes);
    std::printf("render          %.3f ms, %dx%d, mode %s%s, %zu primary + %zu secondary rays\n", stats.seconds * 1e3,
      width, height, mode.c_str(), shadows ? " + shadows" : "", stats.primaryRays, stats.secondaryRays);
    std::printf("throughput      %.2f Mrays/s (%.2f Mrays/s primary)\n", rays / stats.seconds * 1e-6,
      static_cast<double>(stats.primaryRays) / stats.seconds * 1e-6);
    std::printf("wrote           %s (%.3f s)\n", written.c_str(), writeSeconds);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
}
