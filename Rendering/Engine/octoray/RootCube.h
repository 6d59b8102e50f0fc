// The cube that holds every point, and the map from data coordinates onto the
// 2^21 grid of full-depth Morton keys. Kept in double precision: data placed
// far from the origin (UTM coordinates, 1e7 offsets) keeps its detail because
// the offset is subtracted before anything is rounded to float.
#pragma once

#include "Config.h"
#include "Morton.h"
#include "VecMath.h"

namespace octoray
{
struct RootCube
{
  double origin[3] = { 0.0, 0.0, 0.0 }; // minimum corner
  double size = 1.0;                    // side length; one scale for all axes, so voxels stay cubes

  // The cube around bounds [lo, hi]: centred on the box, its side the box's
  // largest extent padded by 2^-20 so that the maximum point falls strictly
  // inside. Degenerate boxes (one point, coincident points) get side 1 or,
  // far from the origin, a side large enough to be representable there.
  static RootCube FromBounds(const double lo[3], const double hi[3])
  {
    RootCube cube;
    double extent = 0.0;
    double magnitude = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      extent = hi[a] - lo[a] > extent ? hi[a] - lo[a] : extent;
      const double m = (lo[a] < 0 ? -lo[a] : lo[a]) > (hi[a] < 0 ? -hi[a] : hi[a])
        ? (lo[a] < 0 ? -lo[a] : lo[a])
        : (hi[a] < 0 ? -hi[a] : hi[a]);
      magnitude = m > magnitude ? m : magnitude;
    }
    // A side below ~2^-30 of the coordinates' magnitude cannot be resolved by
    // 21-bit keys in double precision; treat such a box as a single point.
    const double smallest = magnitude * 0x1p-30;
    if (!(extent > smallest))
    {
      extent = magnitude > 0.0 ? magnitude * 0x1p-20 : 1.0;
    }
    cube.size = extent * (1.0 + 0x1p-20);
    for (int a = 0; a < 3; ++a)
    {
      cube.origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * cube.size;
    }
    return cube;
  }

  static RootCube FromBounds(const Vec3d& lo, const Vec3d& hi)
  {
    const double l[3] = { lo.x, lo.y, lo.z }, h[3] = { hi.x, hi.y, hi.z };
    return FromBounds(l, h);
  }

  // Full-depth grid cell of a point; false when the point lies outside.
  OCTORAY_HD bool GridCell(double x, double y, double z, std::uint32_t cell[3]) const
  {
    return Grid().Cell(x, y, z, cell);
  }

  // The map onto the full-depth grid, its scale divided out once: a loop
  // over points takes it rather than the cube, which would divide again
  // for every point.
  struct CellMap
  {
    double origin[3];
    double cellsPerUnit;

    OCTORAY_HD bool Cell(double x, double y, double z, std::uint32_t cell[3]) const
    {
      const double p[3] = { x, y, z };
      for (int a = 0; a < 3; ++a)
      {
        const double g = (p[a] - origin[a]) * cellsPerUnit;
        // Written so that NaN also fails the test.
        if (!(g >= 0.0 && g < static_cast<double>(1u << kMaxLevel)))
        {
          return false;
        }
        cell[a] = static_cast<std::uint32_t>(g);
      }
      return true;
    }
  };
  OCTORAY_HD CellMap Grid() const
  {
    return CellMap{ { origin[0], origin[1], origin[2] }, static_cast<double>(1u << kMaxLevel) / size };
  }

  OCTORAY_HD bool Contains(const Vec3d& p) const
  {
    std::uint32_t cell[3];
    return GridCell(p.x, p.y, p.z, cell);
  }

  OCTORAY_HD bool FullKey(double x, double y, double z, std::uint64_t& key) const
  {
    std::uint32_t c[3];
    if (!GridCell(x, y, z, c))
    {
      return false;
    }
    key = EncodeMorton(c[0], c[1], c[2]);
    return true;
  }
};
}
