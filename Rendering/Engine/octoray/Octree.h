// The compact sparse octree: every level 0..depth stored breadth-first, each
// level sorted by its Morton key, as structure-of-arrays. Nodes exist only
// where points are, so memory is linear in occupied nodes and the whole
// layout is fixed by the sorted keys (both backends produce identical
// topology arrays).
#pragma once

#include "Attributes.h"
#include "Config.h"
#include "Morton.h"
#include "RootCube.h"
#include "Types.h"

#include <string>
#include <utility>
#include <vector>

namespace octoray
{
// Global index of the child in `octant` of a node whose children start at
// firstChild and exist where childMask has bits: children are stored in
// octant order, so the index is firstChild plus the children before it.
OCTORAY_HD std::uint32_t ChildIndex(unsigned childMask, std::uint32_t firstChild, unsigned octant)
{
  const unsigned before = childMask & ((1u << octant) - 1u);
#if defined(__CUDA_ARCH__)
  return firstChild + static_cast<std::uint32_t>(__popc(before));
#else
  // Bits of a byte summed in pairs, nibbles, then the byte: the builtin
  // would be a libgcc call on the baseline x86-64 without POPCNT.
  unsigned bits = before - ((before >> 1) & 0x55u);
  bits = (bits & 0x33u) + ((bits >> 2) & 0x33u);
  return firstChild + static_cast<std::uint32_t>((bits + (bits >> 4)) & 0x0Fu);
#endif
}

// The set bits of a 64-bit word.
OCTORAY_HD unsigned BitCount64(std::uint64_t x)
{
#if defined(__CUDA_ARCH__)
  return static_cast<unsigned>(__popcll(x));
#else
  // As ChildIndex: no libgcc call on the baseline x86-64.
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return static_cast<unsigned>((x * 0x0101010101010101ull) >> 56);
#endif
}

// Node n's child mask in its group's word of masks (Attributes.h).
OCTORAY_HD unsigned MaskInWord(std::uint64_t masks, std::uint32_t n)
{
  return static_cast<unsigned>(masks >> (8u * (n & 7u))) & 0xFFu;
}

// Node n's first child from its group's first child and word of masks: the
// children of the nodes before n in the group follow the group's first.
OCTORAY_HD std::uint32_t FirstChildInGroup(std::uint32_t groupBase, std::uint64_t masks, std::uint32_t n)
{
  const std::uint64_t before = masks & ((std::uint64_t{ 1 } << (8u * (n & 7u))) - 1u);
  return groupBase + BitCount64(before);
}

// The same from any structure of node arrays (OctreeView, HostOctree).
template <typename Tree>
OCTORAY_HD unsigned ChildMaskOf(const Tree& t, std::uint32_t n)
{
  return MaskInWord(t.childMasks[n >> 3], n);
}

template <typename Tree>
OCTORAY_HD std::uint32_t FirstChildOf(const Tree& t, std::uint32_t n)
{
  return FirstChildInGroup(t.childBase[n >> 3], t.childMasks[n >> 3], n);
}

// Plain pointers into the node arrays (host or device memory). Attribute
// pointers are null when the input lacked that attribute.
struct OctreeView
{
  int depth = 0;                                 // leaves live at this level
  std::uint32_t nodeCount = 0;
  std::uint32_t levelBegin[kMaxLevel + 2] = {};  // nodes of level l: [levelBegin[l], levelBegin[l+1])
  unsigned attributes = 0;                       // AttributeBits present
  RootCube cube;
  ScalarRange scalarRange; // the scalars' codes are relative to it (Scalar16.h)
#define OCTORAY_POINTER(member, Name, Type, ...) Type* member = nullptr;
  OCTORAY_NODE_TOPOLOGY(OCTORAY_POINTER)
  OCTORAY_ATTRIBUTES(OCTORAY_POINTER)
#undef OCTORAY_POINTER

  // Node n's child mask, written into its byte of the group's word (a char
  // type may alias any object; both backends are little-endian, so byte k
  // of a word is bits 8k to 8k + 7). Nodes of one group are written by
  // different threads, each its own byte.
  OCTORAY_HD void SetChildMask(std::uint32_t n, unsigned mask) const
  {
    reinterpret_cast<std::uint8_t*>(childMasks)[n] = static_cast<std::uint8_t>(mask);
  }

