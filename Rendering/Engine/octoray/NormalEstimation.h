// Normals for octrees of points that came without them (a scan, a
// simulation's particles): each node's is the normal of the plane that best
// fits the occupied voxels around it at its level, the direction in which
// they spread least (principal component analysis, as PCL's
// NormalEstimation fits the k nearest points). The six-neighbour occupancy
// gradient the renderer falls back to (RenderKernels.h's SurfaceNormal)
// knows 26 directions and vanishes on a sheet one voxel thick, both sides
// empty, which is what a scanned surface is at its leaves: its Phong picture
// is speckle. The fit is made once per octree, at the first frame that
// shades it (OctreeEngine's ShadingView), in a loop over the nodes that
// both backends run.
#pragma once

#include "Morton.h"
#include "Octree.h"
#include "OctreeState.h"
#include "Render.h"
#include "VecMath.h"

namespace octoray
{
// Voxels within this many cells of a node, on each axis, take part in its
// fit: 5 x 5 x 5 at its level. Of 3 x 3 x 3 the fit follows each voxel of a
// noisy scan (the milk carton of PCL's test data showed its scan's noise as
// ripples); of 5 x 5 x 5 it follows the surface.
constexpr int kNormalFitRadius = 2;

// The eigenvector of the smallest eigenvalue of the symmetric matrix
// [a00 a01 a02; a01 a11 a12; a02 a12 a22], of unit length; zero where that
// eigenvalue is not clearly the smallest (a line, a ball: no one plane).
// Eigenvalues in closed form (the trigonometric solution of the
// characteristic cubic), the vector as the longest cross product of two
// rows of A - lambda I, which it is perpendicular to.
OCTORAY_HD Vec3d LeastSpreadDirection(double a00, double a01, double a02, double a11, double a12, double a22)
{
  const double q = (a00 + a11 + a22) / 3.0;
  const double offDiagonal = a01 * a01 + a02 * a02 + a12 * a12;
  const double p2 = (a00 - q) * (a00 - q) + (a11 - q) * (a11 - q) + (a22 - q) * (a22 - q) + 2.0 * offDiagonal;
  const double p = sqrt(p2 / 6.0);
  if (!(p > 1e-12 * (q > 0.0 ? q : 1.0)))
  {
    return Vec3d{ 0.0, 0.0, 0.0 }; // isotropic: every direction alike
  }
  const double b00 = (a00 - q) / p, b11 = (a11 - q) / p, b22 = (a22 - q) / p;
  const double b01 = a01 / p, b02 = a02 / p, b12 = a12 / p;
  double r = 0.5 * (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) + b02 * (b01 * b12 - b11 * b02));
  r = r < -1.0 ? -1.0 : (r > 1.0 ? 1.0 : r);
  const double phi = acos(r) / 3.0;
  const double largest = q + 2.0 * p * cos(phi);
  const double smallest = q + 2.0 * p * cos(phi + 2.0943951023931957); // + 2 pi / 3
  const double middle = 3.0 * q - largest - smallest;
  // A plane spreads in two directions and hardly in the third.
  if (middle - smallest < 0.25 * (largest - smallest))
  {
    return Vec3d{ 0.0, 0.0, 0.0 };
  }
  const Vec3d row0{ a00 - smallest, a01, a02 };
  const Vec3d row1{ a01, a11 - smallest, a12 };
  const Vec3d row2{ a02, a12, a22 - smallest };
  Vec3d best = Cross(row0, row1);
  const Vec3d others[2] = { Cross(row0, row2), Cross(row1, row2) };
  for (const Vec3d& c : others)
  {
    best = Dot(c, c) > Dot(best, best) ? c : best;
  }
  const double length = Length(best);
  return length > 0.0 ? best * (1.0 / length) : Vec3d{ 0.0, 0.0, 0.0 };
}

// The node of `level` at cell (x, y, z), or kInvalidIndex where there is none
// (or the cell lies outside the grid).
OCTORAY_HD std::uint32_t NodeAt(const OctreeView& tree, int level, int x, int y, int z)
{
  const int cells = 1 << level;
  const bool inside = x >= 0 && y >= 0 && z >= 0 && x < cells && y < cells && z < cells;
  return inside ? tree.Find(level, EncodeMorton(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                                      static_cast<std::uint32_t>(z)))
                : kInvalidIndex;
}

