// The CUDA backend's engine (compiled by nvcc only).
#pragma once

#include "CudaDevice.h"
#include "OctreeEngine.h"

namespace octoray
{
struct FrameConstants;

class CudaEngine final : public OctreeEngine<CudaDevice>
{
public:
  // Works on `device` (-1: the caller's current device).
  explicit CudaEngine(int device);
  ~CudaEngine() override;

  Backend Kind() const override { return Backend::CUDA; }
  std::string Description() const override;
  RenderStats Render(const RenderSettings& settings, Image& image) override;
  DeviceImage LastDeviceImage() const override;
  std::uint64_t DeviceDepthSignature(const float* deviceDepth, std::size_t count) override;

  // Device bytes the engine may hold; allocations beyond it fail with the
  // out-of-memory error, as a full GPU would.
  void SetMemoryBudget(std::size_t bytes) override { Dev.Pool().budget = bytes; }

private:
  void PlaceFrameInputs(const RenderSettings& settings, FrameConstants& frame);
  double CopyImage(const RenderSettings& settings, Image& image);

  std::string DeviceName;
  // The last frame in device memory: premultiplied RGBA (4 floats or bytes a
  // pixel) and window depth, rows from the bottom.
  int ImageWidth = 0, ImageHeight = 0;
  bool ImageIs8Bit = false;
  // Per-frame buffers, kept while the viewport keeps its size.
  DeviceBuffer<Rgba> Transfer;
  DeviceBuffer<float> DepthIn, ImageRgba, ImageDepth;
  DeviceBuffer<std::uint8_t> ImageRgba8;
  DeviceBuffer<unsigned long long> RayCounter;
};
}
