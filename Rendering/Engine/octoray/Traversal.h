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

OCTORAY_HD void SetDirection(Ray& ray, const Vec3f& d)
{
  ray.direction = d;
  ray.inverse = Vec3f{ 1.0f / d.x, 1.0f / d.y, 1.0f / d.z };
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
  if (ray.direction[a] == 0.0f)
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
  return (ray.direction.x < 0.0f ? 1u : 0u) | (ray.direction.y < 0.0f ? 2u : 0u) |
    (ray.direction.z < 0.0f ? 4u : 0u);
}

OCTORAY_HD_INLINE float MidCrossing(const Ray& ray, int a, float lo, float size)
{
  return Crossing(ray, a, lo + 0.5f * size);
}

// The crossings of the node whose corner is cell * size.
OCTORAY_HD_INLINE NodeCrossings CrossingsOf(
  const Ray& ray, unsigned signs, const std::uint32_t cell[3], float size)
{
  NodeCrossings c;
  for (int a = 0; a < 3; ++a)
  {
    const float lo = static_cast<float>(cell[a]) * size;
    const bool towardsLow = (signs >> a) & 1u;
    c.nearT[a] = Crossing(ray, a, towardsLow ? lo + size : lo);
    c.farT[a] = Crossing(ray, a, towardsLow ? lo : lo + size);
    c.midT[a] = MidCrossing(ray, a, lo, size);
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

// Mirrored octants whose every axis the ray can reach inside the node: the
// near half where the mid plane comes no earlier than the node's entry, the
// far half where it comes no later than its exit. A superset of the
// children the ray meets, so only those get their span computed.
OCTORAY_HD_INLINE unsigned ReachableOctants(const NodeCrossings& c)
{
  float tEnter = c.nearT.x, tExit = c.farT.x;
  for (int a = 1; a < 3; ++a)
  {
    tEnter = c.nearT[a] > tEnter ? c.nearT[a] : tEnter;
    tExit = c.farT[a] < tExit ? c.farT[a] : tExit;
  }
  unsigned reachable = 0xFFu;
  for (int a = 0; a < 3; ++a)
  {
    const unsigned nearHalf = a == 0 ? 0x55u : (a == 1 ? 0x33u : 0x0Fu);
    reachable &= (c.midT[a] >= tEnter ? nearHalf : 0u) | (c.midT[a] <= tExit ? ~nearHalf : 0u);
  }
  return reachable & 0xFFu;
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
// Cost: a node's crossings come from its parent's (three new mid planes), a
// child's span from selects, and only children reachable by the mid-plane
// test are looked at. Going back up, the parent's crossings are computed
// again from its cell, so the stack holds one node index per level and the
// mirrored octant being visited at each level packed 3 bits to a level in
// one 64-bit word: (kMaxLevel + 1) * 4 bytes instead of a box per entry.
// Every value equals what slab tests of each child's box give, bit for bit
// (the planes are exact dyadic fractions).
template <typename Visitor>
OCTORAY_HD void Traverse(const OctreeView& tree, const Ray& ray, const LevelOfDetail& lod, Visitor& visitor)
{
  static_assert(3 * kMaxLevel <= 64, "the octant stack packs 3 bits per level into 64");
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
  std::uint32_t parents[kMaxLevel + 1];
  std::uint64_t visiting = 0; // mirrored octant being visited, per level
  std::uint32_t node = 0;
  std::uint32_t cell[3] = { 0u, 0u, 0u };
  int level = 0;
  float size = 1.0f;
  NodeCrossings c = CrossingsOf(ray, signs, cell, size);
  unsigned firstOctant = 0;
  for (;;)
  {
    const unsigned childMask = tree.childMask[node];
    unsigned todo = MirrorOctants(childMask, signs) & ReachableOctants(c) & (0xFFu << firstOctant);
    const std::uint32_t firstChild = todo ? tree.firstChild[node] : 0u;
    const float half = 0.5f * size;
    bool descended = false;
    while (todo)
    {
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
      std::uint32_t childCell[3];
      for (int a = 0; a < 3; ++a)
      {
        childCell[a] = 2u * cell[a] + ((octant >> a) & 1u);
      }
      const std::uint32_t child = ChildIndex(childMask, firstChild, octant);
      if (level + 1 == tree.depth || lod.StopAt(half, span.tEnter))
      {
        hit = NodeHit{ child, level + 1, span.tEnter, span.tExit, span.axis,
          Vec3f{ static_cast<float>(childCell[0]), static_cast<float>(childCell[1]),
            static_cast<float>(childCell[2]) } * half,
          half };
        if (visitor.Visit(hit))
        {
          return;
        }
        continue;
      }
      parents[level] = node;
      visiting = (visiting & ~(std::uint64_t{ 7u } << (3 * level))) | (std::uint64_t{ m } << (3 * level));
      for (int a = 0; a < 3; ++a)
      {
        const bool upper = (m >> a) & 1u;
        c.nearT[a] = upper ? c.midT[a] : c.nearT[a];
        c.farT[a] = upper ? c.farT[a] : c.midT[a];
        cell[a] = childCell[a];
        c.midT[a] = MidCrossing(ray, a, static_cast<float>(cell[a]) * half, half);
      }
      node = child;
      ++level;
      size = half;
      firstOctant = 0;
      descended = true;
      break;
    }
    if (descended)
    {
      continue;
    }
    if (level == 0)
    {
      return;
    }
    --level;
    node = parents[level];
    firstOctant = static_cast<unsigned>((visiting >> (3 * level)) & 7u) + 1u;
    size = PowerOfTwo(-level);
    for (int a = 0; a < 3; ++a)
    {
      cell[a] >>= 1;
    }
    c = CrossingsOf(ray, signs, cell, size);
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
