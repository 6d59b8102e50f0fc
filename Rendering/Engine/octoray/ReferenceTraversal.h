// The plain traversal that Traverse (Traversal.h) is measured and checked
// against: every child of a visited node gets a slab test of its own box,
// the box of each node comes back from its Morton key, and a stack holds
// (node, level, entry) for every child met, pushed farthest first. It is
// what the engine traced with before; tests compare Traverse's visits with
// its visits, and octoray_bench_render's `traversal` part times both in one
// run. Host only: it is a reference, not a path the renderers take.
#pragma once

#include "Traversal.h"

namespace octoray
{
// Same contract as Traverse: the drawn voxels within [tMin, tMax], nearest
// first, until the visitor's Visit returns true.
template <typename Visitor>
void ReferenceTraverse(const OctreeView& tree, const Ray& ray, const LevelOfDetail& lod, Visitor& visitor)
{
  struct Entry
  {
    std::uint32_t node;
    int level;
    float tEnter;
  };
  // At most 7 children of a node are met (8 when the ray grazes its
  // centre, with zero length), so 7 per level plus one never overflows.
  Entry stack[7 * (kMaxLevel + 1) + 1];
  int top = 0;
  {
    float t0, t1;
    int axis;
    if (!IntersectBox(ray, Vec3f{ 0.0f, 0.0f, 0.0f }, 1.0f, t0, t1, axis) || t1 < ray.tMin || t0 > ray.tMax)
    {
      return;
    }
    stack[top++] = Entry{ 0u, 0, t0 };
  }
  const unsigned signs = DirectionSigns(ray);
  while (top > 0)
  {
    const Entry e = stack[--top];
    if (e.tEnter > ray.tMax)
    {
      return;
    }
    NodeHit hit;
    hit.node = e.node;
    hit.level = e.level;
    hit.size = PowerOfTwo(-e.level);
    std::uint32_t cell[3];
    DecodeMorton(tree.Key(e.node), cell[0], cell[1], cell[2]);
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
    const unsigned mask = ChildMaskOf(tree, e.node);
    for (int i = 7; i >= 0; --i) // farthest first, so that they pop nearest first
    {
      const unsigned octant = static_cast<unsigned>(i) ^ signs;
      if (!(mask & (1u << octant)))
      {
        continue;
      }
      const Vec3f lo = hit.lo +
        Vec3f{ (octant & 1u) ? half : 0.0f, (octant & 2u) ? half : 0.0f, (octant & 4u) ? half : 0.0f };
      float t0, t1;
      int axis;
      if (IntersectBox(ray, lo, half, t0, t1, axis) && t1 >= ray.tMin && t0 <= ray.tMax)
      {
        stack[top++] = Entry{ ChildIndex(mask, FirstChildOf(tree, e.node), octant), e.level + 1, t0 };
      }
    }
  }
}
}
