// What both backends' engines do the same way, once: build, update, copy to
// the host and the memory report, through the driver (OctreeDriver.h) on
// the backend's device. CpuEngine and CudaEngine add how they render.
#pragma once

#include "Engine.h"
#include "NormalEstimation.h"
#include "OctreeDriver.h"

#include <memory>
#include <utility>

namespace octoray
{
template <class Device>
class OctreeEngine : public Engine
{
public:
  template <typename... DeviceArguments>
  explicit OctreeEngine(DeviceArguments&&... arguments)
    : Dev(std::forward<DeviceArguments>(arguments)...)
    , State(std::make_unique<OctreeState<Device>>())
  {
  }

  BuildStats Build(const PointCloudView& points, const BuildOptions& options) override
  {
    const auto scope = Dev.Scope();
    const auto start = std::chrono::steady_clock::now();
    BuildStats stats;
    try
    {
      stats = BuildOctree(Dev, Scratch, State, points, options);
    }
    catch (const Error&)
    {
      Dev.TrimCache(); // a failed build (out of memory, say) gives back what it took
      throw;
    }
    DiscardedByUpdate = false;
    ForgetEstimatedNormals();
    stats.bytes = Memory().Total();
    stats.seconds = SecondsSince(start);
    return stats;
  }

  // An update writes into the octree it updates. When it fails after the
  // first write (a refused launch, out of memory), points and nodes may
  // disagree and no picture drawn from them could be trusted, so the octree
  // is dropped (its memory freed) and the caller is told to build again.
  UpdateStats Update(const PositionsView& positions) override
  {
    const auto scope = Dev.Scope();
    ValidateUpdate(positions, State->count, DiscardedByUpdate, State->keepPoints);
    bool writing = false;
    try
    {
      ForgetEstimatedNormals(); // the nodes change, and an update may fail part-way
      return UpdateOctree(Dev, Scratch, *State, positions, writing);
    }
    catch (const Error& e)
    {
      Dev.TrimCache();
      if (!writing)
      {
        throw;
      }
      State = std::make_unique<OctreeState<Device>>();
      DiscardedByUpdate = true;
      throw Error(DiscardedByUpdateMessage(e.what()));
    }
  }

  std::size_t PointCount() const override { return State->count; }

  void CopyToHost(HostOctree& out) const override
  {
    const auto scope = Dev.Scope();
    const OctreeState<Device>& s = *State;
    out.depth = s.depth;
    out.cube = s.cube;
    out.scalarRange = s.scalarRange;
    out.attributes = s.attributes;
    out.levelBegin.assign(s.levelBegin, s.levelBegin + kMaxLevel + 2);
    ForEachNodeArray([&](auto a) { Dev.Download(a.Of(s.nodes), a.Of(out)); });
  }

  MemoryReport Memory() const override
  {
    return ReportMemory(*State, Scratch.Bytes() + Dev.ScratchBytes(), Dev.CachedBytes());
  }

  // The octree in the device's memory, for the renderer.
  OctreeView View() const { return State->View(); }

  // The octree as a frame of `settings` shades it: with the normals
  // estimated from its voxels where it has none of its own and the frame
  // asks for them (made now if not yet made for these nodes, the seconds
  // that took in `normalSeconds`).
  OctreeView ShadingView(const RenderSettings& settings, double& normalSeconds)
  {
    normalSeconds = 0.0;
    OctreeView view = View();
    if (view.normal || !settings.estimateNormals || !FrameUsesNormals(settings, view.attributes))
    {
      return view;
    }
    if (!State->normalsEstimated)
    {
      const auto start = std::chrono::steady_clock::now();
      EstimateNormals(Dev, *State);
      normalSeconds = SecondsSince(start);
    }
    view.normal = State->estimatedNormals.Get();
    return view;
  }

protected:
  void ForgetEstimatedNormals()
  {
    State->normalsEstimated = false;
    Dev.Release(State->estimatedNormals);
  }

  // Declared first, so that its memory (CudaDevice's pool) outlives every
  // buffer below and in derived engines.
  mutable Device Dev;
  DriverScratch<Device> Scratch;
  std::unique_ptr<OctreeState<Device>> State;
  // Set when an update failed part-way and dropped the octree; cleared by a build.
  bool DiscardedByUpdate = false;
};
}
