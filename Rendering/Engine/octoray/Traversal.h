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

namespace octoray
{
struct Ray
{
  float origin[3];
  float direction[3]; // unit length
  float inverse[3];   // 1 / direction, +-inf for zero components
  float tMin, tMax;
};

OCTORAY_HD void SetDirection(Ray& ray, const float d[3])
{
  for (int a = 0; a < 3; ++a)
  {
    ray.direction[a] = d[a];
    ray.inverse[a] = 1.0f / d[a];
  }
}

// Entry and exit of the ray through the box [lo, lo + size); the axis of the
// entry face (-1 if the ray starts inside on every axis). False on a miss,
// and when any value is NaN.
OCTORAY_HD bool IntersectBox(const Ray& ray, const float lo[3], float size, float& tEnter, float& tExit, int& axis)
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

  OCTORAY_HD bool StopAt(int level, float t) const
  {
    if (pixels <= 0.0f)
    {
      return false;
    }
    const float voxel = ldexpf(1.0f, -level);
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
  float lo[3];      // the voxel's corner and size in the unit cube
  float size;
};

constexpr int kTraversalStack = 8 * (kMaxLevel + 1);

// Visits the drawn voxels (leaves, or nodes where the level of detail
// stops) that the ray meets within [tMin, tMax], nearest first, until the
// visitor's Visit(const NodeHit&) returns true. Children of a node are
// pushed farthest first, so the stack pops them in the order the ray meets
// them; disjoint boxes along a ray have disjoint intervals, so depth-first
// in that order is front to back overall.
template <typename Visitor>
OCTORAY_HD void Traverse(const OctreeView& tree, const Ray& ray, const LevelOfDetail& lod, Visitor& visitor)
{
  NodeHit stack[kTraversalStack];
  int top = 0;
  {
    NodeHit root;
    root.node = 0;
    root.level = 0;
    root.lo[0] = root.lo[1] = root.lo[2] = 0.0f;
    root.size = 1.0f;
    if (!IntersectBox(ray, root.lo, 1.0f, root.tEnter, root.tExit, root.axis) || root.tExit < ray.tMin ||
      root.tEnter > ray.tMax)
    {
      return;
    }
    stack[top++] = root;
  }
  while (top > 0)
  {
    const NodeHit hit = stack[--top];
    if (hit.tEnter > ray.tMax)
    {
      return; // everything left on the stack is farther
    }
    if (hit.level == tree.depth || lod.StopAt(hit.level, hit.tEnter))
    {
      if (visitor.Visit(hit))
      {
        return;
      }
      continue;
    }
    // Children the ray meets, sorted nearest first (at most 8).
    NodeHit children[8];
    int count = 0;
    const float half = 0.5f * hit.size;
    const unsigned mask = tree.childMask[hit.node];
    std::uint32_t child = tree.firstChild[hit.node];
    for (int octant = 0; octant < 8; ++octant)
    {
      if (!(mask & (1u << octant)))
      {
        continue;
      }
      NodeHit c;
      c.node = child++;
      c.level = hit.level + 1;
      c.size = half;
      c.lo[0] = hit.lo[0] + ((octant & 1) ? half : 0.0f);
      c.lo[1] = hit.lo[1] + ((octant & 2) ? half : 0.0f);
      c.lo[2] = hit.lo[2] + ((octant & 4) ? half : 0.0f);
      if (!IntersectBox(ray, c.lo, half, c.tEnter, c.tExit, c.axis) || c.tExit < ray.tMin || c.tEnter > ray.tMax)
      {
        continue;
      }
      int k = count++;
      while (k > 0 && children[k - 1].tEnter > c.tEnter)
      {
        children[k] = children[k - 1];
        --k;
      }
      children[k] = c;
    }
    for (int k = count - 1; k >= 0; --k)
    {
      stack[top++] = children[k];
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
OCTORAY_HD bool Occupied(const OctreeView& tree, int level, const float p[3])
{
  for (int a = 0; a < 3; ++a)
  {
    if (!(p[a] >= 0.0f && p[a] < 1.0f))
    {
      return false;
    }
  }
  const float scale = ldexpf(1.0f, level);
  const std::uint64_t key =
    EncodeMorton(static_cast<std::uint32_t>(p[0] * scale), static_cast<std::uint32_t>(p[1] * scale),
      static_cast<std::uint32_t>(p[2] * scale));
  return tree.Find(level, key) != kInvalidIndex;
}
}
