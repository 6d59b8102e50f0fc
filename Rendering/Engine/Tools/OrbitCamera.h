// A camera orbiting the centre of a point set's bounding box, as the
// command-line tool and the render benchmark use it. Builds the OpenGL
// matrices that VTK's composite projection transform gives, so these
// programs drive the engine exactly as the VTK layer does.
#pragma once

#include <octoray/Frame.h>
#include <octoray/PointCloud.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace octoray
{
struct OrbitCamera
{
  double azimuth = -60;  // degrees about +z, from +x
  double elevation = 30; // degrees above the xy plane
  double zoom = 1;       // 1: the bounding sphere just fits the vertical field of view
  double fovy = 30;      // degrees

  static void Direction(double azimuthDeg, double elevationDeg, double d[3])
  {
    const double a = azimuthDeg * M_PI / 180, e = elevationDeg * M_PI / 180;
    d[0] = std::cos(e) * std::cos(a);
    d[1] = std::cos(e) * std::sin(a);
    d[2] = std::sin(e);
  }

  // Sets settings.inverseViewProjection for a width x height viewport
  // looking at the bounding box [lo, hi]; false if the matrix is singular.
  bool Apply(const double lo[3], const double hi[3], RenderSettings& settings) const
  {
    const double centre[3] = { 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]) };
    const double radius = std::max(1e-9, 0.5 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) +
      (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2])));
    const double distance = radius / std::sin(fovy * M_PI / 360) / zoom;
    double d[3];
    Direction(azimuth, elevation, d);
    const double eye[3] = { centre[0] + distance * d[0], centre[1] + distance * d[1], centre[2] + distance * d[2] };
    const double up[3] = { 0, 0, std::cos(elevation * M_PI / 180) >= 0 ? 1.0 : -1.0 };
    const double zNear = std::max(distance - 1.01 * radius, 1e-3 * distance);
    const double zFar = distance + 1.01 * radius;
    const std::array<double, 16> vp =
      ViewProjection(eye, centre, up, fovy, double(settings.width) / settings.height, zNear, zFar);
    return Invert4x4(vp.data(), settings.inverseViewProjection);
  }
};

// Bounding box of a point set.
inline void Bounds(const PointCloudView& points, double lo[3], double hi[3])
{
  for (int k = 0; k < 3; ++k)
  {
    lo[k] = std::numeric_limits<double>::infinity();
    hi[k] = -lo[k];
  }
  for (std::size_t i = 0; i < points.count; ++i)
    for (int k = 0; k < 3; ++k)
    {
      lo[k] = std::min(lo[k], points.Coordinate(i, k));
      hi[k] = std::max(hi[k], points.Coordinate(i, k));
    }
}
}