// The octants of a block of 4 cells an axis at (bx, by, bz), each 2 cells
// an axis, that reach within kNormalFitRadius of cell (cx, cy, cz).
OCTORAY_HD unsigned OctantsNear(int bx, int by, int bz, int cx, int cy, int cz)
{
  unsigned octants = 0;
  for (unsigned o = 0; o < 8; ++o)
  {
    const int x = 4 * bx + 2 * static_cast<int>(o & 1u), y = 4 * by + 2 * static_cast<int>(o >> 1 & 1u),
              z = 4 * bz + 2 * static_cast<int>(o >> 2 & 1u);
    const bool near = x + 1 >= cx - kNormalFitRadius && x <= cx + kNormalFitRadius &&
      y + 1 >= cy - kNormalFitRadius && y <= cy + kNormalFitRadius && z + 1 >= cz - kNormalFitRadius &&
      z <= cz + kNormalFitRadius;
    octants |= near ? 1u << o : 0u;
  }
  return octants;
}

// fn(x, y, z) for each occupied cell two levels below node `block` of cell
// (bx, by, bz), in its children of `octants`: their child masks.
template <typename Fn>
OCTORAY_HD void ForEachGrandchildCell(
  const OctreeView& tree, std::uint32_t block, int bx, int by, int bz, unsigned octants, Fn&& fn)
{
  const unsigned children = ChildMaskOf(tree, block);
  const std::uint32_t firstChild = FirstChildOf(tree, block);
  for (unsigned left = children & octants; left != 0; left &= left - 1)
  {
    const unsigned c = LowestBit(left);
    for (unsigned cells = ChildMaskOf(tree, ChildIndex(children, firstChild, c)); cells != 0; cells &= cells - 1)
    {
      const unsigned g = LowestBit(cells);
      fn(4 * bx + 2 * static_cast<int>(c & 1u) + static_cast<int>(g & 1u),
        4 * by + 2 * static_cast<int>(c >> 1 & 1u) + static_cast<int>(g >> 1 & 1u),
        4 * bz + 2 * static_cast<int>(c >> 2 & 1u) + static_cast<int>(g >> 2 & 1u));
    }
  }
}

// fn(dx, dy, dz) for each occupied voxel of `level` within kNormalFitRadius
// cells of cell (cx, cy, cz) on every axis, the cell itself too. The window
// of 5 cells an axis lies in two blocks of 4 an axis, the cells of a node
// two levels up: eight searches of that level (OctreeView::Find) and the
// child masks beneath the blocks found give every voxel of the window,
// where a search a voxel would take 125. Levels 0 and 1 search each cell.
template <typename Fn>
OCTORAY_HD void ForEachOccupiedNear(const OctreeView& tree, int level, int cx, int cy, int cz, Fn&& fn)
{
  static_assert(kNormalFitRadius == 2, "the window's cells are the grandchildren of two blocks an axis");
  const auto near = [&](int x, int y, int z) {
    const int dx = x - cx, dy = y - cy, dz = z - cz;
    if (abs(dx) <= kNormalFitRadius && abs(dy) <= kNormalFitRadius && abs(dz) <= kNormalFitRadius)
    {
      fn(dx, dy, dz);
    }
  };
  const int cells = 1 << level;
  if (level < 2)
  {
    for (int cell = 0; cell < cells * cells * cells; ++cell)
    {
      const int x = cell % cells, y = cell / cells % cells, z = cell / (cells * cells);
      if (NodeAt(tree, level, x, y, z) != kInvalidIndex)
      {
        near(x, y, z);
      }
    }
    return;
  }
  // The block of the window's first cell (-1 where that lies outside).
  const auto firstBlock = [](int c) { return (c - kNormalFitRadius + 4) / 4 - 1; };
  for (int corner = 0; corner < 8; ++corner)
  {
    const int bx = firstBlock(cx) + (corner & 1), by = firstBlock(cy) + (corner >> 1 & 1),
              bz = firstBlock(cz) + (corner >> 2 & 1);
    const std::uint32_t block = NodeAt(tree, level - 2, bx, by, bz);
    if (block != kInvalidIndex)
    {
      ForEachGrandchildCell(tree, block, bx, by, bz, OctantsNear(bx, by, bz, cx, cy, cz), near);
    }
  }
}

