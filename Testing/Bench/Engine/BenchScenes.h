// Scenes shared by the engine's render benchmarks (octoray_bench_render,
// octoray_bench_quality): a synthetic field of spheres. Header-only and
// VTK-free, like BenchUtil.h.
#pragma once

#include "BenchUtil.h"

#include <octoray/PointCloud.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace octoray
{
namespace bench
{
// Points on the surfaces of `spheres` spheres in the unit cube, their
// count per sphere proportional to its area; radial normals, reflectivity
// 0.4, one colour per sphere.
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
}
}
