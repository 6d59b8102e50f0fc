// octoray engine: compiler glue shared by the CPU and CUDA backends.
#pragma once

#include <cstddef>
#include <cstdint>

// Functions that run per point, per node or per pixel are written once and
// marked OCTORAY_HD: host-and-device under nvcc, plain inline C++ otherwise.
#if defined(__CUDACC__)
#define OCTORAY_HD __host__ __device__ __forceinline__
#define OCTORAY_DEVICE_CODE 1
#else
#define OCTORAY_HD inline
#define OCTORAY_DEVICE_CODE 0
#endif

// The traversal's innermost steps: inlined on the host as every OCTORAY_HD
// function is on the device; GCC's heuristics would otherwise call them
// once per child box.
#if defined(__CUDACC__)
#define OCTORAY_HD_INLINE OCTORAY_HD
#else
#define OCTORAY_HD_INLINE inline __attribute__((always_inline))
#endif

// The body of a loop that a backend runs per element (Device::ForEach and
// the other primitives of OctreeDriver.h), as pbrt-v4's PBRT_CPU_GPU_LAMBDA:
// it captures by value, because under nvcc it is copied to the GPU (an
// extended lambda: the CUDA build passes --extended-lambda). On the host
// it is inlined into the backend's loop: once the level loops' bodies grew,
// GCC called them once per node, which cost the CPU build a fifth of its
// level phase (Benchmarks/gpu/variants-small-levels.txt, call 9's note).
#if defined(__CUDACC__)
#define OCTORAY_LAMBDA(...) [=] __host__ __device__(__VA_ARGS__)
#else
#define OCTORAY_LAMBDA(...) [=](__VA_ARGS__) __attribute__((always_inline))
#endif

namespace octoray
{
// A loop body (OCTORAY_LAMBDA) that asks CUDA for `Blocks` blocks a
// multiprocessor: its kernel's launch bounds, to which the compiler fits
// its registers (CudaDevice::ForEach). The CPU runs it as any other body.
// Loops that do not ask get kLoopBlocks.
constexpr int kLoopBlocks = 4;

template <int Blocks, typename Fn>
struct Occupying
{
  Fn body;
  OCTORAY_HD_INLINE void operator()(std::size_t i) const { body(i); }
};

template <int Blocks, typename Fn>
Occupying<Blocks, Fn> BlocksPerMultiprocessor(Fn body)
{
  return Occupying<Blocks, Fn>{ body };
}

// Deepest level of the octree: 21 bits per axis fill a 63-bit Morton key.
constexpr int kMaxLevel = 21;
constexpr std::uint32_t kInvalidIndex = 0xFFFFFFFFu;

// Where a device's PlaceNested (OctreeDriver.h) writes `count` lists, one a
// level of the octree at most, each with one entry more than it has items:
// the last list in `last`, the others end to end in `packed`, which has
// room for `packedRoom` entries. The sizes of the packed lists are known
// only once they are counted, on the device: where they do not fit, the
// last list alone is written.
struct NestedLists
{
  static constexpr int kMaxLists = kMaxLevel + 1;
  int count;
  std::uint32_t* last;
  std::uint32_t* packed;
  std::size_t packedRoom;

  // List l, after `itemsBefore` items of the lists before it.
  OCTORAY_HD std::uint32_t* List(int l, std::size_t itemsBefore) const
  {
    return l + 1 == count ? last : packed + itemsBefore + l;
  }

  // Whether the packed lists, of `packedItems` items together, fit.
  OCTORAY_HD bool PackedFit(std::size_t packedItems) const { return packedItems + (count - 1) <= packedRoom; }
};

// A histogram that a device's CountNested adds up in the same pass over
// the items as its lists: counts[binOf(i)] += 1 for each item i whose bin
// is in [0, Bins) (-1: none). The automatic depth's lone points
// (DepthChoice.h's LoneLevels) are counted so, beside the levels' run
// starts, where a histogram pass of their own read the sorted keys once
// more: on an H200 the count with them took 50 us at 10 M points, the
// histogram pass 38 and the count alone 31
// (Benchmarks/gpu/variants-auto-depth-count.txt).
template <int Bins, typename BinOf>
struct SideHistogram
{
  static constexpr int kBins = Bins;
  BinOf binOf;
  std::uint64_t* counts;
};

// No histogram beside the lists: what a build of a requested depth counts.
struct NoBin
{
  OCTORAY_HD int operator()(std::size_t) const { return -1; }
};
using NoSideHistogram = SideHistogram<0, NoBin>;
}
