// The synthetic scenes of the engine benchmarks, in one place so that the
// CPU programs and the CUDA one (CudaBench.cu) time the same points:
//   - SphereField: points on the surfaces of 48 spheres in the unit cube
//     (render throughput, quantisation error);
//   - ThesisSliceStack: the thesis's table 2 clouds, grid points of a
//     thresholded slice stack (an ellipsoid, slice by slice);
//   - TwoSpheres: the thesis's two-sphere scene, two solid spheres as
//     grid points, one of them a mirror;
// and CubeCamera, the fixed camera of the CUDA benchmark and the thesis
// tables. Header-only and VTK-free (compiles under nvcc too).
#pragma once

#include "BenchUtil.h"

#include <octoray/Engine.h>
#include <octoray/Frame.h>
#include <octoray/PointCloud.h>
#include <octoray/Render.h>
#include <octoray/RootCube.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace octoray
{
namespace bench
{
// The backends `--backend cpu|cuda|all` names. CUDA is left out where no
// device is usable, saying why; asked for alone, that leaves none.
inline std::vector<Backend> RequestedBackends(const std::string& choice)
{
  std::vector<Backend> backends;
  if (choice == "cpu" || choice == "all")
  {
    backends.push_back(Backend::CPU);
  }
  if (choice == "cuda" || choice == "all")
  {
    std::string why;
    if (CudaAvailable(&why))
    {
      backends.push_back(Backend::CUDA);
    }
    else
    {
      std::printf("CUDA skipped: %s\n", why.c_str());
    }
  }
  return backends;
}

// The engine of the one backend `--backend cpu|cuda` names; null where that
// is CUDA and none is usable (the program then has nothing to measure).
inline std::unique_ptr<Engine> RequestedEngine(const std::string& choice)
{
  const std::vector<Backend> backends = RequestedBackends(choice);
  return backends.empty() ? nullptr : CreateEngine(backends.front());
}

// Float positions, 8-bit colours and a reflectivity per point: the
// attributes the CUDA benchmark's clouds carry.
struct ColouredCloud
{
  std::vector<float> xyz;
  std::vector<std::uint8_t> rgb;
  std::vector<float> reflectivity;

  std::size_t Size() const { return xyz.size() / 3; }
  PointCloudView View() const
  {
    PointCloudView v;
    v.count = Size();
    v.xyzFloat = xyz.data();
    v.color8 = rgb.data();
    v.colorComponents = 3;
    v.reflectivity = reflectivity.data();
    return v;
  }
  void Add(double x, double y, double z, std::uint8_t r, std::uint8_t g, std::uint8_t b, float mirror)
  {
    xyz.insert(xyz.end(), { float(x), float(y), float(z) });
    rgb.insert(rgb.end(), { r, g, b });
    reflectivity.push_back(mirror);
  }
};

// The thesis's table 2 clouds (2015): a thresholded slice stack, i.e. the
// grid points inside an ellipsoid with semi-axes 1, 0.8, 0.6, walked slice
// by slice (z, then y, then x) with the spacing that puts about n points
// inside; the first n in that order are kept, so the counts match the
// thesis's exactly.
inline ColouredCloud ThesisSliceStack(std::size_t n)
{
  const double volume = 4.0 / 3.0 * M_PI * 1.0 * 0.8 * 0.6;
  const double h = std::cbrt(volume / (n * 1.02));
  ColouredCloud c;
  for (double z = -0.6; z <= 0.6 && c.xyz.size() < 3 * n; z += h)
    for (double y = -0.8; y <= 0.8 && c.xyz.size() < 3 * n; y += h)
      for (double x = -1.0; x <= 1.0 && c.xyz.size() < 3 * n; x += h)
        if (x * x + y * y / 0.64 + z * z / 0.36 <= 1.0)
        {
          c.Add(x, y, z, 200, 180, 160, 0.0f);
        }
  return c;
}

// The point counts of the thesis's table 2.
inline std::vector<std::size_t> ThesisTable2Counts()
{
  return { 30641, 303374, 951879, 1076596, 3283639 };
}

// Two solid spheres of radius 0.5 side by side (centres 0.6 either side of
// the origin on x), as grid points like a thresholded slice stack: a
// diffuse red one and a grey mirror (reflectivity 0.6). About n points.
inline ColouredCloud TwoSpheres(std::size_t n)
{
  const double r = 0.5, cx = 0.6;
  const double volume = 2 * 4.0 / 3.0 * M_PI * r * r * r;
  const double h = std::cbrt(volume / n);
  ColouredCloud c;
  for (double z = -r; z <= r; z += h)
    for (double y = -r; y <= r; y += h)
      for (double x = -cx - r; x <= cx + r; x += h)
      {
        const double dl = (x + cx) * (x + cx) + y * y + z * z, dr = (x - cx) * (x - cx) + y * y + z * z;
        if (dl <= r * r)
          c.Add(x, y, z, 220, 60, 50, 0.0f);
        else if (dr <= r * r)
          c.Add(x, y, z, 190, 190, 200, 0.6f);
      }
  return c;
}

// Points on the surfaces of `spheres` spheres in the unit cube, their
// count per sphere proportional to its area; radial normals, reflectivity
// 0.4. Double positions.
struct SphereField
{
  std::vector<double> xyz;
  std::vector<std::uint8_t> rgb;
  std::vector<float> normal, reflectivity;
  PointCloudView View(bool withReflectivity, bool withNormals) const
  {
    PointCloudView v;
    v.count = xyz.size() / 3;
    v.xyzDouble = xyz.data();
    v.color8 = rgb.data();
    v.colorComponents = 3;
    v.normal = withNormals ? normal.data() : nullptr;
    v.reflectivity = withReflectivity ? reflectivity.data() : nullptr;
    return v;
  }
};

inline SphereField MakeSphereField(std::size_t points, int spheres = 48)
{
  Random random(kDefaultSeed);
  std::vector<double> c(3 * spheres), r(spheres), area(spheres);
  std::vector<std::uint8_t> colour(3 * spheres);
  double total = 0;
  for (int s = 0; s < spheres; ++s)
  {
    r[s] = 0.03 + 0.09 * random.Uniform();
    for (int a = 0; a < 3; ++a)
    {
      c[3 * s + a] = r[s] + (1 - 2 * r[s]) * random.Uniform();
      colour[3 * s + a] = static_cast<std::uint8_t>(60 + random.Next() % 196);
    }
    total += area[s] = r[s] * r[s];
  }
  SphereField f;
  for (int s = 0; s < spheres; ++s)
  {
    const std::size_t n = static_cast<std::size_t>(points * area[s] / total);
    for (std::size_t i = 0; i < n; ++i)
    {
      // Uniform on the sphere: z uniform in [-1, 1], angle uniform.
      const double z = 2 * random.Uniform() - 1, phi = 6.283185307179586 * random.Uniform();
      const double q = std::sqrt(1 - z * z);
      const double d[3] = { q * std::cos(phi), q * std::sin(phi), z };
      for (int a = 0; a < 3; ++a)
      {
        f.xyz.push_back(c[3 * s + a] + r[s] * d[a]);
        f.normal.push_back(static_cast<float>(d[a]));
        f.rgb.push_back(colour[3 * s + a]);
      }
      f.reflectivity.push_back(0.4f);
    }
  }
  return f;
}

// The fixed camera of the CUDA benchmark and the thesis tables: looking at
// the root cube's centre from outside (1.2, -1.5, 0.8 cube sides away),
// z up, 30 degrees vertical field of view.
inline RenderSettings CubeCamera(const RootCube& cube, int w, int h)
{
  const double c[3] = { cube.origin[0] + cube.size / 2, cube.origin[1] + cube.size / 2,
    cube.origin[2] + cube.size / 2 };
  const double eye[3] = { c[0] + 1.2 * cube.size, c[1] - 1.5 * cube.size, c[2] + 0.8 * cube.size };
  double f[3] = { c[0] - eye[0], c[1] - eye[1], c[2] - eye[2] };
  double fl = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  for (double& v : f)
    v /= fl;
  const double up[3] = { 0, 0, 1 };
  double s[3] = { f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0] };
  double sl = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  for (double& v : s)
    v /= sl;
  const double u[3] = { s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0] };
  const double view[16] = { s[0], s[1], s[2], -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]), u[0], u[1], u[2],
    -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]), -f[0], -f[1], -f[2], f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2],
    0, 0, 0, 1 };
  const double zn = 0.1 * cube.size, zf = 10 * cube.size, tn = 1 / std::tan(15 * M_PI / 180), aspect = double(w) / h;
  const double proj[16] = { tn / aspect, 0, 0, 0, 0, tn, 0, 0, 0, 0, -(zf + zn) / (zf - zn), -2 * zf * zn / (zf - zn), 0,
    0, -1, 0 };
  double vp[16] = {};
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col)
      for (int k = 0; k < 4; ++k)
        vp[4 * r + col] += proj[4 * r + k] * view[4 * k + col];
  RenderSettings rs;
  rs.width = w;
  rs.height = h;
  Invert4x4(vp, rs.inverseViewProjection);
  return rs;
}
}
}
