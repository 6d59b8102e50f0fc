// Eight rays through the octree at once, for the CPU backend: one walk of
// the octree for the packet, each step's arithmetic done in SIMD lanes, one
// ray per lane. Host only (GCC and Clang vector extensions): the GPU's
// threads are its lanes already.
//
// The walk is Traverse's (Traversal.h) for every lane at once. Rays of one
// octant of directions (DirectionSigns) visit a node's children in the same
// order, by increasing mirrored octant, so one depth-first walk of the
// union of the lanes' visits holds each lane's own visits in its own order.
// Each lane keeps its own set of children left, the very set Traverse keeps
// for that ray, as one byte of a 64-bit word per node; the walk steps to
// the lowest child any lane has left, and every value a lane computes is
// the one Traverse computes for its ray, bit for bit. Each lane's visitor
// therefore sees what Traverse shows it, in the same order, until it says
// stop, and the pictures are the same.
//
// A lane the packet cannot take (a direction in another octant than the
// first lane's, a zero component, a root that the level of detail stops
// at) is traced alone by Traverse, and so is every ray of a packet of
// fewer than kMinPacketRays.
#pragma once

#include "Traversal.h"

#include <cstring>

namespace octoray
{
constexpr int kPacketLanes = 8;
// A walk of the packet costs about what four rays alone do (the "packets"
// and "Traverse" columns of octoray_bench_render --parts traversal): fewer
// rays than this are traced alone.
constexpr int kMinPacketRays = 4;

typedef float PacketFloats __attribute__((vector_size(4 * kPacketLanes)));
typedef std::int32_t PacketInts __attribute__((vector_size(4 * kPacketLanes)));
typedef std::uint8_t PacketBytes __attribute__((vector_size(kPacketLanes)));

// A byte per lane in a 64-bit word: lane i is byte i.
constexpr std::uint64_t kEveryLaneByte = 0x0101010101010101ull;

// Lane `lane` alone, as a set of lanes in bytes of 0xFF.
constexpr std::uint64_t OneLane(int lane)
{
  return std::uint64_t{ 0xFF } << (8 * lane);
}

// Lanes where a comparison held, as bytes of 0xFF.
inline std::uint64_t LaneBytes(PacketInts comparison)
{
  const PacketBytes bytes = __builtin_convertvector(comparison, PacketBytes);
  std::uint64_t word;
  std::memcpy(&word, &bytes, sizeof word);
  return word;
}

// The 8-bit sets of each lane, as bytes.
inline std::uint64_t LaneSets(PacketInts sets)
{
  return LaneBytes(sets & 0xFF);
}

// The lanes whose set holds bit b, as bytes of 0xFF.
inline std::uint64_t LanesHolding(std::uint64_t sets, unsigned b)
{
  return ((sets >> b) & kEveryLaneByte) * 0xFFu;
}

// Every lane's set joined.
inline unsigned UnionOfLanes(std::uint64_t sets)
{
  sets |= sets >> 32;
  sets |= sets >> 16;
  sets |= sets >> 8;
  return static_cast<unsigned>(sets) & 0xFFu;
}

// The packet's rays, lane by lane, and the span of each through the root.
struct RayPacket
{
  PacketFloats origin[3], inverse[3];
  PacketFloats tMin, tMax, tEnter, tExit;
  PacketFloats lodPixels, footprint0, footprintSlope; // LevelOfDetail's, per lane
  bool lodOn = false;                                  // in any lane
  unsigned signs = 0;
  std::uint64_t lanes = 0; // bytes of 0xFF for the lanes taking part

