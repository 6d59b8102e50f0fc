// The CPU backend: the shared build and update (OctreeDriver.h) on the
// CPU device, and rendering that runs the shared per-pixel function
// (RenderKernels.h) over rows interleaved across threads.
#include "CpuEngine.h"

#include "Frame.h"

#include <chrono>

namespace octoray
{
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
  DispatchFeatures(frame, [&](auto features) {
    using F = decltype(features);
    ParallelChunks(static_cast<std::size_t>(threads), threads, [&](std::size_t, std::size_t, int t) {
      std::size_t rays = 0;
      for (int y = t; y < settings.height; y += threads)
      {
        for (int x = 0; x < settings.width; ++x)
        {
          const std::size_t i = static_cast<std::size_t>(y) * settings.width + x;
          float pixel[4];
          RenderPixel<F>(frame, view, x, y, pixel, image.depth[i], rays);
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
