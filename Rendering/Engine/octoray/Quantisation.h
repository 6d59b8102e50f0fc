// How far the octree moves each point: the distance, in data units, from a
// point to the centre of the leaf voxel the engine put it in. This is the
// geometric error of drawing a point as its leaf, and the octree's depth is
// the knob that trades it for nodes and memory.
//
// Measured on the engine's own octree (Engine::CopyToHost): each point's
// full-depth cell comes from the engine's root cube (the double-precision
// transform the engine keys points with), the point is walked from the root
// through the stored child masks and child offsets down to its leaf, and the
// leaf's centre is taken from the leaf's stored Morton key. A point whose
// leaf is missing from the tree is an error, not a figure.
// Header-only. The report's quantisation section measures it against leaf
// depth (Benchmarks/Engine/BenchQuantisation.cpp); TestQuantisation checks it
// against a brute-force recomputation.
//
// The same walk measures the rounding of 8-bit colours, scalars and
// normals (Attributes.h): each node's stored value against the exact mean
// of the points beneath it.
#pragma once

#include "Octree.h"
#include "PointCloud.h"
#include "Types.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace octoray
{
struct QuantisationError
{
  double max = 0.0;   // largest point-to-leaf-centre distance, data units
  double mean = 0.0;  // mean of the same distances
  double bound = 0.0; // half the leaf voxel's diagonal: sqrt(3)/2 * side / 2^depth
  double leafSide = 0.0;
  std::size_t points = 0;
};

// The centre of the voxel of `levelKey` (a level-local Morton key) at
// `level`, in data coordinates.
inline Vec3d VoxelCentre(const RootCube& cube, int level, std::uint64_t levelKey)
{
  std::uint32_t cell[3];
  DecodeMorton(levelKey, cell[0], cell[1], cell[2]);
  const double side = cube.size / std::ldexp(1.0, level);
  const Vec3d origin{ cube.origin[0], cube.origin[1], cube.origin[2] };
  return origin + Vec3d{ cell[0] + 0.5, cell[1] + 0.5, cell[2] + 0.5 } * side;
}

// The rounding of a node attribute stored rounded (Attributes.h): the
// largest difference between a node's stored value and the exact mean of
// its points' values, at the leaves and above them, and the bound at the
// root. 8-bit colours: the largest channel's, in steps of 1/255; scalars:
// in steps of their range; normals: the distance between the vectors.
struct RoundingError
{
  double leafMax = 0.0;
  double innerMax = 0.0;
  double rootBound = 0.0;
  bool withinBound = true; // every node within its level's bound
};

// The leaf of point i, found by walking the tree from the root; its node
// index. visit(node) is called for each node on the way, the root first.
// Throws when the walk leaves the tree (the engine lost the point).
template <class Visit>
std::uint32_t WalkToLeaf(const HostOctree& tree, const PointCloudView& points, std::size_t i, Visit&& visit)
{
  std::uint64_t full = 0;
  const Vec3d p = points.Position(i);
  if (!tree.cube.FullKey(p.x, p.y, p.z, full))
  {
    throw std::runtime_error("point " + std::to_string(i) + " lies outside the engine's root cube");
  }
  std::uint32_t node = 0;
  visit(node);
  for (int level = 1; level <= tree.depth; ++level)
  {
    const unsigned octant = static_cast<unsigned>(AncestorKey(full, level) & 7u);
    const unsigned mask = ChildMaskOf(tree, node);
    if (!(mask & (1u << octant)))
    {
      throw std::runtime_error("point " + std::to_string(i) + " has no node at level " + std::to_string(level));
    }
    node = ChildIndex(mask, FirstChildOf(tree, node), octant);
    visit(node);
  }
  if (tree.Key(node) != AncestorKey(full, tree.depth))
  {
    throw std::runtime_error("point " + std::to_string(i) + ": the leaf reached has another key");
  }
  return node;
}

inline QuantisationError MeasureQuantisation(const HostOctree& tree, const PointCloudView& points)
{
  QuantisationError q;
  q.points = points.count;
  q.leafSide = tree.cube.size / std::ldexp(1.0, tree.depth);
  q.bound = 0.5 * std::sqrt(3.0) * q.leafSide;
  double sum = 0.0;
  for (std::size_t i = 0; i < points.count; ++i)
  {
    const std::uint32_t leaf = WalkToLeaf(tree, points, i, [](std::uint32_t) {});
    const double d = Length(points.Position(i) - VoxelCentre(tree.cube, tree.depth, tree.Key(leaf)));
    q.max = std::max(q.max, d);
    sum += d;
  }
  q.mean = points.count ? sum / double(points.count) : 0.0;
  return q;
}

// Sums each point's Slots values, pointValue(i, values), into every node on
// its path, and compares each node's mean with its stored value by
// difference(node, mean), against bound(level).
template <int Slots, class PointValue, class Difference, class Bound>
RoundingError MeasureRounding(const HostOctree& tree, const PointCloudView& points, PointValue&& pointValue,
  Difference&& difference, Bound&& bound)
{
  std::vector<double> sum(Slots * tree.NodeCount(), 0.0);
  for (std::size_t i = 0; i < points.count; ++i)
  {
    double value[Slots];
    pointValue(i, value);
    WalkToLeaf(tree, points, i, [&](std::uint32_t node) {
      for (int k = 0; k < Slots; ++k)
      {
        sum[Slots * node + k] += value[k];
      }
    });
  }
  RoundingError e;
  e.rootBound = bound(0);
  for (int level = 0; level <= tree.depth; ++level)
  {
    double& worst = level == tree.depth ? e.leafMax : e.innerMax;
    for (std::uint32_t n = tree.levelBegin[level]; n < tree.levelBegin[level + 1]; ++n)
    {
      double mean[Slots];
      for (int k = 0; k < Slots; ++k)
      {
        mean[k] = sum[Slots * n + k] / tree.pointCount[n];
      }
      const double d = difference(n, mean);
      worst = std::max(worst, d);
      e.withinBound = e.withinBound && d <= bound(level) * (1 + 1e-9);
    }
  }
  return e;
}

// Needs an octree of 8-bit colours (tree.color8) built from `points`.
inline RoundingError MeasureColourQuantisation(const HostOctree& tree, const PointCloudView& points)
{
  const int cc = points.colorComponents;
  auto bytes = [&](std::size_t i, double rgba[4]) {
    const std::uint8_t* c = points.color8 + cc * i;
    for (int k = 0; k < 4; ++k)
    {
      rgba[k] = k < cc ? double(c[k]) : 255.0;
    }
  };
  auto steps = [&](std::uint32_t n, const double mean[4]) {
    const Rgba8 c = tree.color8[n];
    const double stored[4] = { double(c.r), double(c.g), double(c.b), double(c.a) };
    double worst = 0.0;
    for (int k = 0; k < 4; ++k)
    {
      worst = std::max(worst, std::fabs(stored[k] - mean[k]));
    }
    return worst;
  };
  return MeasureRounding<4>(tree, points, bytes, steps,
    [&](int level) { return 255.0 * ColourErrorBound(tree.depth, level); });
}

// Needs an octree of scalars (tree.scalar) built from `points`, all finite:
// in steps of the range (Scalar16.h).
inline RoundingError MeasureScalarQuantisation(const HostOctree& tree, const PointCloudView& points)
{
  const ScalarRange& range = tree.scalarRange;
  const double step = 2.0 * range.HalfStep();
  auto value = [&](std::size_t i, double v[1]) { v[0] = points.scalar[i]; };
  auto steps = [&](std::uint32_t n, const double mean[1]) {
    const double d = std::fabs(double(tree.Scalar(n)) - mean[0]);
    return step > 0.0 ? d / step : (d > 0.0 ? HUGE_VAL : 0.0);
  };
  return MeasureRounding<1>(tree, points, value, steps, [&](int level) {
    return step > 0.0 ? ScalarErrorBound(range, tree.depth, level) / step : 0.0;
  });
}

// Needs an octree of reflectivities built from `points`, in 0..1: each
// node's mean against the exact mean of its points' floats. The points'
// values are coded in Scalar16's unit steps (Attributes.h's UnitInput),
// each within half a step; their means add up in float, which the engine's
// tests hold to 2e-6 (TestSupport.h).
inline RoundingError MeasureReflectivityQuantisation(const HostOctree& tree, const PointCloudView& points)
{
  auto value = [&](std::size_t i, double v[1]) { v[0] = points.reflectivity[i]; };
  auto difference = [&](std::uint32_t n, const double mean[1]) {
    return std::fabs(double(tree.reflectivity[n]) - mean[0]);
  };
  return MeasureRounding<1>(tree, points, value, difference, [](int) { return 0.5 / kScalarSteps + 2e-6; });
}

// Needs an octree of normals (tree.normal) built from `points`; the exact
// means are of the caller's normals scaled to unit length in double.
inline RoundingError MeasureNormalQuantisation(const HostOctree& tree, const PointCloudView& points)
{
  auto unitNormal = [&](std::size_t i, double n[3]) {
    const Vec3d v = ToDouble(Vec3f{ points.normal[3 * i], points.normal[3 * i + 1], points.normal[3 * i + 2] });
    const double length = Length(v);
    const Vec3d unit = length > 0.0 && std::isfinite(length) ? v / length : Vec3d{ 0.0, 0.0, 0.0 };
    n[0] = unit.x, n[1] = unit.y, n[2] = unit.z;
  };
  auto distance = [&](std::uint32_t n, const double mean[3]) {
    return Length(ToDouble(DecodeNormal(tree.normal[n])) - Vec3d{ mean[0], mean[1], mean[2] });
  };
  return MeasureRounding<3>(tree, points, unitNormal, distance,
    [&](int level) { return NormalErrorBound(tree.depth, level); });
}
}
