// Everything one octree holds on a backend's device (its copy of the points
// and its node arrays, in the device's buffers), the scratch the build keeps
// between builds, and what the engine reports of both.
#pragma once

#include "Octree.h"
#include "PointArrays.h"
#include "PointCloud.h"

#include <string>

namespace octoray
{
template <class Device>
struct OctreeState
{
  std::size_t count = 0;   // points
  unsigned attributes = 0; // AttributeBits of the points, and so of the nodes
  // BuildOptions::keepPoints of the build: off, `points` is empty once the
  // nodes are built (ReleasePoints, OctreeDriver.h).
  bool keepPoints = true;
  PointArrays<Device::template Buffer> points;

  int depth = 0;
  RootCube cube;
  ScalarRange scalarRange; // what the scalars' codes are relative to (Scalar16.h)
  std::uint32_t levelBegin[kMaxLevel + 2] = {}; // nodes of level l: [levelBegin[l], levelBegin[l+1])
  NodeArrays<Device::template Buffer> nodes;
  // Normals estimated from the voxels (NormalEstimation.h) for an octree of
  // points without normals, made at the first frame that shades by them
  // (RenderSettings::estimateNormals) and kept until the nodes change.
  typename Device::template Buffer<OctNormal> estimatedNormals;
  bool normalsEstimated = false;
  static constexpr const char* kEstimatedNormalsLabel = "normals (estimated)"; // a node array's (MemoryReport)

  PointArraysView Points() const
  {
    PointArraysView v;
    v.count = count;
    v.xyzFloat = DataOrNull(points.xyzFloat);
    v.xyzDouble = DataOrNull(points.xyzDouble);
    v.records = DataOrNull(points.records);
    v.layout = points.layout;
    return v;
  }

  OctreeView View() const
  {
    return MakeOctreeView(nodes, depth, levelBegin, kMaxLevel + 2, attributes, cube, scalarRange);
  }
};

// Buffers a build keeps for the next, so that rebuilds of similar size
// allocate nothing.
template <class Device>
struct DriverScratch
{
  template <typename T>
  using Buffer = typename Device::template Buffer<T>;

  // The sort's keys (64- or 32-bit) and the points' indices, each with its
  // second buffer, or the points' records in sorted order (SortedKeys,
  // OctreeKernels.h); the 32-bit key or index array the sort leaves free
  // holds run starts after it.
  Buffer<std::uint64_t> sortKey[2];
  Buffer<std::uint32_t> narrowKey[2];
  Buffer<std::uint32_t> sortIndex[2];
  Buffer<std::uint32_t> sortRecords;
  // The levels' run starts: what Device::CountNested counts for
  // PlaceNested, and the nested lists of the inner levels (the leaves' go
  // to the array the sort left free).
  Buffer<std::uint32_t> levelTally;
  Buffer<std::uint32_t> levelStarts;
  Buffer<std::uint64_t> counters; // what loops report to the host (CounterSlot, OctreeDriver.h)

  // fn(buffer) for each buffer of `scratch` but the counters (const or not).
  template <class Scratch, class Fn>
  static void ForEachScratchBuffer(Scratch& scratch, Fn&& fn)
  {
    for (int b = 0; b < 2; ++b)
    {
      fn(scratch.sortKey[b]);
      fn(scratch.narrowKey[b]);
      fn(scratch.sortIndex[b]);
    }
    fn(scratch.sortRecords);
    fn(scratch.levelTally);
    fn(scratch.levelStarts);
  }

  std::size_t Bytes() const
  {
    std::size_t bytes = counters.Bytes();
    ForEachScratchBuffer(*this, [&](const auto& buffer) { bytes += buffer.Bytes(); });
    return bytes;
  }
};

// What the engine holds, array by array, under the labels of Attributes.h;
// `sortBytes`: the scratch of the build and of the device; `cachedBytes`:
// freed memory the device keeps for the next allocations.
template <class Device>
MemoryReport ReportMemory(const OctreeState<Device>& s, std::size_t sortBytes, std::size_t cachedBytes)
{
  MemoryReport m;
  ForEachNodeArray([&](auto a) { m.Add(MemoryReport::NodeArray(a.kLabel), a.Of(s.nodes).Bytes()); });
  m.Add(MemoryReport::NodeArray(s.kEstimatedNormalsLabel), s.estimatedNormals.Bytes());
  m.Add("point positions", s.points.xyzFloat.Bytes() + s.points.xyzDouble.Bytes());
  // Each attribute's words of the records.
  const PointRecordLayout& layout = s.points.layout;
  const std::size_t perWord = layout.stride ? s.points.records.Bytes() / layout.stride : 0;
  ForEachAttribute([&](auto a) {
    m.Add(std::string("point ") + a.kLabel, layout.offset[a.kIndex] >= 0 ? RecordWords(a) * perWord : 0);
  });
  m.Add("sort buffers", sortBytes);
  m.Add(MemoryReport::kAllocatorCache, cachedBytes);
  return m;
}
}
