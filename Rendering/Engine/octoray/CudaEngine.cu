// The CUDA backend: the shared build and update (OctreeDriver.h) on the
// CUDA device, and rendering that runs the shared per-pixel function
// (RenderKernels.h) from one kernel per frame. Every public entry point
// makes the engine's device current for its duration.
#include "CudaEngine.h"

#include "DepthSignature.h"
#include "Frame.h"

#include <chrono>

namespace octoray
{
namespace
{
// Threads of one render block (CMake's OCTORAY_RENDER_BLOCK): 16 x 8
// pixels unless set. The warps of a block are its rows taken 32 threads at
// a time, so the block's width is the width of the tile a warp traces.
#if defined(OCTORAY_RENDER_BLOCK_X) && defined(OCTORAY_RENDER_BLOCK_Y)
constexpr int kRenderBlockX = OCTORAY_RENDER_BLOCK_X;
constexpr int kRenderBlockY = OCTORAY_RENDER_BLOCK_Y;
#else
constexpr int kRenderBlockX = 16;
constexpr int kRenderBlockY = 8;
#endif
static_assert(kRenderBlockX * kRenderBlockY == 128 && (32 % kRenderBlockX == 0 || kRenderBlockX % 32 == 0),
  "128 threads (the register cap counts on it), each warp a rectangle of pixels");

// The register cap that OCTORAY_RENDER_MIN_BLOCKS (CMake) asks for.
#if defined(OCTORAY_RENDER_MIN_BLOCKS) && OCTORAY_RENDER_MIN_BLOCKS > 0
#define OCTORAY_RENDER_BOUNDS __launch_bounds__(kRenderBlockX * kRenderBlockY, OCTORAY_RENDER_MIN_BLOCKS)
#else
#define OCTORAY_RENDER_BOUNDS
#endif

template <typename F>
__global__ void OCTORAY_RENDER_BOUNDS RenderKernel(FrameConstants f, OctreeView tree, float* rgba,
  std::uint8_t* rgba8, float* depth, unsigned long long* secondaryRays)
{
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  if (x >= f.width)
  {
    return;
  }
  // Rows stride over the grid: a viewport taller than the grid's y limit
  // (65535 blocks) is still covered.
  std::size_t rays = 0;
  for (int y = blockIdx.y * blockDim.y + threadIdx.y; y < f.height; y += gridDim.y * blockDim.y)
  {
    const std::size_t i = static_cast<std::size_t>(y) * f.width + x;
    float pixel[4];
    RenderPixel<F>(f, tree, x, y, pixel, depth[i], rays);
    if (rgba8)
    {
      reinterpret_cast<uchar4*>(rgba8)[i] =
        make_uchar4(ChannelToByte(pixel[0]), ChannelToByte(pixel[1]), ChannelToByte(pixel[2]), ChannelToByte(pixel[3]));
    }
    else
    {
      reinterpret_cast<float4*>(rgba)[i] = make_float4(pixel[0], pixel[1], pixel[2], pixel[3]);
    }
  }
  if (rays)
  {
    atomicAdd(secondaryRays, static_cast<unsigned long long>(rays));
  }
}
}

CudaEngine::CudaEngine(int device)
  : OctreeEngine<CudaDevice>(device)
{
  cudaDeviceProp prop;
  CudaCheck(cudaGetDeviceProperties(&prop, Dev.Index()), "cudaGetDeviceProperties");
  DeviceName = prop.name;
}

CudaEngine::~CudaEngine()
{
  Dev.ScopeUntilDestroyed();
}

std::string CudaEngine::Description() const
{
  int count = 0;
  cudaGetDeviceCount(&count);
  return "CUDA (" + DeviceName + (count > 1 ? ", device " + std::to_string(Dev.Index()) : std::string()) + ")";
}

std::uint64_t CudaEngine::DeviceDepthSignature(const float* deviceDepth, std::size_t count)
{
  const auto scope = Dev.Scope();
  const std::uint64_t sum = Dev.Reduce(
    count, std::uint64_t(0), OCTORAY_LAMBDA(std::size_t i) { return DepthSignatureTerm(deviceDepth[i], i); },
    OCTORAY_LAMBDA(std::uint64_t a, std::uint64_t b) { return a + b; });
  return sum + count;
}

DeviceImage CudaEngine::LastDeviceImage() const
{
  DeviceImage image;
  if (ImageWidth > 0)
  {
    image.width = ImageWidth;
    image.height = ImageHeight;
    image.device = Dev.Index();
    image.rgba = ImageIs8Bit ? nullptr : ImageRgba.Get();
    image.rgba8 = ImageIs8Bit ? ImageRgba8.Get() : nullptr;
    image.depth = ImageDepth.Get();
  }
  return image;
}

// The frame's inputs in host memory (its transfer function, a depth buffer)
// copied to the device, and the frame pointed at the copies; a depth
// buffer the caller already has there is read where it is.
void CudaEngine::PlaceFrameInputs(const RenderSettings& settings, FrameConstants& frame)
{
  if (frame.transfer)
  {
    Dev.Upload(Transfer, settings.transfer.table.data(), settings.transfer.table.size(), "transfer function");
    frame.transfer = Transfer.Get();
  }
  if (settings.deviceDepthBuffer)
  {
    if (frame.depthBuffer)
    {
      throw Error("octoray: a depth buffer in host and in device memory at once");
    }
    frame.depthBuffer = settings.deviceDepthBuffer;
  }
  else if (frame.depthBuffer)
  {
    Dev.Upload(DepthIn, settings.depthBuffer.data(), settings.depthBuffer.size(), "depth buffer");
    frame.depthBuffer = DepthIn.Get();
  }
}

// The last frame into `image` where the settings ask for it (else `image`
// is left empty, the frame on the device alone); returns the copy's time.
double CudaEngine::CopyImage(const RenderSettings& settings, Image& image)
{
  image.width = settings.width;
  image.height = settings.height;
  image.rgba.clear();
  image.rgba8.clear();
  image.depth.clear();
  if (!settings.copyToHost)
  {
    return 0.0;
  }
  const auto copy = std::chrono::steady_clock::now();
  if (settings.rgba8)
  {
    Dev.Download(ImageRgba8, image.rgba8);
  }
  else
  {
    Dev.Download(ImageRgba, image.rgba);
  }
  Dev.Download(ImageDepth, image.depth);
  return SecondsSince(copy);
}

RenderStats CudaEngine::Render(const RenderSettings& settings, Image& image)
{
  const auto scope = Dev.Scope();
  ImageWidth = ImageHeight = 0; // no picture until this one is complete
  ValidateRender(State->count, DiscardedByUpdate);
  const auto start = std::chrono::steady_clock::now();
  double normalSeconds = 0.0;
  const OctreeView view = ShadingView(settings, normalSeconds);
  FrameConstants frame = MakeFrame(settings, view);
  PlaceFrameInputs(settings, frame);
  const std::size_t pixels = static_cast<std::size_t>(settings.width) * settings.height;
  if (settings.rgba8)
  {
    Dev.Reserve(ImageRgba8, 4 * pixels, "image colours");
  }
  else
  {
    Dev.Reserve(ImageRgba, 4 * pixels, "image colours");
  }
  Dev.Reserve(ImageDepth, pixels, "image depth");
  Dev.Reserve(RayCounter, 1, "counters");
  Dev.FillBytes(RayCounter.Get(), 1, 0);
  const dim3 block(kRenderBlockX, kRenderBlockY);
  const unsigned rows = (settings.height + block.y - 1) / block.y;
  const dim3 grid((settings.width + block.x - 1) / block.x, rows < 65535u ? rows : 65535u);
  DispatchFeatures(frame, [&](auto features) {
    Launch("RenderKernel", RenderKernel<decltype(features)>, grid, block, frame, view,
      settings.rgba8 ? nullptr : ImageRgba.Get(), settings.rgba8 ? ImageRgba8.Get() : nullptr, ImageDepth.Get(),
      RayCounter.Get());
  });
  Dev.Synchronize("RenderKernel");
  RenderStats stats;
  stats.normalSeconds = normalSeconds;
  stats.primaryRays = pixels;
  unsigned long long secondary = 0;
  Dev.ToHost(RayCounter.Get(), 1, &secondary, "RenderKernel");
  stats.secondaryRays = secondary;
  stats.seconds = SecondsSince(start);
  ImageWidth = settings.width;
  ImageHeight = settings.height;
  ImageIs8Bit = settings.rgba8;
  stats.copySeconds = CopyImage(settings, image);
  return stats;
}

bool CudaDeviceUsable(std::string* why)
{
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess || count == 0)
  {
    cudaGetLastError();
    if (why)
    {
      *why = status != cudaSuccess ? std::string(cudaGetErrorString(status)) : "no CUDA device";
    }
    return false;
  }
  return true;
}

int CudaDevices()
{
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess)
  {
    cudaGetLastError();
    return 0;
  }
  return count;
}

std::unique_ptr<Engine> CreateCudaEngine(int device)
{
  return std::make_unique<CudaEngine>(device);
}
}
