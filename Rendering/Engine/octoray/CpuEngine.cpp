// The CPU backend: the shared build and update (OctreeDriver.h) on the
// CPU device, and rendering over rows interleaved across threads: the
// primary rays of eight pixels at a time through one walk of the octree
// (PacketTraversal.h), each pixel then made by the shared per-pixel
// functions (RenderKernels.h).
#include "CpuEngine.h"

#include "Frame.h"
#include "PacketTraversal.h"

#include <algorithm>
#include <chrono>
#include <type_traits>

namespace octoray
{
namespace
{
// A surface pixel (RenderPixel's) from the first voxel its ray hits and,
// with shadows, that hit's shadow rays.
template <typename F>
void SurfacePixel(const FrameConstants& f, const OctreeView& tree, const CameraRay& pixel,
  const FirstHitVisitor& first, const TracedShadows* shadows, float rgba[4], float& depth,
  std::size_t& secondaryRays)
{
  if constexpr (F::kSecondary)
  {
    TracedPixel<F>(f, tree, pixel, &first, shadows, rgba, depth, secondaryRays);
  }
  else
  {
    ShadeFirstHit<F>(f, tree, pixel, first, shadows, rgba, depth, secondaryRays);
  }
}

// The shadow rays of a packet's first hits, one packet per light: from
// neighbouring hits towards one light they are about as coherent as the
// primary rays (a directional light's all parallel). The rays and the test
// are ShadeSurface's own (SurfaceAt, SampleLight, ShadowRay), so each lane
// gets what ShadeSurface would have traced for it.
void TraceShadowPackets(const FrameConstants& f, const OctreeView& tree, const CameraRay pixels[kPacketLanes],
  const FirstHitVisitor hits[kPacketLanes], unsigned valid, TracedShadows shadows[kPacketLanes])
{
  LevelOfDetail lods[kPacketLanes];
  unsigned hit = 0;
  for (int lane = 0; lane < kPacketLanes; ++lane)
  {
    if (((valid >> lane) & 1u) && hits[lane].found)
    {
      shadows[lane].surface = SurfaceAt(f, tree, pixels[lane].ray, hits[lane].hit);
      lods[lane] = pixels[lane].lod;
      hit |= 1u << lane;
    }
  }
  for (int i = 0; hit && i < LightsOf(f); ++i)
  {
    Ray rays[kPacketLanes];
    unsigned facing = 0;
    for (int lane = 0; lane < kPacketLanes; ++lane)
    {
      if ((hit >> lane) & 1u)
      {
        const LightSample light = SampleLight(f, i, shadows[lane].surface);
        if (light.cosine > 0.0f && ShadowRay(f, shadows[lane].surface, hits[lane].hit, light, rays[lane]))
        {
          facing |= 1u << lane;
        }
      }
    }
    FirstHitVisitor blockers[kPacketLanes];
    TracePacket(tree, rays, lods, facing, blockers);
    for (int lane = 0; lane < kPacketLanes; ++lane)
    {
      shadows[lane].occluded[i] = blockers[lane].found;
    }
  }
}

// A row of pixels, eight at a time: their primary rays from one walk of the
// octree (PacketTraversal.h), each seen by its pixel's visitor, and the
// first hits' shadow rays as packets too; then each pixel made from what
// its visitors saw, as RenderPixel makes it.
// store(x, rgba) keeps a pixel.
template <typename F, typename Store>
void RenderRow(
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
    using Visitor = std::conditional_t<F::kVolume, BlendVisitor, FirstHitVisitor>;
    Visitor visitors[kPacketLanes];
    if constexpr (F::kVolume)
    {
      std::fill_n(visitors, kPacketLanes, BlendVisitor{ &f, &tree });
      for (int lane = 0; lane < lanes; ++lane)
      {
        visitors[lane].tEnd = (valid >> lane) & 1u ? rays[lane].tMax : 0.0f;
      }
    }
    TracePacket(tree, rays, lods, valid, visitors);
    TracedShadows shadows[kPacketLanes];
    if constexpr (F::kShadows)
    {
      TraceShadowPackets(f, tree, pixels, visitors, valid, shadows);
    }
    for (int lane = 0; lane < lanes; ++lane)
    {
      if ((valid >> lane) & 1u)
      {
        if constexpr (F::kVolume)
        {
          ShadeBlend(f, pixels[lane], visitors[lane], rgba[lane], depthRow[x0 + lane]);
        }
        else
        {
          SurfacePixel<F>(f, tree, pixels[lane], visitors[lane], F::kShadows ? &shadows[lane] : nullptr, rgba[lane],
            depthRow[x0 + lane], secondaryRays);
        }
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
  double normalSeconds = 0.0;
  const OctreeView view = ShadingView(settings, normalSeconds);
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
        RenderRow<F>(frame, view, y, image.depth.data() + row, rays,
          [&](int x, const float pixel[4]) { store(row + x, pixel); });
      }
      secondary[t] = rays;
    });
  });
  RenderStats stats;
  stats.normalSeconds = normalSeconds;
  stats.primaryRays = pixels;
  for (std::size_t r : secondary)
  {
    stats.secondaryRays += r;
  }
  stats.seconds = SecondsSince(start);
  return stats;
}
}
