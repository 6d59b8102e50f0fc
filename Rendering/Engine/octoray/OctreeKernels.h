// Per-point and per-node steps of the octree build and update, written once
// for both backends: the driver (OctreeDriver.h) runs them inside the loops
// of a device, which are threads on the CPU and kernels on CUDA. Every node
// attribute is the plain mean over the points beneath it, so an inner node's
// value is the count-weighted mean of its children's and updates can adjust
// it by deltas.
#pragma once

#include "Octree.h"
#include "PointArrays.h"

#include <limits>

namespace octoray
{
// What a search for the first failing index finds when nothing fails.
constexpr std::uint64_t kNoIndex = ~std::uint64_t(0);

// Loops run their iterations concurrently on both backends; results that
// iterations share go through these.
OCTORAY_HD void AtomicMin(std::uint64_t* target, std::uint64_t value)
{
#if defined(__CUDA_ARCH__)
  static_assert(sizeof(std::uint64_t) == sizeof(unsigned long long), "64-bit atomics");
  atomicMin(reinterpret_cast<unsigned long long*>(target), static_cast<unsigned long long>(value));
#else
  std::uint64_t seen = __atomic_load_n(target, __ATOMIC_RELAXED);
  while (value < seen && !__atomic_compare_exchange_n(target, &seen, value, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED))
  {
  }
#endif
}

OCTORAY_HD void AtomicRaise(std::uint64_t* flag)
{
#if defined(__CUDA_ARCH__)
  *reinterpret_cast<volatile unsigned long long*>(flag) = 1ull;
#else
  __atomic_store_n(flag, std::uint64_t(1), __ATOMIC_RELAXED);
#endif
}

// Bounds of positions, and the first non-finite one (kNoIndex: none).
struct Bounds
{
  Vec3d lo, hi;
  std::uint64_t firstBad;
};

OCTORAY_HD Bounds EmptyBounds()
{
  constexpr double inf = std::numeric_limits<double>::infinity();
  return Bounds{ Vec3d{ inf, inf, inf }, Vec3d{ -inf, -inf, -inf }, kNoIndex };
}

// The bounds of point i of an xyz array (three coordinates a point), or
// the point as the first non-finite one, and their union: a reduction over
// the points of a flat array, which a copy can run on each piece as it
// lands (Device::StageReduced).
struct XyzPointBounds
{
  template <typename T>
  OCTORAY_HD Bounds operator()(std::size_t i, const T* xyz) const
  {
    const Vec3d p{ xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2] };
    if (!IsFinitePoint(p))
    {
      Bounds b = EmptyBounds();
      b.firstBad = i;
      return b;
    }
    return Bounds{ p, p, kNoIndex };
  }
};

struct BoundsUnion
{
  OCTORAY_HD Bounds operator()(const Bounds& x, const Bounds& y) const
  {
    return Bounds{ Min(x.lo, y.lo), Max(x.hi, y.hi), x.firstBad < y.firstBad ? x.firstBad : y.firstBad };
  }
};

// fn(slot, value) for each slot of each attribute the nodes store, of
// those in Possible, of node n (as ForEachRecordSlot for a point).
template <unsigned Possible = kAllAttributes, typename Fn>
OCTORAY_HD void ForEachNodeSlot(const OctreeView& t, std::uint32_t n, Fn&& fn)
{
  ForEachAttribute([&](auto a) {
    using A = decltype(a);
    if constexpr ((Possible & A::kBit) != 0)
    {
      if (A::Of(t))
      {
        const typename A::Type value = A::Of(t)[n];
        ForEachSlotOf(a, value, fn);
      }
    }
  });
}

// Writes sums / count into the node's present attributes.
template <typename Real>
OCTORAY_HD void StoreNodeMeans(const OctreeView& t, std::uint32_t n, const SlotSums<Real>& sums, double count)
{
  const double inv = count > 0.0 ? 1.0 / count : 0.0;
  ForEachAttribute([&](auto a) {
    using A = decltype(a);
    if (A::Of(t))
    {
      A::Of(t)[n] = AttributeValue<typename A::Type>::Mean(sums.Of(a), inv);
    }
  });
}