  OCTORAY_HD std::uint32_t LevelSize(int level) const
  {
    return levelBegin[level + 1] - levelBegin[level];
  }

  // Node n's level-local key, from its words (Attributes.h).
  OCTORAY_HD std::uint64_t Key(std::uint32_t n) const { return NodeKey(key, keyHigh, n); }
  OCTORAY_HD void SetKey(std::uint32_t n, std::uint64_t levelKey) const
  {
    key[n] = static_cast<std::uint32_t>(levelKey);
    if (keyHigh)
    {
      keyHigh[n] = static_cast<std::uint32_t>(levelKey >> 32);
    }
  }

  // Binary search for a node of `level` by its level-local key.
  OCTORAY_HD std::uint32_t Find(int level, std::uint64_t levelKey) const
  {
    std::uint32_t lo = levelBegin[level];
    std::uint32_t hi = levelBegin[level + 1];
    while (lo < hi)
    {
      const std::uint32_t mid = lo + (hi - lo) / 2;
      if (Key(mid) < levelKey)
      {
        lo = mid + 1;
      }
      else
      {
        hi = mid;
      }
    }
    return (lo < levelBegin[level + 1] && Key(lo) == levelKey) ? lo : kInvalidIndex;
  }
};

// A node's averaged colour, float or 8-bit, else white.
OCTORAY_HD Rgba StoredColor(const OctreeView& tree, std::uint32_t node)
{
  if (tree.color)
  {
    return tree.color[node];
  }
  if (tree.color8)
  {
    return ToRgba(tree.color8[node]);
  }
  return Rgba{ 1.0f, 1.0f, 1.0f, 1.0f };
}

// The first element of a vector or buffer (HostBuffer, DeviceBuffer), or
// null where it holds none: what views point at.
template <typename T>
T* DataOrNull(std::vector<T>& v)
{
  return v.empty() ? nullptr : v.data();
}
template <typename T>
const T* DataOrNull(const std::vector<T>& v)
{
  return v.empty() ? nullptr : v.data();
}
template <typename Buffer>
auto DataOrNull(const Buffer& b) -> decltype(b.Get())
{
  return b.Empty() ? nullptr : b.Get();
}

// A view of node arrays (NodeArrays of any buffer) with the layout of an
// octree of `depth` and those levels.
template <typename Arrays>
OctreeView MakeOctreeView(Arrays& arrays, int depth, const std::uint32_t* levelBegin, std::size_t levels,
  unsigned attributes, const RootCube& cube, const ScalarRange& scalarRange)
{
  OctreeView v;
  v.depth = depth;
  for (std::size_t l = 0; l < levels && l < kMaxLevel + 2; ++l)
  {
    v.levelBegin[l] = levelBegin[l];
  }
  v.attributes = attributes;
  v.cube = cube;
  v.scalarRange = scalarRange;
  ForEachNodeArray([&](auto a) {
    using A = decltype(a);
    A::Of(v) = const_cast<typename A::Type*>(DataOrNull(A::Of(arrays)));
  });
  v.nodeCount = v.key ? static_cast<std::uint32_t>(v.levelBegin[depth + 1]) : 0;
  return v;
}

template <typename T>
using HostVector = std::vector<T>;

// The octree in host memory (what tests and the VTK layer inspect): one
// vector per node array (Attributes.h), named as there: key, childMasks,
// childBase, pointCount, color, scalar, ...
struct HostOctree : NodeArrays<HostVector>
{
  int depth = 0;
  std::vector<std::uint32_t> levelBegin;
  unsigned attributes = 0;
  RootCube cube;
  ScalarRange scalarRange; // the scalars' codes are relative to it (Scalar16.h)

