// Rays through the compact octree: the slab test and a front-to-back
// traversal with a bounded stack, written once for both backends.
//
// The ray lives in the unit cube [0,1)^3, its origin moved (in double, by
// the camera code) to where it enters the root cube, so float keeps voxel
// detail however far away the camera is. Boxes are half-open per axis where
// a direction component is zero: a ray running exactly along a face plane
// belongs to exactly one of the two voxels sharing that face, never to
// neither (no cracks) and the IEEE infinities of 1/0 never meet 0 (no NaN).
#pragma once

#include "Octree.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace octoray
{
// 2^e for -126 <= e <= 127, exactly, built from its bits: what ldexpf(1, e)
// returns, without the library call that the CPU pays per visited node.
OCTORAY_HD float PowerOfTwo(int e)
{
  const std::uint32_t bits = static_cast<std::uint32_t>(e + 127) << 23;
  float f;
  memcpy(&f, &bits, sizeof f);
  return f;
}

struct Ray
{
  Vec3f origin;
  Vec3f direction; // unit length
  Vec3f inverse;   // 1 / direction, +-inf for zero components
  float tMin, tMax;
};

// A component too small for its reciprocal to be finite (a zero of either
// sign, a denormal) becomes +0 with the reciprocal +inf: the ray runs
// parallel to that axis, on the + side of half-open boxes, and the sign
// tests and the parallel test (inverse == +inf) agree on it.
OCTORAY_HD void SetDirection(Ray& ray, const Vec3f& d)
{
  for (int a = 0; a < 3; ++a)
  {
    const float inverse = 1.0f / d[a];
    const bool parallel = inverse == INFINITY || inverse == -INFINITY;
    ray.direction[a] = parallel ? 0.0f : d[a];
    ray.inverse[a] = parallel ? INFINITY : inverse;
  }
}

// Entry and exit of the ray through the box [lo, lo + size); the axis of the
// entry face (-1 if the ray starts inside on every axis). False on a miss,
// and when any value is NaN.
OCTORAY_HD_INLINE bool IntersectBox(const Ray& ray, const Vec3f& lo, float size, float& tEnter, float& tExit, int& axis)
{
  tEnter = -INFINITY;
  tExit = INFINITY;
  axis = -1;
  for (int a = 0; a < 3; ++a)
  {
    if (ray.direction[a] == 0.0f)
    {
      if (!(ray.origin[a] >= lo[a] && ray.origin[a] < lo[a] + size))
      {
        return false;
      }
      continue;
    }
    const float t0 = (lo[a] - ray.origin[a]) * ray.inverse[a];
    const float t1 = (lo[a] + size - ray.origin[a]) * ray.inverse[a];
    const float tNear = t0 < t1 ? t0 : t1;
    const float tFar = t0 < t1 ? t1 : t0;
    if (tNear > tEnter)
    {
      tEnter = tNear;
      axis = a;
    }
    tExit = tFar < tExit ? tFar : tExit;
  }
  return tEnter <= tExit;
}

// Level of detail: a node at `level` whose voxel spans fewer than the
// threshold's pixels at distance t is drawn as it is (its averaged
// attributes), without descending. Footprint of a pixel grows linearly
// along the ray: footprint(t) = footprint0 + footprintSlope * t.
// Whether a node of side `voxel` (in the unit cube), met at t, is smaller
// than `pixels` pixels' footprint there (a pixel's footprint grows from
// footprint0 by footprintSlope a unit of t; t before the eye counts as 0):
// the level of detail's rule, for one ray (T a float) or a packet's lanes
// (PacketTraversal.h). False for pixels <= 0 with no test of its own: no
// side is below 0, nor below NaN where 0 meets an infinite footprint.
template <typename T>
OCTORAY_HD_INLINE auto FootprintCovers(float voxel, T pixels, T footprint0, T footprintSlope, T t)
{
  return voxel < pixels * (footprint0 + footprintSlope * (t > T{} ? t : T{}));
}

struct LevelOfDetail
{
  float footprint0 = 0.0f;
  float footprintSlope = 0.0f;
  float pixels = 0.0f; // 0 (or less): always down to the leaves

  OCTORAY_HD bool StopAt(float voxel, float t) const
  {
    return FootprintCovers(voxel, pixels, footprint0, footprintSlope, t);
  }
};

// One node the ray passes through, in front-to-back order.
struct NodeHit
{
  std::uint32_t node;
  int level;
  float tEnter, tExit;
  int axis;         // entry face axis, -1 when the ray starts inside
  Vec3f lo;         // the voxel's corner and size in the unit cube
  float size;
};

// The per-node arithmetic below serves one ray (a Ray: floats) and, on the
// CPU, the lanes of a packet of rays at once (PacketTraversal.h's
// RayPacket: vectors of floats, one lane per ray), written once for both.
// Where a comparison picks bits, `Where` and `Unless` take a bool for one
// ray and a lane mask (0 or -1 per lane) for a packet.
OCTORAY_HD_INLINE unsigned Where(bool held, unsigned bits)
{
  return held ? bits : 0u;
}

OCTORAY_HD_INLINE unsigned Unless(bool held, unsigned bits)
{
  return held ? ~bits : ~0u;
}

template <typename Lanes>
OCTORAY_HD_INLINE Lanes Where(Lanes held, unsigned bits)
{
  return held & static_cast<int>(bits);
}

template <typename Lanes>
OCTORAY_HD_INLINE Lanes Unless(Lanes held, unsigned bits)
{
  return ~(held & static_cast<int>(bits));
}

// The type of a ray's (float) or a packet's (lanes of floats) values.
template <typename Rays>
using ValuesOf = std::decay_t<decltype(Rays{}.origin[0])>;

// Where the ray crosses the plane x[a] = p. A ray parallel to the plane
// never crosses it: -inf where it runs on the plane or beyond it (boxes are
// half-open, so the plane belongs to the upper side), +inf below it. A ray
// known to have no parallel axis (MayBeParallel false: almost every ray,
// and every lane of a packet) skips that test, a third of the work of the
// traversal's crossings.
template <bool MayBeParallel = true, typename Rays>
OCTORAY_HD_INLINE ValuesOf<Rays> Crossing(const Rays& ray, int a, float p)
{
  if constexpr (MayBeParallel)
  {
    if (ray.inverse[a] == INFINITY) // parallel (SetDirection)
    {
      return p <= ray.origin[a] ? -INFINITY : INFINITY;
    }
  }
  return (p - ray.origin[a]) * ray.inverse[a];
}

// The ray against one node, in the node's octants as the ray sees them:
// octant bit a of a child is flipped where the ray runs towards -a, so that
// on every axis the ray crosses the near face (the child's bit 0 side), the
// mid plane, then the far face. A child's interval is thus picked from
// these nine values without any arithmetic, and a child's near and far
// faces are its parent's near face or mid plane and mid plane or far face.
template <typename T>
struct Crossings
{
  T nearT[3], midT[3], farT[3];
};
using NodeCrossings = Crossings<float>;

// Octant bit a set where the ray runs towards -a (a zero component counts
// as +, as the half-open boxes want).
OCTORAY_HD_INLINE unsigned DirectionSigns(const Ray& ray)
{
  return (ray.inverse.x < 0.0f ? 1u : 0u) | (ray.inverse.y < 0.0f ? 2u : 0u) | (ray.inverse.z < 0.0f ? 4u : 0u);
}

// The planes by which the ray enters and leaves, on axis a, the node whose
// corner is `lo`.
OCTORAY_HD_INLINE float NearFace(unsigned signs, int a, float lo, float size)
{
  return (signs >> a) & 1u ? lo + size : lo;
}

OCTORAY_HD_INLINE float FarFace(unsigned signs, int a, float lo, float size)
{
  return (signs >> a) & 1u ? lo : lo + size;
}

// The crossings of the node whose corner is `lo` and side `size`. Its
// planes are exact dyadic fractions, so the values are the same however the
// corner was reached.
template <bool MayBeParallel, typename Rays>
OCTORAY_HD_INLINE Crossings<ValuesOf<Rays>> CrossingsOf(const Rays& ray, unsigned signs, const Vec3f& lo, float size)
{
  Crossings<ValuesOf<Rays>> c;
  for (int a = 0; a < 3; ++a)
  {
    c.nearT[a] = Crossing<MayBeParallel>(ray, a, NearFace(signs, a, lo[a], size));
    c.midT[a] = Crossing<MayBeParallel>(ray, a, lo[a] + 0.5f * size);
    c.farT[a] = Crossing<MayBeParallel>(ray, a, FarFace(signs, a, lo[a], size));
  }
  return c;
}

// The larger and the smaller of two crossings, which are never NaN: one
// instruction on the device, where fmaxf is one; a compare on the host,
// where it is a library call (and, for a packet's lanes, one instruction).
template <typename T>
OCTORAY_HD_INLINE T Later(T a, T b)
{
#if defined(__CUDA_ARCH__)
  return fmaxf(a, b);
#else
  return a > b ? a : b;
#endif
}

template <typename T>
OCTORAY_HD_INLINE T Earlier(T a, T b)
{
#if defined(__CUDA_ARCH__)
  return fminf(a, b);
#else
  return a < b ? a : b;
#endif
}

// The entry and exit of the child in mirrored octant m: the latest near
// face and the earliest far face.
template <typename T>
struct ChildSpan
{
  T tEnter, tExit;
};

template <typename T>
OCTORAY_HD_INLINE T ChildNear(const Crossings<T>& c, unsigned m, int a)
{
  return (m >> a) & 1u ? c.midT[a] : c.nearT[a];
}

template <typename T>
OCTORAY_HD_INLINE T ChildFar(const Crossings<T>& c, unsigned m, int a)
{
  return (m >> a) & 1u ? c.farT[a] : c.midT[a];
}

template <typename T>
OCTORAY_HD_INLINE ChildSpan<T> SpanOf(const Crossings<T>& c, unsigned m)
{
  ChildSpan<T> s{ T{} - INFINITY, T{} + INFINITY };
  for (int a = 0; a < 3; ++a)
  {
    s.tEnter = Later(ChildNear(c, m, a), s.tEnter);
    s.tExit = Earlier(ChildFar(c, m, a), s.tExit);
  }
  return s;
}

// The crossings of the child in mirrored octant m, once the ray goes into
// it: its near and far faces are its parent's planes, its mid planes new.
template <typename T, typename Triple>
OCTORAY_HD_INLINE void EnterChild(Crossings<T>& c, unsigned m, const Triple& childMidT)
{
  for (int a = 0; a < 3; ++a)
  {
    const T tNear = ChildNear(c, m, a);
    c.farT[a] = ChildFar(c, m, a);
    c.nearT[a] = tNear;
    c.midT[a] = childMidT[a];
  }
}

// The corner of the child in (unmirrored) octant `octant` of the node whose
// corner is lo, for children of side `half`.
OCTORAY_HD_INLINE Vec3f ChildCorner(Vec3f lo, unsigned octant, float half)
{
  for (int a = 0; a < 3; ++a)
  {
    lo[a] += (octant >> a) & 1u ? half : 0.0f;
  }
  return lo;
}

// The axis of the face by which the ray enters the child in mirrored octant
// m at tEnter (SpanOf's): the lowest axis on ties, -1 when the ray starts
// inside on every axis. Only the voxels drawn need it.
OCTORAY_HD_INLINE int EntryAxis(const NodeCrossings& c, unsigned m, float tEnter)
{
  for (int a = 0; a < 3; ++a)
  {
    const float tNear = ChildNear(c, m, a);
    if (tNear == tEnter && tNear > -INFINITY)
    {
      return a;
    }
  }
  return -1;
}

// The mirrored octants the ray meets over [tEnter, tExit] inside a node
// whose mid planes it crosses at midT and whose box it is in over all of
// that interval (a part of its span will do): exactly the children whose
// slab test passes, zero-length touches of edges and corners included. A
// child's span is empty only where one of its near planes comes after one of
// its far planes. On one axis the near face, mid plane and far face come in
// that order, and a near face never comes after a far face of a node the ray
// is in, so three kinds of comparison decide it: the near half of axis a
// needs its mid plane no earlier than the entry, the far half no later than
// the exit, and an octant past a's mid plane but not b's needs a's mid plane
// no later than b's. Touches are kept, both where the ray crosses two mid
// planes at once: keeping one of the two (one comparison per pair of axes)
// lets a ray through a lattice of voxels' edges miss them all, a dotted line
// of holes.
//
// For one ray (Vec3f and floats) the octants' bits; for a packet (arrays of
// lanes) the bits per lane.
template <typename Triple, typename T>
OCTORAY_HD_INLINE auto MetOctants(const Triple& midT, T tEnter, T tExit)
{
  using Sets = decltype(Where(tEnter > tExit, 0u)); // unsigned, or lanes of int
  Sets met = Sets{} + 0xFF;
  for (int a = 0; a < 3; ++a)
  {
    const unsigned nearHalf = a == 0 ? 0x55u : (a == 1 ? 0x33u : 0x0Fu);
    met &= Where(midT[a] >= tEnter, nearHalf) | Where(midT[a] <= tExit, ~nearHalf);
  }
  // Octants with bit a set and bit b clear, for the pairs (x,y), (y,x),
  // (x,z), (z,x), (y,z), (z,y).
  met &= Unless(midT[0] > midT[1], 0x22u);
  met &= Unless(midT[1] > midT[0], 0x44u);
  met &= Unless(midT[0] > midT[2], 0x0Au);
  met &= Unless(midT[2] > midT[0], 0x50u);
  met &= Unless(midT[1] > midT[2], 0x0Cu);
  met &= Unless(midT[2] > midT[1], 0x30u);
  return met & 0xFF;
}

// The octants that hold every bit of m: those the ray can still meet after
// the child m, which it met (a ray's children form a chain of growing bit
// sets). Byte m of the constant, one shift where selects per bit of m
// would take the device's integer pipe, the traversal's narrowest.
OCTORAY_HD_INLINE unsigned OctantsAfter(unsigned m)
{
  // m:  7     6     5     4     3     2     1     0
  //     0x80  0xC0  0xA0  0xF0  0x88  0xCC  0xAA  0xFF
  return static_cast<unsigned>(0x80C0A0F088CCAAFFull >> (8u * m)) & 0xFFu;
}

// A child mask with octant bits flipped as in NodeCrossings: bit m of the
// result is bit m ^ signs of the mask.
constexpr OCTORAY_HD_INLINE unsigned MirrorOctants(unsigned mask, unsigned signs)
{
  if (signs & 1u)
  {
    mask = ((mask & 0x55u) << 1) | ((mask & 0xAAu) >> 1);
  }
  if (signs & 2u)
  {
    mask = ((mask & 0x33u) << 2) | ((mask & 0xCCu) >> 2);
  }
  if (signs & 4u)
  {
    mask = ((mask & 0x0Fu) << 4) | ((mask & 0xF0u) >> 4);
  }
  return mask;
}

// MirrorOctants of every mask, for each of the eight signs.
struct MirroredMasks
{
  std::uint8_t bySigns[8][256];
};

constexpr MirroredMasks EveryMirroredMask()
{
  MirroredMasks table{};
  for (unsigned signs = 0; signs < 8; ++signs)
  {
    for (unsigned mask = 0; mask < 256; ++mask)
    {
      table.bySigns[signs][mask] = static_cast<std::uint8_t>(MirrorOctants(mask, signs));
    }
  }
  return table;
}

#if defined(__CUDACC__)
__device__ const MirroredMasks kMirroredMasks = EveryMirroredMask();
#endif

// MirrorOctants for one ray's signs. On the device a load from the table
// (2 kB, which stays in the L1 cache): the swaps took about 14 of the 228
// instructions of a step, in a kernel that issues an instruction three
// cycles in four and sends near half of them to the ALU pipe (logic,
// compares, selects), its busiest (Benchmarks/gpu/variants-mirror-table.txt).
// On the host the swaps.
class OctantMirror
{
public:
  OCTORAY_HD_INLINE explicit OctantMirror(unsigned signs)
#if defined(__CUDA_ARCH__)
    : row(kMirroredMasks.bySigns[signs])
#else
    : signs(signs)
#endif
  {
  }

  OCTORAY_HD_INLINE unsigned operator()(unsigned mask) const
  {
#if defined(__CUDA_ARCH__)
    return row[mask];
#else
    return MirrorOctants(mask, signs);
#endif
  }

private:
#if defined(__CUDA_ARCH__)
  const std::uint8_t* row;
#else
  unsigned signs;
#endif
};

// The corner, on one axis, of the node of `level` that holds the point x of
// the unit cube: x cut down to a multiple of the node's side (exact in
// float, the scalings being powers of two).
OCTORAY_HD_INLINE float NodeCorner(float x, int level)
{
  return static_cast<float>(static_cast<int>(x * PowerOfTwo(level))) * PowerOfTwo(-level);
}

// What the traversal keeps of a node that has children left to visit while
// it is inside one of their siblings, packed in 64 bits: how to find the
// children and which of them are left.
struct PausedNode
{
  std::uint64_t bits;

  OCTORAY_HD_INLINE static PausedNode Of(std::uint32_t firstChild, unsigned childMask, unsigned todo)
  {
    return PausedNode{ std::uint64_t{ firstChild } | std::uint64_t{ childMask } << 32 | std::uint64_t{ todo } << 40 };
  }
  OCTORAY_HD_INLINE std::uint32_t FirstChild() const { return static_cast<std::uint32_t>(bits); }
  OCTORAY_HD_INLINE unsigned ChildMask() const { return static_cast<unsigned>(bits >> 32) & 0xFFu; }
  OCTORAY_HD_INLINE unsigned Todo() const { return static_cast<unsigned>(bits >> 40) & 0xFFu; }
};

// A child of the node a walk is in: its index, level, corner and side.
struct WalkChild
{
  std::uint32_t node;
  int level;
  Vec3f lo;
  float size;

  // Where a ray crosses its mid plane on axis a (the rays of a packet, lane
  // by lane).
  template <bool MayBeParallel, typename Rays>
  OCTORAY_HD_INLINE ValuesOf<Rays> MidCrossing(const Rays& rays, int a) const
  {
    return Crossing<MayBeParallel>(rays, a, lo[a] + 0.5f * size);
  }
  // The child as a drawn voxel, met over [tEnter, tExit] through a face of
  // `axis`.
  OCTORAY_HD_INLINE NodeHit Hit(float tEnter, float tExit, int axis) const
  {
    return NodeHit{ node, level, tEnter, tExit, axis, lo, size };
  }
};

// The node a walk of the octree is in, and the rays' crossings of its
// planes: one ray's (T a float: Traverse) or a packet's lanes'
// (TraversePacket). Both walks look at a child, go down into it and climb
// back to a paused node through these, so that each lane of a packet
// computes what Traverse computes for its ray, bit for bit.
template <typename T>
struct WalkNode
{
  Vec3f lo; // corner and side
  float size;
  int level;
  Crossings<T> c;
  unsigned childMask;
  std::uint32_t firstChild;

  // The root, for rays whose directions have these signs.
  template <bool MayBeParallel, typename Rays>
  OCTORAY_HD_INLINE void StartAtRoot(const OctreeView& tree, const Rays& rays, unsigned signs)
  {
    lo = Vec3f{ 0.0f, 0.0f, 0.0f };
    size = 1.0f;
    level = 0;
    c = CrossingsOf<MayBeParallel>(rays, signs, lo, size);
    childMask = ChildMaskOf(tree, 0);
    firstChild = FirstChildOf(tree, 0);
  }

  // The child in mirrored octant m.
  OCTORAY_HD_INLINE WalkChild Child(unsigned m, unsigned signs) const
  {
    const unsigned octant = m ^ signs;
    const float half = 0.5f * size;
    return WalkChild{ ChildIndex(childMask, firstChild, octant), level + 1, ChildCorner(lo, octant, half), half };
  }

  // Down into `child`, in mirrored octant m, whose mid planes the rays cross
  // at childMidT and whose group of eight has the child masks groupMasks
  // (the child's own, grandchildMask): the child's first child is found
  // only here, once the walk goes in (Attributes.h).
  template <typename Triple>
  OCTORAY_HD_INLINE void Enter(const OctreeView& tree, unsigned m, const WalkChild& child, const Triple& childMidT,
    std::uint64_t groupMasks, unsigned grandchildMask)
  {
    level = child.level;
    EnterChild(c, m, childMidT);
    lo = child.lo;
    size = child.size;
    childMask = grandchildMask;
    firstChild = FirstChildInGroup(tree.childBase[child.node >> 3], groupMasks, child.node);
  }

  // Back up to the node of level l, which holds this one and has these
  // children (a paused node's): its corner cut from this node's, its
  // crossings computed again.
  template <bool MayBeParallel, typename Rays>
  OCTORAY_HD_INLINE void ClimbTo(int l, std::uint32_t first, unsigned mask, const Rays& rays, unsigned signs)
  {
    level = l;
    firstChild = first;
    childMask = mask;
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = NodeCorner(lo[a], level);
    }
    size = PowerOfTwo(-level);
    c = CrossingsOf<MayBeParallel>(rays, signs, lo, size);
  }
};