// Point i's leaf key at `depth` levels, on the grid of the cube (Grid());
// false, and the key 0, if it is not finite or lies outside the cube. The
// engine keeps no keys: the build and an update compute them here.
OCTORAY_HD bool ComputeLeafKey(const PointArraysView& pts, const RootCube::CellMap& grid, std::size_t i, int depth,
  std::uint64_t& key)
{
  const Vec3d p = pts.Position(i);
  std::uint32_t cell[3] = {};
  const bool inside = grid.Cell(p.x, p.y, p.z, cell);
  key = inside ? EncodeMortonAt(cell[0], cell[1], cell[2], depth) : 0;
  return inside;
}

// The points in the order of their leaf keys, as the build's sort leaves
// them. Leaf keys of depth 10 and less fit 32 bits; each travels with its
// point's record where that is one or two words (RecordsTravel), so that
// the leaf pass reads the records in order. Reading them through the
// points' indices instead costs a random read each, which in the general
// leaf loop on an H100 took longer than the sort
// (Benchmarks/gpu/variants-records.txt). Other keys
// travel with their points' indices, and so do these where the sort runs
// before the records have landed (a staged build), whose leaf loop then
// reads them so: on an H200 at 10 M points that loop took 296 us in ncu
// where the records gathered in sorted order first and the loop over them
// took 238 + 115, at 100 M 3.78 ms against 3.26 + 0.80, and the whole call
// 1.40-1.45 times the pinned copy against 1.45-1.62
// (Benchmarks/gpu/variants-direct-records.txt).
struct SortedKeys
{
  const std::uint64_t* wideKey;   // leaf keys deeper than 32 bits, else null
  const std::uint32_t* narrowKey; // leaf keys of 32 bits and less, else null
  const std::uint32_t* index;     // the points, where their records did not travel
  const std::uint32_t* records;   // the records in sorted order (the layout's stride), where they travelled
  int keyShift;                   // bits of the sorted keys below the leaf level

  static constexpr OCTORAY_HD bool Narrow(int depth) { return KeysFitWord(depth); }
  static constexpr OCTORAY_HD bool RecordsFit(int stride) { return stride <= 2; }
  static constexpr OCTORAY_HD bool RecordsTravel(int depth, int stride) { return Narrow(depth) && RecordsFit(stride); }

  OCTORAY_HD std::uint64_t LeafKey(std::size_t s) const
  {
    return (narrowKey ? std::uint64_t(narrowKey[s]) : wideKey[s]) >> keyShift;
  }
  // The record of the s-th point in sorted order.
  OCTORAY_HD const std::uint32_t* Record(const PointArraysView& pts, std::size_t s) const
  {
    return records ? records + s * pts.layout.stride : pts.Record(index[s]);
  }
};

// The attributes of most clouds, scanned or simulated: 8-bit colours,
// scalars and reflectivity; not float colours, normals (for lighting) or
// refraction (for glass). The leaf and inner loops keep the sums of every
// slot their points or children may have in registers, so a loop that may
// meet fewer attributes holds fewer: the leaf loop 39 registers on sm_90
// where it may meet every attribute 60 (four blocks a multiprocessor).
// With fewer registers more blocks fit, and these loops wait mostly on
// their loads: at 10 M points on an H200 the leaves, over records in
// sorted order, took 124 us at six blocks and 115 at kLeanLoopBlocks (32
// registers, 12 bytes spilled) where they took 163 at four, level 9 88 us
// at eight against 101 (Benchmarks/gpu/variants-lean-loops.txt). The
// leaves of a staged build read the records at random (SortedKeys); their
// kernel's bounds are the same. LinkLevels runs the loops of clouds of
// these alone as ReduceNodes<kLeanAttributes>; the general loops, at eight
// blocks, spilled 152 bytes a thread and took twice as long.
constexpr unsigned kLeanAttributes = kHasColor8 | kHasScalar | kHasReflectivity;
constexpr int kLeanLoopBlocks = 8;