  // Lane `lane` takes the ray, whose span through the root is `root`.
  void Take(int lane, const Ray& ray, const NodeHit& root, const LevelOfDetail& lod)
  {
    lanes |= OneLane(lane);
    for (int a = 0; a < 3; ++a)
    {
      origin[a][lane] = ray.origin[a];
      inverse[a][lane] = ray.inverse[a];
    }
    tMin[lane] = ray.tMin;
    tMax[lane] = ray.tMax;
    tEnter[lane] = root.tEnter;
    tExit[lane] = root.tExit;
    lodPixels[lane] = lod.pixels;
    footprint0[lane] = lod.footprint0;
    footprintSlope[lane] = lod.footprintSlope;
    lodOn = lodOn || lod.pixels > 0.0f;
  }
  // The lanes left out get finite values, which no set of theirs reads.
  void FillLanesLeftOut()
  {
    for (int lane = 0; lane < kPacketLanes; ++lane)
    {
      if (!(lanes & OneLane(lane)))
      {
        for (int a = 0; a < 3; ++a)
        {
          origin[a][lane] = 0.0f;
          inverse[a][lane] = 1.0f;
        }
        tMin[lane] = tMax[lane] = tEnter[lane] = tExit[lane] = 0.0f;
        lodPixels[lane] = footprint0[lane] = footprintSlope[lane] = 0.0f;
      }
    }
  }
};

// One lane's crossings.
inline NodeCrossings LaneOf(const Crossings<PacketFloats>& c, int lane)
{
  NodeCrossings one;
  for (int a = 0; a < 3; ++a)
  {
    one.nearT[a] = c.nearT[a][lane];
    one.midT[a] = c.midT[a][lane];
    one.farT[a] = c.farT[a][lane];
  }
  return one;
}

// Of the lanes `entering` the child, those that stop at it (as Traverse's
// rays): all at the leaves, else those whose level of detail stops there.
inline std::uint64_t DrawnLanes(const OctreeView& tree, const RayPacket& p, const WalkChild& child,
  const ChildSpan<PacketFloats>& span, std::uint64_t entering)
{
  if (child.level == tree.depth)
  {
    return entering;
  }
  return p.lodOn
    ? entering & LaneBytes(FootprintCovers(child.size, p.lodPixels, p.footprint0, p.footprintSlope, span.tEnter))
    : 0;
}

// Shows the child, in mirrored octant m of the node whose crossings are c,
// to the visitor of each lane in `drawn`; returns the lanes whose visitors
// said stop, as bytes of 0xFF.
template <typename Visitor>
std::uint64_t VisitLanes(std::uint64_t drawn, const Crossings<PacketFloats>& c, unsigned m,
  const ChildSpan<PacketFloats>& span, const WalkChild& child, Visitor visitors[kPacketLanes])
{
  std::uint64_t stopped = 0;
  for (int lane = 0; lane < kPacketLanes; ++lane)
  {
    if (drawn & OneLane(lane))
    {
      const float tEnter = span.tEnter[lane], tExit = span.tExit[lane];
      if (visitors[lane].Visit(child.Hit(tEnter, tExit, EntryAxis(LaneOf(c, lane), m, tEnter))))
      {
        stopped |= OneLane(lane);
      }
    }
  }
  return stopped;
}

// The walk for the lanes of p (Traverse's loop, TraverseFromRoot, for each
// lane; see the header), visitors[lane] seeing its lane's voxels. `todo`
// and the paused nodes hold a set per lane.
template <typename Visitor>
void TraversePacket(const OctreeView& tree, const RayPacket& p, Visitor visitors[kPacketLanes])
{
  struct PausedNodes
  {
    std::uint32_t firstChild;
    unsigned childMask;
    std::uint64_t todo;
  };
  PausedNodes paused[kMaxLevel];
  unsigned pausedLevels = 0;
  std::uint64_t live = p.lanes; // lanes whose visitors still look
  WalkNode<PacketFloats> node;
  node.StartAtRoot<false>(tree, p, p.signs);
  std::uint64_t todo = live & LaneSets(static_cast<int>(MirrorOctants(node.childMask, p.signs)) &
                                 MetOctants(node.c.midT, Later(p.tEnter, p.tMin), Earlier(p.tExit, p.tMax)));
  while (live)
  {
    const unsigned any = UnionOfLanes(todo);
    if (!any)
    {
      if (!pausedLevels)
      {
        return;
      }
      const int level = HighestBit(pausedLevels);
      pausedLevels &= ~(1u << level);
      node.ClimbTo<false>(level, paused[level].firstChild, paused[level].childMask, p, p.signs);
      todo = paused[level].todo & live;
      continue;
    }
    const unsigned m = LowestBit(any);
    const std::uint64_t entering = LanesHolding(todo, m); // the lanes that meet child m
    todo &= ~(kEveryLaneByte << m);
    const ChildSpan<PacketFloats> span = SpanOf(node.c, m);
    const WalkChild child = node.Child(m, p.signs);
    const std::uint64_t drawn = DrawnLanes(tree, p, child, span, entering);
    if (drawn)
    {
      live &= ~VisitLanes(drawn, node.c, m, span, child, visitors);
      todo &= live;
    }
    const std::uint64_t descending = entering & ~drawn;
    if (!descending)
    {
      continue;
    }
    PacketFloats innerMidT[3];
    for (int a = 0; a < 3; ++a)
    {
      innerMidT[a] = child.MidCrossing<false>(p, a);
    }
    const std::uint64_t groupMasks = tree.childMasks[child.node >> 3];
    const unsigned grandchildMask = MaskInWord(groupMasks, child.node);
    const std::uint64_t met = descending &
      LaneSets(static_cast<int>(MirrorOctants(grandchildMask, p.signs)) &
        MetOctants(innerMidT, Later(span.tEnter, p.tMin), Earlier(span.tExit, p.tMax)));
    // Every lane that met the child goes on, here or after it, with the
    // children that can still follow it (as Traverse's `after`).
    todo = (todo & ~descending) | (todo & descending & (OctantsAfter(m) * kEveryLaneByte));
    if (!met)
    {
      continue;
    }
    if (todo)
    {
      paused[node.level] = PausedNodes{ node.firstChild, node.childMask, todo };
      pausedLevels |= 1u << node.level;
    }
    node.Enter(tree, m, child, innerMidT, groupMasks, grandchildMask);
    todo = met;
  }
}

// Up to kPacketLanes rays, each shown to its visitor as Traverse would show
// it: `valid` has a bit per lane whose ray exists. Lanes the packet cannot
// take are traced one by one. The instruction set is TracePacket's choice
// (below).
template <typename Visitor>
void TracePacketOf(const OctreeView& tree, const Ray rays[kPacketLanes], const LevelOfDetail lods[kPacketLanes],
  unsigned valid, Visitor visitors[kPacketLanes])
{
  RayPacket p;
  p.signs = 8; // none yet
  unsigned alone = 0, packed = 0; // a bit per lane
  for (int lane = 0; lane < kPacketLanes; ++lane)
  {
    const Ray& ray = rays[lane];
    NodeHit root;
    if (!((valid >> lane) & 1u) || !MeetsRoot(ray, root))
    {
      continue;
    }
    const unsigned signs = DirectionSigns(ray);
    if (HasParallelAxis(ray) || DrawsRoot(tree, lods[lane], root.tEnter) || (p.signs != 8 && signs != p.signs))
    {
      alone |= 1u << lane;
      continue;
    }
    p.signs = signs;
    p.Take(lane, ray, root, lods[lane]);
    packed |= 1u << lane;
  }
  if (__builtin_popcount(packed) < kMinPacketRays)
  {
    alone |= packed;
    p.lanes = 0;
  }
  if (p.lanes)
  {
    p.FillLanesLeftOut();
    TraversePacket(tree, p, visitors);
  }
  for (int lane = 0; lane < kPacketLanes; ++lane)
  {
    if ((alone >> lane) & 1u)
    {
      Traverse(tree, rays[lane], lods[lane], visitors[lane]);
    }
  }
}

// TracePacketOf with everything it calls inlined, compiled for the
// baseline instruction set (on x86-64, two SSE registers per lane vector)
// or, where the processor has it, for AVX2 (eight lanes in one register).
// Inlining keeps the AVX2 instructions inside their one function, so a
// processor without them never meets them, and no 256-bit vector crosses a
// call between code built for different ABIs. No FMA: products and sums
// round as the per-ray path's do.
template <typename Visitor>
__attribute__((flatten)) void TracePacketBaseline(const OctreeView& tree, const Ray rays[kPacketLanes],
  const LevelOfDetail lods[kPacketLanes], unsigned valid, Visitor visitors[kPacketLanes])
{
  TracePacketOf(tree, rays, lods, valid, visitors);
}

#if defined(__x86_64__)
template <typename Visitor>
__attribute__((target("avx2"), flatten)) void TracePacketAvx2(const OctreeView& tree, const Ray rays[kPacketLanes],
  const LevelOfDetail lods[kPacketLanes], unsigned valid, Visitor visitors[kPacketLanes])
{
  TracePacketOf(tree, rays, lods, valid, visitors);
}

inline bool HasAvx2()
{
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}
#else
template <typename Visitor>
void TracePacketAvx2(const OctreeView& tree, const Ray rays[kPacketLanes], const LevelOfDetail lods[kPacketLanes],
  unsigned valid, Visitor visitors[kPacketLanes])
{
  TracePacketBaseline(tree, rays, lods, valid, visitors);
}

inline bool HasAvx2()
{
  return false;
}
#endif

template <typename Visitor>
void TracePacket(const OctreeView& tree, const Ray rays[kPacketLanes], const LevelOfDetail lods[kPacketLanes],
  unsigned valid, Visitor visitors[kPacketLanes])
{
  HasAvx2() ? TracePacketAvx2(tree, rays, lods, valid, visitors)
            : TracePacketBaseline(tree, rays, lods, valid, visitors);
}
}
