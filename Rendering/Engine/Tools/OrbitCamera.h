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
      LookAtPerspective(eye, centre, up, double(settings.width) / settings.height, zNear, zFar);
    return Invert4x4(vp.data(), settings.inverseViewProjection);
  }

  std::array<double, 16> LookAtPerspective(const double eye[3], const double target[3], const double up[3],
    double aspect, double zNear, double zFar) const
  {
    double f[3] = { target[0] - eye[0], target[1] - eye[1], target[2] - eye[2] };
    const double fl = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (double& v : f)
      v /= fl;
    double s[3] = { f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0] };
    const double sl = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (double& v : s)
      v /= sl;
    const double u[3] = { s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0] };
    const double view[16] = { s[0], s[1], s[2], -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]), u[0], u[1], u[2],
      -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]), -f[0], -f[1], -f[2],
      f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2], 0, 0, 0, 1 };
    const double t = 1.0 / std::tan(fovy * M_PI / 360.0);
    const double proj[16] = { t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, -(zFar + zNear) / (zFar - zNear),
      -2 * zFar * zNear / (zFar - zNear), 0, 0, -1, 0 };
    std::array<double, 16> m{};
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k)
          m[4 * r + c] += proj[4 * r + k] * view[4 * k + c];
    return m;
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
