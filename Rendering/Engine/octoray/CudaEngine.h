// The CUDA backend's engine (compiled by nvcc only).
#pragma once

#include "CudaSupport.h"
#include "Engine.h"
#include "PointArrays.h"

#include <memory>

namespace octoray
{
class CudaEngine final : public Engine
{
public:
  // Works on `device` (-1: the caller's current device).
  explicit CudaEngine(int device);
  ~CudaEngine() override;

  Backend Kind() const override { return Backend::CUDA; }
  std::string Description() const override;
  BuildStats Build(const PointCloudView& points, const BuildOptions& options) override;
  UpdateStats Update(const PositionsView& positions) override;
  RenderStats Render(const RenderSettings& settings, Image& image) override;
  std::size_t PointCount() const override { return State->count; }
  void CopyToHost(HostOctree& out) const override;
  MemoryReport Memory() const override;

  // Device bytes the engine may hold; allocations beyond it fail with the
  // out-of-memory error, as a full GPU would.
  void SetMemoryBudget(std::size_t bytes) override { Pool.budget = bytes; }

  // Everything one octree holds on the device.
  struct DeviceState
  {
    std::size_t count = 0;
    unsigned attributes = 0;
    DeviceBuffer<float> xyzFloat;
    DeviceBuffer<double> xyzDouble;
    DeviceBuffer<std::uint8_t> color8;
    DeviceBuffer<Rgba> colorFloat;
    DeviceBuffer<float> scalar, reflectivity, refraction;
    DeviceBuffer<Vec3f> normal;
    DeviceBuffer<std::uint64_t> pointKey;

    int depth = 0;
    RootCube cube;
    std::uint32_t levelBegin[kMaxLevel + 2] = {};
    DeviceBuffer<std::uint64_t> key;
    DeviceBuffer<std::uint8_t> childMask;
    DeviceBuffer<std::uint32_t> firstChild, parent, pointCount;
    DeviceBuffer<Rgba> nodeColor;
    DeviceBuffer<float> nodeScalar, nodeReflectivity, nodeRefraction;
    DeviceBuffer<Vec3f> nodeNormal;

    PointArraysView Points() const;
    OctreeView View() const;
  };

  OctreeView View() const { return State->View(); }

  // The last frame in device memory: premultiplied RGBA (4 floats a pixel)
  // and window depth, rows from the bottom.
  const float* DeviceImageRgba() const { return ImageRgba.Get(); }
  const std::uint8_t* DeviceImageRgba8() const { return ImageRgba8.Get(); }
  const float* DeviceImageDepth() const { return ImageDepth.Get(); }
  DeviceImage LastDeviceImage() const override;
  std::uint64_t DeviceDepthSignature(const float* deviceDepth, std::size_t count) override;

private:
  void DataBounds(const DeviceState& s, double lo[3], double hi[3]);
  BuildStats BuildFromState(DeviceState& s, const RootCube& cube, int requestedDepth);
  void* CubTemp(std::size_t bytes);
  // Counts and means adjusted along the paths of the points that changed
  // leaf (device array of LeafMove); false, with nothing changed, when a
  // node would appear or empty.
  bool UpdateInPlace(DeviceState& s, const void* moves, std::size_t changed);
  // The update proper; sets `writing` before its first write to the state.
  UpdateStats UpdateState(DeviceState& s, const PositionsView& positions, bool& writing);

  int Device = 0;
  std::string DeviceName;
  int ImageWidth = 0, ImageHeight = 0;
  bool ImageIs8Bit = false;
  // Declared first so that it is destroyed last: the destructor makes the
  // engine's device current and this restores the caller's once every
  // buffer below is freed.
  std::unique_ptr<ScopedDevice> DestructionScope;
  // Declared before the buffers so that it outlives them.
  DeviceMemoryPool Pool;
  std::unique_ptr<DeviceState> State;
  // Set when an update failed part-way and dropped the octree; cleared by a build.
  bool DiscardedByUpdate = false;
  // Scratch kept across builds so that rebuilds of similar size reuse it.
  DeviceBuffer<std::uint64_t> SortKey[2];
  DeviceBuffer<std::uint32_t> SortIndex[2];
  DeviceBuffer<std::uint32_t> Starts;
  DeviceBuffer<unsigned char> CubScratch;
  // Per-frame buffers, kept while the viewport keeps its size.
  DeviceBuffer<Rgba> Transfer;
  DeviceBuffer<float> DepthIn, ImageRgba, ImageDepth;
  DeviceBuffer<std::uint8_t> ImageRgba8;
  DeviceBuffer<unsigned long long> RayCounter;
};
}
