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
struct LevelOfDetail
{
  float footprint0 = 0.0f;
  float footprintSlope = 0.0f;
  float pixels = 0.0f; // 0: always down to the leaves

  // `voxel`: the node's side in the unit cube.
  OCTORAY_HD bool StopAt(float voxel, float t) const
  {
    if (pixels <= 0.0f)
    {
      return false;
    }
    return voxel < pixels * (footprint0 + footprintSlope * (t > 0.0f ? t : 0.0f));
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

// Where the ray crosses the plane x[a] = p. A ray parallel to the plane
// never crosses it: -inf where it runs on the plane or beyond it (boxes are
// half-open, so the plane belongs to the upper side), +inf below it.
OCTORAY_HD_INLINE float Crossing(const Ray& ray, int a, float p)
{
  if (ray.inverse[a] == INFINITY) // parallel (SetDirection)
  {
    return p <= ray.origin[a] ? -INFINITY : INFINITY;
  }
  return (p - ray.origin[a]) * ray.inverse[a];
}

// The ray against one node, in the node's octants as the ray sees them:
// octant bit a of a child is flipped where the ray runs towards -a, so that
// on every axis the ray crosses the near face (the child's bit 0 side), the
// mid plane, then the far face. A child's interval is thus picked from
// these nine values without any arithmetic, and a child's near and far
// faces are its parent's near face or mid plane and mid plane or far face.
struct NodeCrossings
{
  Vec3f nearT, midT, farT;
};

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

// The crossings of the root cube [0, 1)^3.
OCTORAY_HD_INLINE NodeCrossings RootCrossings(const Ray& ray, unsigned signs)
{
  NodeCrossings c;
  for (int a = 0; a < 3; ++a)
  {
    c.nearT[a] = Crossing(ray, a, NearFace(signs, a, 0.0f, 1.0f));
    c.midT[a] = Crossing(ray, a, 0.5f);
    c.farT[a] = Crossing(ray, a, FarFace(signs, a, 0.0f, 1.0f));
  }
  return c;
}

// The entry, exit and entry axis of the child in mirrored octant m: the
// latest near face and the earliest far face, the lowest axis on ties.
struct ChildSpan
{
  float tEnter, tExit;
  int axis;
};

OCTORAY_HD_INLINE ChildSpan SpanOf(const NodeCrossings& c, unsigned m)
{
  ChildSpan s{ -INFINITY, INFINITY, -1 };
  for (int a = 0; a < 3; ++a)
  {
    const bool upper = (m >> a) & 1u;
    const float tNear = upper ? c.midT[a] : c.nearT[a];
    const float tFar = upper ? c.farT[a] : c.midT[a];
    if (tNear > s.tEnter)
    {
      s.tEnter = tNear;
      s.axis = a;
    }
    s.tExit = tFar < s.tExit ? tFar : s.tExit;
  }
  return s;
}

// Mirrored octants whose every axis the ray can reach inside a node it
// spans over [tEnter, tExit]: the near half where the mid plane comes no
// earlier than the entry, the far half where it comes no later than the
// exit. A superset of the children the ray meets, so only those get their
// span computed.
OCTORAY_HD_INLINE unsigned ReachableOctants(const NodeCrossings& c, float tEnter, float tExit)
{
  unsigned reachable = 0xFFu;
  for (int a = 0; a < 3; ++a)
  {
    const unsigned nearHalf = a == 0 ? 0x55u : (a == 1 ? 0x33u : 0x0Fu);
    reachable &= (c.midT[a] >= tEnter ? nearHalf : 0u) | (c.midT[a] <= tExit ? ~nearHalf : 0u);
  }
  return reachable & 0xFFu;
}

// The octants that hold every bit of m: those the ray can still meet after
// the child m, which it met (a ray's children form a chain of growing bit
// sets).
OCTORAY_HD_INLINE unsigned OctantsAfter(unsigned m)
{
  return (m & 1u ? 0xAAu : 0xFFu) & (m & 2u ? 0xCCu : 0xFFu) & (m & 4u ? 0xF0u : 0xFFu);
}

// A child mask with octant bits flipped as in NodeCrossings.
OCTORAY_HD_INLINE unsigned MirrorOctants(unsigned mask, unsigned signs)
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

OCTORAY_HD_INLINE unsigned LowestBit(unsigned bits)
{
#if defined(__CUDA_ARCH__)
  return static_cast<unsigned>(__ffs(static_cast<int>(bits)) - 1);
#else
  return static_cast<unsigned>(__builtin_ctz(bits));
#endif
}

// What the traversal keeps of a node while it is inside one of its
// children, packed in 64 bits: how to find the children, which of them are
// still to be looked at, and the one it is in.
struct PausedNode
{
  std::uint64_t bits;

  OCTORAY_HD_INLINE static PausedNode Of(std::uint32_t firstChild, unsigned childMask, unsigned todo, unsigned m)
  {
    return PausedNode{ std::uint64_t{ firstChild } | std::uint64_t{ childMask } << 32 |
      std::uint64_t{ todo } << 40 | std::uint64_t{ m } << 48 };
  }
  OCTORAY_HD_INLINE std::uint32_t FirstChild() const { return static_cast<std::uint32_t>(bits); }
  OCTORAY_HD_INLINE unsigned ChildMask() const { return static_cast<unsigned>(bits >> 32) & 0xFFu; }
  OCTORAY_HD_INLINE unsigned Todo() const { return static_cast<unsigned>(bits >> 40) & 0xFFu; }
  OCTORAY_HD_INLINE unsigned Visiting() const { return static_cast<unsigned>(bits >> 48) & 7u; }
};

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
// Cost, one candidate child per step of a single loop (threads of a warp
// stay in step): a child's span is picked from its parent's crossings, a
// node's crossings are its parent's with three new mid planes, and only
// the children the mid planes let the ray reach are looked at. Going back
// up, the parent's crossings come back from the child's (its near face and
// mid plane, or mid plane and far face, per axis) with at most three far
// faces computed again; the parent itself is one 64-bit word per level
// (PausedNode). Every value equals what a slab test of each child's box
// gives, bit for bit: the planes are exact dyadic fractions.
template <typename Visitor>
OCTORAY_HD void Traverse(const OctreeView& tree, const Ray& ray, const LevelOfDetail& lod, Visitor& visitor)
{
  NodeHit hit;
  if (!IntersectBox(ray, Vec3f{ 0.0f, 0.0f, 0.0f }, 1.0f, hit.tEnter, hit.tExit, hit.axis) ||
    hit.tExit < ray.tMin || hit.tEnter > ray.tMax)
  {
    return;
  }
  if (tree.depth == 0 || lod.StopAt(1.0f, hit.tEnter))
  {
    hit.node = 0;
    hit.level = 0;
    hit.lo = Vec3f{ 0.0f, 0.0f, 0.0f };
    hit.size = 1.0f;
    visitor.Visit(hit);
    return;
  }
  const unsigned signs = DirectionSigns(ray);
  PausedNode parents[kMaxLevel];
  NodeCrossings c = RootCrossings(ray, signs);
  Vec3f lo{ 0.0f, 0.0f, 0.0f }; // the current node's corner and side
  float size = 1.0f;
  int level = 0;
  unsigned childMask = tree.childMask[0];
  std::uint32_t firstChild = tree.firstChild[0];
  unsigned todo = MirrorOctants(childMask, signs) & ReachableOctants(c, hit.tEnter, hit.tExit);
  for (;;)
  {
    if (!todo)
    {
      if (level == 0)
      {
        return;
      }
      const PausedNode parent = parents[--level];
      const unsigned m = parent.Visiting();
      firstChild = parent.FirstChild();
      childMask = parent.ChildMask();
      todo = parent.Todo() & OctantsAfter(m);
      for (int a = 0; a < 3; ++a)
      {
        lo[a] -= ((m ^ signs) >> a) & 1u ? size : 0.0f;
        if ((m >> a) & 1u)
        {
          c.midT[a] = c.nearT[a]; // the parent's near face is not needed again
        }
        else
        {
          c.midT[a] = c.farT[a];
          c.farT[a] = Crossing(ray, a, FarFace(signs, a, lo[a], 2.0f * size));
        }
      }
      size *= 2.0f;
      continue;
    }
    const unsigned m = LowestBit(todo);
    todo &= todo - 1u;
    const ChildSpan span = SpanOf(c, m);
    if (!(span.tEnter <= span.tExit) || span.tExit < ray.tMin)
    {
      continue;
    }
    if (span.tEnter > ray.tMax)
    {
      return; // everything after it is farther
    }
    const unsigned octant = m ^ signs;
    const float half = 0.5f * size;
    Vec3f childLo = lo;
    for (int a = 0; a < 3; ++a)
    {
      childLo[a] += (octant >> a) & 1u ? half : 0.0f;
    }
    const std::uint32_t child = ChildIndex(childMask, firstChild, octant);
    if (level + 1 == tree.depth || lod.StopAt(half, span.tEnter))
    {
      hit = NodeHit{ child, level + 1, span.tEnter, span.tExit, span.axis, childLo, half };
      if (visitor.Visit(hit))
      {
        return;
      }
      continue;
    }
    parents[level++] = PausedNode::Of(firstChild, childMask, todo, m);
    for (int a = 0; a < 3; ++a)
    {
      const bool upper = (m >> a) & 1u;
      c.nearT[a] = upper ? c.midT[a] : c.nearT[a];
      c.farT[a] = upper ? c.farT[a] : c.midT[a];
      c.midT[a] = Crossing(ray, a, childLo[a] + 0.5f * half);
    }
    lo = childLo;
    size = half;
    childMask = tree.childMask[child];
    firstChild = tree.firstChild[child];
    todo = MirrorOctants(childMask, signs) & ReachableOctants(c, span.tEnter, span.tExit);
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