// The loop of Traverse (below) from the root, whose span the ray's is.
template <bool MayBeParallel, typename Visitor>
OCTORAY_HD void TraverseFromRoot(const OctreeView& tree, const Ray& ray, const LevelOfDetail& lod, Visitor& visitor,
  float tEnter, float tExit)
{
  const unsigned signs = DirectionSigns(ray);
  const OctantMirror mirror(signs);
  // Whether the picture has a level of detail at all (most are drawn down
  // to the leaves): asked once here, so that those pictures skip StopAt's
  // arithmetic at every step.
  const bool lodOn = lod.pixels > 0.0f;
  PausedNode paused[kMaxLevel]; // by level, where `pausedLevels` has its bit
  unsigned pausedLevels = 0;
  WalkNode<float> node;
  node.StartAtRoot<MayBeParallel>(tree, ray, signs);
  // Children are tested against the part of each span within [tMin, tMax]
  // (never empty: a child is stepped to only where it meets that part), so
  // the loop needs no test of its own for voxels before tMin or past tMax.
  unsigned todo =
    mirror(node.childMask) & MetOctants(node.c.midT, Later(tEnter, ray.tMin), Earlier(tExit, ray.tMax));
  for (;;)
  {
    if (!todo)
    {
      if (!pausedLevels)
      {
        return;
      }
      const int level = HighestBit(pausedLevels);
      pausedLevels &= ~(1u << level);
      const PausedNode resumed = paused[level];
      todo = resumed.Todo();
      node.ClimbTo<MayBeParallel>(level, resumed.FirstChild(), resumed.ChildMask(), ray, signs);
      // A paused node has children left: on to the next of them in the same
      // step, where the threads of a warp that did not climb are.
    }
    const unsigned m = LowestBit(todo);
    todo &= todo - 1u;
    const auto span = SpanOf(node.c, m);
    const WalkChild child = node.Child(m, signs);
    if (child.level == tree.depth || (lodOn && lod.StopAt(child.size, span.tEnter)))
    {
      if (visitor.Visit(child.Hit(span.tEnter, span.tExit, EntryAxis(node.c, m, span.tEnter))))
      {
        return;
      }
      continue;
    }
    Vec3f innerMidT;
    for (int a = 0; a < 3; ++a)
    {
      innerMidT[a] = child.MidCrossing<MayBeParallel>(ray, a);
    }
    // The child's group of eight: its mask now, its first child if it is
    // entered (Attributes.h).
    const std::uint64_t groupMasks = tree.childMasks[child.node >> 3];
    const unsigned grandchildMask = MaskInWord(groupMasks, child.node);
    const unsigned met = mirror(grandchildMask) &
      MetOctants(innerMidT, Later(span.tEnter, ray.tMin), Earlier(span.tExit, ray.tMax));
    const unsigned after = todo & OctantsAfter(m);
    if (!met)
    {
      todo = after; // as if it had gone down and come back
      continue;
    }
    if (after)
    {
      paused[node.level] = PausedNode::Of(node.firstChild, node.childMask, after);
      pausedLevels |= 1u << node.level;
    }
    node.Enter(tree, m, child, innerMidT, groupMasks, grandchildMask);
    todo = met;
  }
}