// Leaf `node` holds the sorted points [begin, end): key, topology and means.
// Its points' records hold no attributes outside Possible (AttributeBits).
template <unsigned Possible = kAllAttributes>
OCTORAY_HD void ReduceLeaf(const OctreeView& t, const PointArraysView& pts, const SortedKeys& sorted,
  std::uint32_t node, std::uint32_t begin, std::uint32_t end)
{
  t.SetKey(node, sorted.LeafKey(begin));
  t.SetChildMask(node, 0);
  if ((node & 7u) == 0)
  {
    // A group that starts with a leaf holds leaves alone (they come last),
    // whose children would follow every node.
    t.childBase[node >> 3] = t.nodeCount;
  }
  t.pointCount[node] = end - begin;
  if (!t.attributes)
  {
    return;
  }
  SlotSums<double> sums;
  for (std::uint32_t s = begin; s < end; ++s)
  {
    ForEachRecordSlot<Possible>(sorted.Record(pts, s), pts.layout, [&](int k, auto x) { sums.Add(k, x, 1); });
  }
  StoreNodeMeans(t, node, sums, static_cast<double>(end - begin));
}

// Inner `node` has the children [c0, c1) (global indices, one level down):
// its key (its children's, one level up), child mask, its group's first
// child where it starts a group, count and count-weighted means. The
// children's weighted values add up in float (8-bit colours in whole
// bytes, exactly: SlotSums): eight terms at most, so the sum's relative
// error stays below 5e-7 (about 1e-7 as a rule), far inside what nodes
// store (16-bit scalars and normals) and the tests' 2e-6 for float
// attributes. In double the loop held 56 registers on an H100, four blocks
// a multiprocessor; in float 40 and six, and level 9 of 10 M points took
// 150 us against 182 (Benchmarks/gpu/variants-inner-float.txt). A leaf's
// points stay summed in double (ReduceLeaf): a leaf may hold millions.
template <unsigned Possible = kAllAttributes>
OCTORAY_HD void ReduceChildren(const OctreeView& t, std::uint32_t node, std::uint32_t c0, std::uint32_t c1)
{
  t.SetKey(node, t.Key(c0) >> 3);
  if ((node & 7u) == 0)
  {
    t.childBase[node >> 3] = c0;
  }
  unsigned mask = 0;
  std::uint32_t count = 0;
  SlotSums<float> sums;
  for (std::uint32_t c = c0; c < c1; ++c)
  {
    mask |= 1u << OctantOf(t.key[c]); // a key's low word holds its octant
    const std::uint32_t n = t.pointCount[c];
    count += n;
    if (t.attributes) // one test the compiler can take out of the loop, not one an attribute
    {
      ForEachNodeSlot<Possible>(t, c, [&](int k, auto x) { sums.Add(k, x, n); });
    }
  }
  t.SetChildMask(node, mask);
  t.pointCount[node] = count;
  if (t.attributes)
  {
    StoreNodeMeans(t, node, sums, static_cast<double>(count));
  }
}

// The inner levels, as LinkLevels reduces them a level a launch and
// Device::ReduceSmallLevels the small ones together: level l's nodes are the
// runs of equal parent keys among level l + 1's nodes, its children (c and
// j count from each level's first node; the runs' starts come from
// LinkLevels' nested lists). The nodes store no attributes outside
// Possible.
template <unsigned Possible = kAllAttributes>
struct InnerLevels
{
  OctreeView view;

  OCTORAY_HD std::uint32_t Children(int l) const { return view.LevelSize(l + 1); }

  // Node j of level l from its children [c0, c1).
  OCTORAY_HD void Reduce(int l, std::uint32_t j, std::uint32_t c0, std::uint32_t c1) const
  {
    const std::uint32_t first = view.levelBegin[l + 1];
    ReduceChildren<Possible>(view, view.levelBegin[l] + j, first + c0, first + c1);
  }
};

