// The CPU backend: the shared build and update (OctreeDriver.h) on the
// CPU device, and rendering that runs the shared per-pixel function
// (RenderKernels.h) over rows interleaved across threads.
#include "CpuEngine.h"

#include "Frame.h"
#include "PacketTraversal.h"

#include <chrono>

namespace octoray
{
namespace
{
// A surface pixel (RenderPixel's) from the first voxel its ray hits.
template <typename F>
void SurfacePixel(const FrameConstants& f, const OctreeView& tree, const CameraRay& pixel,
  const FirstHitVisitor& first, float rgba[4], float& depth, std::size_t& secondaryRays)
{
  if constexpr (F::kSecondary)
  {
    TracedPixel<F>(f, tree, pixel, &first, rgba, depth, secondaryRays);
  }
  else
  {
    ShadeFirstHit<F>(f, tree, pixel, first, rgba, depth, secondaryRays);
  }
}

// A row of surface pixels, eight at a time: their primary rays' first
// voxels from one walk of the octree (PacketTraversal.h), then each
// pixel's shading and secondary rays as RenderPixel's. store(x, rgba)
// keeps a pixel.
template <typename F, typename Store>
void RenderSurfaceRow(
  const FrameConstants& f, const OctreeView& tree, int y, float* depthRow, std::size_t& secondaryRays, Store store)
{
  for (int x0 = 0; x0 < f.width; x0 += kPacketLanes)
  {
    CameraRay pixels[kPacketLanes];
    Ray rays[kPacketLanes];
    LevelOfDetail lods[kPacketLanes];
    float rgba[kPacketLanes][4];
    unsigned valid = 0;
    const int lanes = f.width - x0 < kPacketLanes ? f.width - x0 : kPacketLanes;
    for (int lane = 0; lane < lanes; ++lane)
    {
      if (StartPixel(f, x0 + lane, y, pixels[lane], rgba[lane], depthRow[x0 + lane]))
      {
        valid |= 1u << lane;
        rays[lane] = pixels[lane].ray;
        lods[lane] = pixels[lane].lod;
      }
    }
    PacketHits hits;
    FirstHits(tree, rays, lods, valid, hits);
    for (int lane = 0; lane < lanes; ++lane)
    {
      if ((valid >> lane) & 1u)
      {
        SurfacePixel<F>(f, tree, pixels[lane], hits.lane[lane], rgba[lane], depthRow[x0 + lane], secondaryRays);
      }
      store(x0 + lane, rgba[lane]);
    }
  }
}
}

std::string CpuEngine::Description() const
{
  return "CPU (" + std::to_string(Dev.threads) + (Dev.threads == 1 ? " thread)" : " threads)");
}

void CpuEngine::SetThreadCount(int threads)
{
  Dev.threads = threads > 0 ? threads : DefaultThreadCount();
}

RenderStats CpuEngine::Render(const RenderSettings& settings, Image& image)
{
  if (settings.deviceDepthBuffer)
  {
    throw Error("octoray: the CPU backend cannot read a depth buffer in device memory");
  }
  ValidateRender(State->count, DiscardedByUpdate);
  const auto start = std::chrono::steady_clock::now();
  const OctreeView view = View();
  const FrameConstants frame = MakeFrame(settings, view);
  image.width = settings.width;
  image.height = settings.height;
  const std::size_t pixels = static_cast<std::size_t>(settings.width) * settings.height;
  image.rgba.assign(settings.rgba8 ? 0 : 4 * pixels, 0.0f);
  image.rgba8.assign(settings.rgba8 ? 4 * pixels : 0, 0);
  image.depth.resize(pixels);
  // Rows are interleaved over threads so that costly regions are shared.
  const int threads = Dev.threads;
  std::vector<std::size_t> secondary(threads, 0);
  const auto store = [&](std::size_t i, const float pixel[4]) {
    for (int c = 0; c < 4; ++c)
    {
      if (settings.rgba8)
      {
        image.rgba8[4 * i + c] = ChannelToByte(pixel[c]);
      }
      else
      {
        image.rgba[4 * i + c] = pixel[c];
      }
    }
  };
  DispatchFeatures(frame, [&](auto features) {
    using F = decltype(features);
    ParallelChunks(static_cast<std::size_t>(threads), threads, [&](std::size_t, std::size_t, int t) {
      std::size_t rays = 0;
      for (int y = t; y < settings.height; y += threads)
      {
        const std::size_t row = static_cast<std::size_t>(y) * settings.width;
        if constexpr (!F::kVolume)
        {
          RenderSurfaceRow<F>(frame, view, y, image.depth.data() + row, rays,
            [&](int x, const float pixel[4]) { store(row + x, pixel); });
        }
        else
        {
          for (int x = 0; x < settings.width; ++x)
          {
            float pixel[4];
            RenderPixel<F>(frame, view, x, y, pixel, image.depth[row + x], rays);
            store(row + x, pixel);
          }
        }
      }
      secondary[t] = rays;
    });
  });
  RenderStats stats;
  stats.primaryRays = pixels;
  for (std::size_t r : secondary)
  {
    stats.secondaryRays += r;
  }
  stats.seconds = SecondsSince(start);
  return stats;
}
}
