// The engine: one octree built from points on one backend. Both backends
// run the same build and update (OctreeDriver.h, over CpuDevice.h or
// CudaDevice.h) and the same per-point, per-node and per-pixel functions
// (OctreeKernels.h, RenderKernels.h); they differ only in where memory
// lives and how loops are launched.
#pragma once

#include "Octree.h"
#include "PointCloud.h"
#include "Render.h"

#include <memory>
#include <string>

namespace octoray
{
enum class Backend
{
  CPU,
  CUDA
};

const char* ToString(Backend backend);

class Engine
{
public:
  virtual ~Engine() = default;

  virtual Backend Kind() const = 0;
  // E.g. "CPU (2 threads)" or "CUDA (NVIDIA H100 80GB HBM3)".
  virtual std::string Description() const = 0;

  // Builds the octree of `points`, replacing any previous one. Throws Error
  // for empty input, a non-finite coordinate (naming the first such point),
  // an unsupported option or exhausted memory; the previous octree is then
  // left as it was.
  virtual BuildStats Build(const PointCloudView& points, const BuildOptions& options) = 0;

  // Moves points (all, or those listed in positions.indices). The result is
  // the octree a Build from the new positions in the same root cube would
  // give: the same nodes and counts, the same means within float rounding.
  // Points that stay in their leaf cost nothing; when points change leaf
  // but no node appears or empties, counts and means are adjusted along
  // their paths (cost proportional to the points moved); otherwise the
  // keys are computed and sorted again and the levels rebuilt in the same
  // buffers.
  // Indices must be distinct. When a point leaves
  // the root cube, the octree is rebuilt around the new bounds
  // (UpdateStats::Path::NewCube) at the same depth. Throws Error for a
  // non-finite coordinate, an index out of range or listed twice, before
  // changing anything. When the device fails part-way through an update (out
  // of memory, a refused kernel launch), the error says so and the octree is
  // dropped: Render and Update then throw until the next Build.
  virtual UpdateStats Update(const PositionsView& positions) = 0;

  // Ray-traces the octree into `image` (resized to the viewport). Throws
  // Error for settings that cannot make a picture or before any build.
  virtual RenderStats Render(const RenderSettings& settings, Image& image) = 0;

  // The last picture where the backend keeps it: device memory for CUDA
  // (valid until the next Render or Build), nothing for the CPU. A caller
  // that draws with OpenGL copies it from there into its textures without
  // a round trip through the host (RenderSettings::copyToHost off).
  virtual DeviceImage LastDeviceImage() const { return {}; }

  // DepthSignature (DepthSignature.h) of `count` depths in this engine's
  // device memory (CUDA; the CPU backend throws Error): the VTK layer keeps
  // it to know whether the opaque depth changed without reading it back.
  virtual std::uint64_t DeviceDepthSignature(const float* deviceDepth, std::size_t count);

  virtual std::size_t PointCount() const = 0;
  virtual void CopyToHost(HostOctree& out) const = 0;
  virtual MemoryReport Memory() const = 0;

  // Threads the CPU backend uses (ignored by CUDA); default: all cores.
  virtual void SetThreadCount(int threads) { (void)threads; }

  // Device bytes of arrays the CUDA backend may hold (ignored by the CPU
  // backend; MemoryReport::ArrayBytes); an allocation past it fails with
  // the out-of-memory error, as a full GPU would, and the allocator's cache
  // is given back. Default: no limit but the device's.
  virtual void SetMemoryBudget(std::size_t bytes) { (void)bytes; }
};

// The backend's engine. Throws Error when the backend is not available here
// (CUDA not compiled in, or no usable device), saying why. `cudaDevice`:
// the CUDA device the engine works on (an index below CudaDeviceCount());
// -1 keeps the calling thread's current device.
std::unique_ptr<Engine> CreateEngine(Backend backend, int cudaDevice = -1);

// Whether CreateEngine(Backend::CUDA) would succeed; if not, why.
bool CudaAvailable(std::string* why = nullptr);

// CUDA devices this process sees (0 without CUDA or without a device).
int CudaDeviceCount();
}