  std::size_t NodeCount() const { return key.size(); }
  std::uint64_t Key(std::size_t n) const { return NodeKey(key.data(), DataOrNull(keyHigh), n); }
  // Node n's scalar, decoded.
  float Scalar(std::size_t n) const { return DecodeScalar(scalarRange, scalar[n]); }
  OctreeView View();
};

// Bytes held by the engine, one entry per array, and last the memory its
// device's allocator keeps for reuse (kAllocatorCache), where it keeps some.
struct MemoryReport
{
  static constexpr const char* kAllocatorCache = "allocator cache";
  // What the octree's own arrays are labelled with ("node keys"), before
  // the label of their attribute (Attributes.h).
  static constexpr const char* kNodeArrays = "node ";
  // The label of the node array whose own label is `label` ("node keys").
  static std::string NodeArray(const char* label) { return kNodeArrays + std::string(label); }
  // Whether `label` names one of the octree's own arrays.
  static bool IsNodeArray(const std::string& label) { return label.rfind(kNodeArrays, 0) == 0; }

  std::vector<std::pair<std::string, std::size_t>> arrays;
  std::size_t Total() const
  {
    std::size_t total = 0;
    for (const auto& a : arrays)
    {
      total += a.second;
    }
    return total;
  }
  // The arrays alone: what a memory budget (Engine::SetMemoryBudget) counts.
  std::size_t ArrayBytes() const
  {
    std::size_t total = Total();
    if (!arrays.empty() && arrays.back().first == kAllocatorCache)
    {
      total -= arrays.back().second;
    }
    return total;
  }
  // The bytes of the arrays labelled `label`.
  std::size_t BytesOf(const std::string& label) const
  {
    std::size_t bytes = 0;
    for (const auto& a : arrays)
    {
      bytes += a.first == label ? a.second : 0;
    }
    return bytes;
  }
  // The node arrays' bytes: the octree itself.
  std::size_t NodeBytes() const
  {
    std::size_t bytes = 0;
    for (const auto& a : arrays)
    {
      bytes += IsNodeArray(a.first) ? a.second : 0;
    }
    return bytes;
  }
  void Add(const std::string& name, std::size_t bytes)
  {
    if (bytes)
    {
      arrays.emplace_back(name, bytes);
    }
  }
};

struct BuildOptions
{
  // Leaf level 1..21, or 0 to choose it from the data (DepthChoice.h).
  int depth = 0;
  // Build inside this root cube instead of one fitted to the points: keeps
  // nodes comparable across frames of an animation and across the pieces of
  // data split over parallel ranks. Every point must lie inside it.
  bool fixedCube = false;
  RootCube cube;
  // Keep the engine's copy of the points (positions, attributes, full-depth
  // keys) and the sort's buffers after the build, so that Update can move
  // points without the caller's arrays; CUDA also keeps the memory it
  // frees for the next build (the "allocator cache" of the memory report).
  // Off, the engine holds the node arrays alone, which is all that
  // rendering reads: a static scene in a third of the memory, and Update
  // refuses until the next build.
  bool keepPoints = true;
};

struct BuildStats
{
  std::size_t points = 0;
  int depth = 0;
  RootCube cube; // the root cube the octree was built in (fixed or fitted)
  std::vector<std::uint32_t> nodesPerLevel;
  std::size_t nodes = 0;
  std::size_t bytes = 0;     // MemoryReport::Total() after the build
  double seconds = 0.0;      // whole build, wall clock
  // The host's time copying the caller's arrays to the device, with the
  // positions' bounds (reduced as the copy lands), and queueing the
  // attributes' conversion into point records (colours, normals); on CUDA
  // the attributes are copied in the positions' pass of the staging.
  double uploadSeconds = 0.0;
  // The device's time (the host's on the CPU backend) of each phase:
  double keySeconds = 0.0;   // the cube from the bounds, and Morton keys
  double sortSeconds = 0.0;  // radix sort of the keys with their records or indices, and the neighbour histogram
  double levelSeconds = 0.0; // unique keys per level, links and averages
};

struct UpdateStats
{
  std::size_t moved = 0;        // points given new positions
  std::size_t changedLeaf = 0;  // of those, points that left their leaf
  enum class Path
  {
    Unchanged,     // no point left its leaf: nothing to do
    InPlace,       // same nodes: counts and averages adjusted along the moved points' paths (no colours)
    Relevel,       // nodes appeared or vanished: points re-sorted, levels rebuilt in the same buffers
    NewCube        // a point left the root cube: full rebuild around the new bounds
  } path = Path::Unchanged;
  double seconds = 0.0;
};

const char* ToString(UpdateStats::Path path);
}