// In-place update: a point that changed leaf leaves every node on its old
// leaf's path to the root and joins every node on its new leaf's. Records
// (node, 2 * point + joins), depth + 1 per path, the old path first, stored
// from `first` on; grouped by node (a stable sort) they give each touched
// node's changes in a fixed order. False, with records that name no node,
// when the new leaf does not exist: the topology changes. A path's nodes
// are found by their keys, level by level (the octree keeps no links to
// parents: a key's parent is the key shifted by one octant, and updates in
// place, which alone would read such links, move few points).
OCTORAY_HD bool WritePathRecords(const OctreeView& t, std::uint32_t point, std::uint64_t fromLeaf,
  std::uint64_t toLeaf, std::size_t first, std::uint32_t* recordNode, std::uint32_t* recordPoint)
{
  const std::size_t pathLength = static_cast<std::size_t>(t.depth) + 1;
  bool found = true;
  for (int joins = 0; joins < 2; ++joins)
  {
    const std::uint64_t leafKey = joins ? toLeaf : fromLeaf;
    const std::uint32_t leaf = t.Find(t.depth, leafKey);
    found = found && leaf != kInvalidIndex;
    const std::size_t base = first + joins * pathLength;
    for (std::size_t step = 0; step < pathLength; ++step)
    {
      const int level = t.depth - static_cast<int>(step);
      recordNode[base + step] =
        leaf == kInvalidIndex ? kInvalidIndex : (step == 0 ? leaf : t.Find(level, leafKey >> (3 * step)));
      recordPoint[base + step] = 2u * point + static_cast<std::uint32_t>(joins);
    }
  }
  return found;
}

// The net change in point count of the node of the sorted records [begin, end).
OCTORAY_HD long long RecordedCountChange(const std::uint32_t* recordPoint, std::uint32_t begin, std::uint32_t end)
{
  long long dCount = 0;
  for (std::uint32_t j = begin; j < end; ++j)
  {
    dCount += (recordPoint[j] & 1u) ? 1 : -1;
  }
  return dCount;
}

// Whether the node of the records [begin, end) would be emptied (which
// changes the topology and needs the re-sort path instead).
OCTORAY_HD bool WouldEmpty(const OctreeView& t, const std::uint32_t* recordNode, const std::uint32_t* recordPoint,
  std::uint32_t begin, std::uint32_t end)
{
  const std::uint32_t n = recordNode[begin];
  return n != kInvalidIndex &&
    static_cast<long long>(t.pointCount[n]) + RecordedCountChange(recordPoint, begin, end) <= 0;
}

// Adjusts the count and means of the node of the records [begin, end) by the
// points that left and joined it.
OCTORAY_HD void ApplyRecords(const OctreeView& t, const PointArraysView& pts, const std::uint32_t* recordNode,
  const std::uint32_t* recordPoint, std::uint32_t begin, std::uint32_t end)
{
  const std::uint32_t n = recordNode[begin];
  const long long count = static_cast<long long>(t.pointCount[n]) + RecordedCountChange(recordPoint, begin, end);
  if (t.attributes)
  {
    SlotSums<double> sums;
    for (std::uint32_t j = begin; j < end; ++j)
    {
      const int weight = (recordPoint[j] & 1u) ? 1 : -1; // joins or leaves
      ForEachRecordSlot(pts.Record(recordPoint[j] >> 1), pts.layout, [&](int k, auto x) { sums.Add(k, x, weight); });
    }
    const std::uint32_t before = t.pointCount[n];
    ForEachNodeSlot(t, n, [&](int k, auto mean) { sums.Add(k, mean, before); });
    StoreNodeMeans(t, n, sums, static_cast<double>(count));
  }
  t.pointCount[n] = static_cast<std::uint32_t>(count);
}
}