// The ray's span through the root cube within [tMin, tMax], in hit's
// tEnter, tExit and axis; false where it has none.
OCTORAY_HD_INLINE bool MeetsRoot(const Ray& ray, NodeHit& hit)
{
  return IntersectBox(ray, Vec3f{ 0.0f, 0.0f, 0.0f }, 1.0f, hit.tEnter, hit.tExit, hit.axis) &&
    !(hit.tExit < ray.tMin || hit.tEnter > ray.tMax);
}

// Whether the root is drawn as it is: a tree of one node, or a level of
// detail that stops there.
OCTORAY_HD_INLINE bool DrawsRoot(const OctreeView& tree, const LevelOfDetail& lod, float tEnter)
{
  return tree.depth == 0 || lod.StopAt(1.0f, tEnter);
}

// Whether the ray runs parallel to an axis (SetDirection's +inf).
OCTORAY_HD_INLINE bool HasParallelAxis(const Ray& ray)
{
  return ray.inverse.x == INFINITY || ray.inverse.y == INFINITY || ray.inverse.z == INFINITY;
}

// Visits the drawn voxels (leaves, or nodes where the level of detail
// stops) that the ray meets within [tMin, tMax], nearest first, until the
// visitor's Visit(const NodeHit&) returns true.
//
// Order: a ray crosses each mid plane of a node at most once, from the near
// half to the far one, so the children it meets form a chain in which each
// next one sets one more bit of the mirrored octant (NodeCrossings).
// Visiting the children by increasing mirrored octant is thus the order the
// ray meets them, and depth-first in that order is front to back overall.
//
// Cost, one child per step of a single loop (threads of a warp stay in
// step): a node's crossings are its parent's with three new mid planes, a
// child's span is picked from them, and only the children the ray meets
// within [tMin, tMax] are stepped to (MetOctants). A child whose own
// children the ray misses is passed over in the step that looks at it,
// without going down. Going back up is part of the step that looks at the
// next child, however many levels it climbs: the stack holds only nodes
// with children left (one 64-bit word each, PausedNode), a bit per level
// says which, and the traversal resumes at the deepest of them, its corner
// cut from the current one and its crossings computed again (CrossingsOf).
// Every value equals what a slab test of each child's box gives, bit for
// bit: the planes are exact dyadic fractions.
template <typename Visitor>
OCTORAY_HD void Traverse(const OctreeView& tree, const Ray& ray, const LevelOfDetail& lod, Visitor& visitor)
{
  NodeHit hit;
  if (!MeetsRoot(ray, hit))
  {
    return;
  }
  if (DrawsRoot(tree, lod, hit.tEnter))
  {
    hit.node = 0;
    hit.level = 0;
    hit.lo = Vec3f{ 0.0f, 0.0f, 0.0f };
    hit.size = 1.0f;
    visitor.Visit(hit);
    return;
  }
  if (HasParallelAxis(ray))
  {
    TraverseFromRoot<true>(tree, ray, lod, visitor, hit.tEnter, hit.tExit);
  }
  else
  {
    TraverseFromRoot<false>(tree, ray, lod, visitor, hit.tEnter, hit.tExit);
  }
}

// Visitor that stops at the first voxel.
struct FirstHitVisitor
{
  bool found = false;
  NodeHit hit;
  OCTORAY_HD bool Visit(const NodeHit& h)
  {
    found = true;
    hit = h;
    return true;
  }
};

// Whether a voxel holds the point p of the unit cube at `level` (or the
// deepest drawn level above it): used for occupancy-gradient normals.
OCTORAY_HD bool Occupied(const OctreeView& tree, int level, const Vec3f& p)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!(p[a] >= 0.0f && p[a] < 1.0f))
    {
      return false;
    }
  }
  const Vec3f cell = p * PowerOfTwo(level);
  const std::uint64_t key = EncodeMorton(static_cast<std::uint32_t>(cell.x), static_cast<std::uint32_t>(cell.y),
    static_cast<std::uint32_t>(cell.z));
  return tree.Find(level, key) != kInvalidIndex;
}
}