// The first and second moments of a set of voxels' offsets, in integers
// (offsets of at most kNormalFitRadius, at most 125 voxels: no overflow).
struct VoxelMoments
{
  int count = 0, x = 0, y = 0, z = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  OCTORAY_HD void Add(int dx, int dy, int dz)
  {
    ++count;
    x += dx, y += dy, z += dz;
    xx += dx * dx, xy += dx * dy, xz += dx * dz, yy += dy * dy, yz += dy * dz, zz += dz * dz;
  }

  // The direction in which the voxels spread least (LeastSpreadDirection of
  // their covariance).
  OCTORAY_HD Vec3d LeastSpread() const
  {
    const double inv = 1.0 / count, mx = x * inv, my = y * inv, mz = z * inv;
    return LeastSpreadDirection(xx * inv - mx * mx, xy * inv - mx * my, xz * inv - mx * mz, yy * inv - my * my,
      yz * inv - my * mz, zz * inv - mz * mz);
  }
};

// The normal of node `n` of `level` (either sign), from the voxels of that
// level within kNormalFitRadius of it; zero where they fit no plane.
OCTORAY_HD OctNormal EstimateNodeNormal(const OctreeView& tree, int level, std::uint32_t n)
{
  std::uint32_t cx, cy, cz;
  DecodeMorton(tree.Key(n), cx, cy, cz);
  VoxelMoments moments;
  ForEachOccupiedNear(tree, level, static_cast<int>(cx), static_cast<int>(cy), static_cast<int>(cz),
    [&](int dx, int dy, int dz) { moments.Add(dx, dy, dz); });
  const Vec3d normal = moments.LeastSpread();
  return EncodeNormal(Vec3f{ static_cast<float>(normal.x), static_cast<float>(normal.y), static_cast<float>(normal.z) });
}

// Whether a frame of `settings` lights or bends rays by surface normals:
// Phong, mirrors and refraction in the surface mode.
inline bool FrameUsesNormals(const RenderSettings& settings, unsigned attributes)
{
  const bool bounces = settings.maxBounces > 0 && (attributes & (kHasReflectivity | kHasRefraction)) != 0;
  return settings.blend == BlendMode::Surface && (settings.shade == ShadeMode::Phong || bounces);
}

// Node n's estimated normal: its own fit, or where its voxels fit no plane
// (the ragged edge of a scanned sheet is a line at its level, a stray
// voxel beside it a ball) its parent's, already in `estimated`: the
// parent's window spans twice the cells and sees the surface the node lies
// on. Zero where no ancestor found a plane either.
OCTORAY_HD OctNormal EstimateOrInheritNormal(
  const OctreeView& tree, int level, std::uint32_t n, const OctNormal* estimated)
{
  const OctNormal own = EstimateNodeNormal(tree, level, n);
  if (level == 0 || own.bits != 0) // a zero normal encodes as 0
  {
    return own;
  }
  return estimated[tree.Find(level - 1, tree.Key(n) >> 3)];
}

// Fills s.estimatedNormals with every node's EstimateOrInheritNormal, one
// loop a level from the root down, so that a parent's is made before its
// children look it up.
template <class Device>
void EstimateNormals(Device& d, OctreeState<Device>& s)
{
  const OctreeView tree = s.View();
  d.Reserve(s.estimatedNormals, tree.nodeCount, MemoryReport::NodeArray(s.kEstimatedNormalsLabel).c_str());
  OctNormal* out = s.estimatedNormals.Get();
  for (int level = 0; level <= tree.depth; ++level)
  {
    const std::uint32_t begin = tree.levelBegin[level];
    d.ForEach("EstimateNormalsKernel", tree.LevelSize(level), OCTORAY_LAMBDA(std::size_t i) {
      const std::uint32_t n = begin + static_cast<std::uint32_t>(i);
      out[n] = EstimateOrInheritNormal(tree, level, n, out);
    });
  }
  d.Synchronize("EstimateNormalsKernel");
  s.normalsEstimated = true;
}
}
