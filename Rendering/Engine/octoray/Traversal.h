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

// A ray crosses each splitting plane of a node at most once, so it passes
// through at most 4 of the 8 children (the stack then holds at most 3 per
// level plus one); one that grazes the node's centre can touch all 8 with
// zero length, so room is kept for 7 per level: the stack never overflows
// (the check in Traverse is a guard only).
constexpr int kTraversalStack = 7 * (kMaxLevel + 1) + 1;

struct TraversalEntry
{
  std::uint32_t node;
  std::int32_t level;
  float tEnter;
};

// Visits the drawn voxels (leaves, or nodes where the level of detail
// stops) that the ray meets within [tMin, tMax], nearest first, until the
// visitor's Visit(const NodeHit&) returns true.
//
// Order: a ray moving towards +x crosses a node's x = mid plane from the low
// half to the high one, never back; so the octants it meets form a chain in
// which each next octant sets one more bit of (octant ^ signMask), where
// signMask has bit a set for a negative direction component. Visiting
// octants by increasing (octant ^ signMask) is thus the order the ray meets
// them, and depth-first in that order is front to back overall (disjoint
// boxes along a ray have disjoint intervals). No sorting is needed, and the
// stack keeps only node, level and entry distance; a node's box comes back
// from its key.
template <typename Visitor>
OCTORAY_HD void Traverse(const OctreeView& tree, const Ray& ray, const LevelOfDetail& lod, Visitor& visitor)
{
  TraversalEntry stack[kTraversalStack];
  int top = 0;
  {
    float t0, t1;
    int axis;
    if (!IntersectBox(ray, Vec3f{ 0.0f, 0.0f, 0.0f }, 1.0f, t0, t1, axis) || t1 < ray.tMin || t0 > ray.tMax)
    {
      return;
    }
    stack[top++] = TraversalEntry{ 0u, 0, t0 };
  }
  const unsigned signMask =
    (ray.direction.x < 0.0f ? 1u : 0u) | (ray.direction.y < 0.0f ? 2u : 0u) | (ray.direction.z < 0.0f ? 4u : 0u);
  while (top > 0)
  {
    const TraversalEntry e = stack[--top];
    if (e.tEnter > ray.tMax)
    {
      return; // everything left on the stack is farther
    }
    NodeHit hit;
    hit.node = e.node;
    hit.level = e.level;
    hit.size = PowerOfTwo(-e.level);
    std::uint32_t cell[3];
    DecodeMorton(tree.key[e.node], cell[0], cell[1], cell[2]);
    hit.lo = Vec3f{ static_cast<float>(cell[0]), static_cast<float>(cell[1]), static_cast<float>(cell[2]) } * hit.size;
    if (e.level == tree.depth || lod.StopAt(hit.size, e.tEnter))
    {
      IntersectBox(ray, hit.lo, hit.size, hit.tEnter, hit.tExit, hit.axis);
      if (visitor.Visit(hit))
      {
        return;
      }
      continue;
    }
    const float half = 0.5f * hit.size;
    const unsigned mask = tree.childMask[e.node];
    const std::uint32_t firstChild = tree.firstChild[e.node];
    // Pushed farthest first, so that they pop nearest first.
    for (int i = 7; i >= 0; --i)
    {
      const unsigned octant = static_cast<unsigned>(i) ^ signMask;
      if (!(mask & (1u << octant)))
      {
        continue;
      }
      const Vec3f offset{ (octant & 1u) ? half : 0.0f, (octant & 2u) ? half : 0.0f, (octant & 4u) ? half : 0.0f };
      const Vec3f lo = hit.lo + offset;
      float t0, t1;
      int axis;
      if (!IntersectBox(ray, lo, half, t0, t1, axis) || t1 < ray.tMin || t0 > ray.tMax || top == kTraversalStack)
      {
        continue;
      }
      stack[top++] = TraversalEntry{ ChildIndex(mask, firstChild, octant), e.level + 1, t0 };
    }
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
