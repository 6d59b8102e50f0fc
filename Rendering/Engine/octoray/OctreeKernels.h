// Per-point and per-node steps of the octree build and update, written once
// for both backends: the CPU backend calls them inside a parallel-for, the
// CUDA backend from __global__ kernels. Every node attribute is the plain
// mean over the points beneath it, so an inner node's value is the
// count-weighted mean of its children's and updates can adjust it by deltas.
#pragma once

#include "Octree.h"
#include "PointArrays.h"

namespace octoray
{
// Reads a node's attribute vector (present attributes only).
OCTORAY_HD void LoadNodeAttributes(const OctreeView& t, std::uint32_t n, float v[kSlotCount])
{
  if (t.color)
  {
    v[kSlotR] = t.color[n].r;
    v[kSlotG] = t.color[n].g;
    v[kSlotB] = t.color[n].b;
    v[kSlotA] = t.color[n].a;
  }
  if (t.scalar)
  {
    v[kSlotScalar] = t.scalar[n];
  }
  if (t.reflectivity)
  {
    v[kSlotReflectivity] = t.reflectivity[n];
  }
  if (t.refraction)
  {
    v[kSlotRefraction] = t.refraction[n];
  }
  if (t.normal)
  {
    v[kSlotNx] = t.normal[n].x;
    v[kSlotNy] = t.normal[n].y;
    v[kSlotNz] = t.normal[n].z;
  }
}

// Writes sum / count into the node's present attributes.
OCTORAY_HD void StoreNodeMeans(const OctreeView& t, std::uint32_t n, const double sum[kSlotCount], double count)
{
  const double inv = count > 0.0 ? 1.0 / count : 0.0;
  if (t.color)
  {
    t.color[n] = Rgba{ static_cast<float>(sum[kSlotR] * inv), static_cast<float>(sum[kSlotG] * inv),
      static_cast<float>(sum[kSlotB] * inv), static_cast<float>(sum[kSlotA] * inv) };
  }
  if (t.scalar)
  {
    t.scalar[n] = static_cast<float>(sum[kSlotScalar] * inv);
  }
  if (t.reflectivity)
  {
    t.reflectivity[n] = static_cast<float>(sum[kSlotReflectivity] * inv);
  }
  if (t.refraction)
  {
    t.refraction[n] = static_cast<float>(sum[kSlotRefraction] * inv);
  }
  if (t.normal)
  {
    t.normal[n] = Vec3f{ static_cast<float>(sum[kSlotNx] * inv), static_cast<float>(sum[kSlotNy] * inv),
      static_cast<float>(sum[kSlotNz] * inv) };
  }
}

// Point i's full-depth key; false if it is not finite or lies outside the cube.
OCTORAY_HD bool ComputePointKey(const PointArraysView& pts, const RootCube& cube, std::size_t i, std::uint64_t& key)
{
  double p[3];
  pts.Position(i, p);
  return cube.FullKey(p[0], p[1], p[2], key);
}

// Leaf `node` holds the sorted points [begin, end): key, topology and means.
OCTORAY_HD void ReduceLeaf(const OctreeView& t, const PointArraysView& pts, const std::uint32_t* sortedIndex,
  std::uint32_t node, std::uint64_t levelKey, std::uint32_t begin, std::uint32_t end)
{
  t.key[node] = levelKey;
  t.childMask[node] = 0;
  t.firstChild[node] = kInvalidIndex;
  t.pointCount[node] = end - begin;
  if (!t.attributes)
  {
    return;
  }
  double sum[kSlotCount] = {};
  float v[kSlotCount] = {};
  for (std::uint32_t s = begin; s < end; ++s)
  {
    pts.Attributes(sortedIndex[s], v);
    for (int k = 0; k < kSlotCount; ++k)
    {
      sum[k] += v[k];
    }
  }
  StoreNodeMeans(t, node, sum, static_cast<double>(end - begin));
}

// Inner `node` has the children [c0, c1) (global indices, one level down):
// child mask, links both ways, count and count-weighted means.
OCTORAY_HD void ReduceChildren(const OctreeView& t, std::uint32_t node, std::uint64_t levelKey, std::uint32_t c0,
  std::uint32_t c1)
{
  t.key[node] = levelKey;
  t.firstChild[node] = c0;
  unsigned mask = 0;
  std::uint32_t count = 0;
  double sum[kSlotCount] = {};
  float v[kSlotCount] = {};
  for (std::uint32_t c = c0; c < c1; ++c)
  {
    mask |= 1u << OctantOf(t.key[c]);
    t.parent[c] = node;
    const std::uint32_t n = t.pointCount[c];
    count += n;
    if (t.attributes)
    {
      LoadNodeAttributes(t, c, v);
      for (int k = 0; k < kSlotCount; ++k)
      {
        sum[k] += static_cast<double>(v[k]) * n;
      }
    }
  }
  t.childMask[node] = static_cast<std::uint8_t>(mask);
  t.pointCount[node] = count;
  if (t.attributes)
  {
    StoreNodeMeans(t, node, sum, static_cast<double>(count));
  }
}

// In-place update: node n gains dCount points whose attributes add up to
// dSum (negative for points that left). False if the node would be emptied,
// which changes the topology and needs the re-sort path instead.
OCTORAY_HD bool ApplyNodeDelta(const OctreeView& t, std::uint32_t n, long long dCount, const double dSum[kSlotCount])
{
  const long long count = static_cast<long long>(t.pointCount[n]) + dCount;
  if (count <= 0)
  {
    return false;
  }
  if (t.attributes)
  {
    float v[kSlotCount] = {};
    LoadNodeAttributes(t, n, v);
    double sum[kSlotCount];
    for (int k = 0; k < kSlotCount; ++k)
    {
      sum[k] = static_cast<double>(v[k]) * t.pointCount[n] + dSum[k];
    }
    StoreNodeMeans(t, n, sum, static_cast<double>(count));
  }
  t.pointCount[n] = static_cast<std::uint32_t>(count);
  return true;
}
}
