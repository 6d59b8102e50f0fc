// Refraction against Snell's law: the lateral shift through a glass slab,
// and total internal reflection at a block's side face. Scenes are built
// on a fixed 64^3 grid of unit voxels; the floor's colour encodes each
// voxel's x so that the picture says where every ray landed.
#include "TestSupport.h"

#include <octoray/Frame.h>

#include <cmath>

using namespace octoray;
using namespace octoray::test;

namespace
{
struct Scene
{
  std::vector<double> xyz;
  std::vector<std::uint8_t> rgb;
  std::vector<float> refraction;

  void Voxel(int x, int y, int z, std::uint8_t r, std::uint8_t g, float ior)
  {
    xyz.insert(xyz.end(), { x + 0.5, y + 0.5, z + 0.5 });
    rgb.insert(rgb.end(), { r, g, 255 });
    refraction.push_back(ior);
  }
  // The floor z = 0: red encodes x (4 per voxel), green y.
  void Floor()
  {
    for (int x = 0; x < 64; ++x)
      for (int y = 0; y < 64; ++y)
        Voxel(x, y, 0, static_cast<std::uint8_t>(4 * x), static_cast<std::uint8_t>(4 * y), 0.0f);
  }
  PointCloudView View() const
  {
    PointCloudView v;
    v.count = xyz.size() / 3;
    v.xyzDouble = xyz.data();
    v.color8 = rgb.data();
    v.colorComponents = 3;
    v.refraction = refraction.data();
    return v;
  }
};

BuildOptions Grid64()
{
  BuildOptions o;
  o.depth = 6;
  o.fixedCube = true;
  o.cube.size = 64.0;
  return o;
}

// A parallel projection looking along `dir` (unit, world) at the grid centre.
RenderSettings ParallelView(const double dir[3], int w, int h, double halfHeight)
{
  const double up0[3] = { 0, 1, 0 };
  double s[3] = { dir[1] * up0[2] - dir[2] * up0[1], dir[2] * up0[0] - dir[0] * up0[2],
    dir[0] * up0[1] - dir[1] * up0[0] };
  const double sl = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  for (double& v : s)
    v /= sl;
  const double u[3] = { s[1] * dir[2] - s[2] * dir[1], s[2] * dir[0] - s[0] * dir[2], s[0] * dir[1] - s[1] * dir[0] };
  const double eye[3] = { 32 - 100 * dir[0], 32 - 100 * dir[1], 32 - 100 * dir[2] };
  const double view[16] = { s[0], s[1], s[2], -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]), u[0], u[1], u[2],
    -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]), -dir[0], -dir[1], -dir[2],
    dir[0] * eye[0] + dir[1] * eye[1] + dir[2] * eye[2], 0, 0, 0, 1 };
  const double zn = 1, zf = 300, aspect = double(w) / h;
  const double proj[16] = { 1 / (halfHeight * aspect), 0, 0, 0, 0, 1 / halfHeight, 0, 0, 0, 0, -2 / (zf - zn),
    -(zf + zn) / (zf - zn), 0, 0, 0, 1 };
  double vp[16] = {};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k)
        vp[4 * r + c] += proj[4 * r + k] * view[4 * k + c];
  RenderSettings rs;
  rs.width = w;
  rs.height = h;
  Invert4x4(vp, rs.inverseViewProjection);
  return rs;
}

// World point where pixel (x, y)'s ray crosses the plane z = planeZ.
void PixelRayAtZ(const RenderSettings& s, int x, int y, const double dir[3], double planeZ, double p[3])
{
  const double ndc[4] = { 2.0 * (x + 0.5) / s.width - 1, 2.0 * (y + 0.5) / s.height - 1, -1, 1 };
  double h[4] = {};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k)
      h[i] += s.inverseViewProjection[4 * i + k] * ndc[k];
  const double o[3] = { h[0] / h[3], h[1] / h[3], h[2] / h[3] };
  const double t = (planeZ - o[2]) / dir[2];
  for (int a = 0; a < 3; ++a)
    p[a] = o[a] + t * dir[a];
}

using Refraction = BackendTest;
}

TEST_P(Refraction, GlassSlabShiftsTheRayAsSnellSays)
{
  // Glass (index 1.5) fills 20 <= z < 28; the floor lies 19 voxels below.
  Scene scene;
  scene.Floor();
  for (int x = 0; x < 64; ++x)
    for (int y = 0; y < 64; ++y)
      for (int z = 20; z < 28; ++z)
        scene.Voxel(x, y, z, 255, 255, 1.5f);
  engine->Build(scene.View(), Grid64());
  const double theta = 45.0 * M_PI / 180;
  const double dir[3] = { std::sin(theta), 0, -std::cos(theta) };
  RenderSettings s = ParallelView(dir, 48, 48, 10);
  Image image;
  engine->Render(s, image);

  const double thetaT = std::asin(std::sin(theta) / 1.5);
  int exact = 0, near = 0, checked = 0;
  for (int y = 0; y < s.height; ++y)
  {
    for (int x = 0; x < s.width; ++x)
    {
      double top[3];
      PixelRayAtZ(s, x, y, dir, 28.0, top);
      if (top[0] < 4 || top[0] > 40 || top[1] < 4 || top[1] > 60)
        continue;
      // Down 8 voxels of glass at thetaT, then 19 of air at theta to the
      // floor's top face (z = 1).
      const double floorX = top[0] + 8 * std::tan(thetaT) + 19 * std::tan(theta);
      const double straightX = top[0] + 27 * std::tan(theta);
      const std::size_t i = std::size_t(y) * s.width + x;
      const int seen = static_cast<int>(std::lround(image.rgba[4 * i] * 255.0 / 4.0));
      ++checked;
      exact += seen == static_cast<int>(std::floor(floorX));
      near += std::abs(seen - static_cast<int>(std::floor(floorX))) <= 1;
      // The refracted path lands ~3.7 voxels short of the straight one.
      EXPECT_LT(seen, static_cast<int>(std::floor(straightX)) - 2) << "pixel " << x << "," << y;
    }
  }
  ASSERT_GT(checked, 500);
  EXPECT_EQ(near, checked);                 // every pixel within one voxel of Snell's landing point
  EXPECT_GE(exact * 100, checked * 95);     // and 95% on the very voxel
}

TEST_P(Refraction, TotalInternalReflectionAtTheSideFace)
{
  // A glass block 0 <= x < 32, 8 <= z < 24; air beyond x = 32.
  Scene scene;
  scene.Floor();
  for (int x = 0; x < 32; ++x)
    for (int y = 0; y < 64; ++y)
      for (int z = 8; z < 24; ++z)
        scene.Voxel(x, y, z, 255, 255, 1.5f);
  engine->Build(scene.View(), Grid64());
  const double theta = 60.0 * M_PI / 180;
  const double dir[3] = { std::sin(theta), 0, -std::cos(theta) };
  RenderSettings s = ParallelView(dir, 64, 32, 12);
  s.maxBounces = 3; // in, reflected at the side, out
  Image image;
  engine->Render(s, image);

  const double thetaT = std::asin(std::sin(theta) / 1.5); // 35.3 deg; the side sees 54.7 > 41.8 (critical)
  const double critical = std::asin(1 / 1.5);
  ASSERT_GT(M_PI / 2 - thetaT, critical);
  int checked = 0, near = 0;
  for (int y = 0; y < s.height; ++y)
  {
    for (int x = 0; x < s.width; ++x)
    {
      double top[3];
      PixelRayAtZ(s, x, y, dir, 24.0, top);
      // Entries whose refracted ray meets the side face x = 32 above z = 8.
      if (top[0] < 23 || top[0] > 31.5 || top[1] < 4 || top[1] > 60)
        continue;
      const double zSide = 24 - (32 - top[0]) / std::tan(thetaT);
      const double xBottom = 32 - (zSide - 8) * std::tan(thetaT);
      const double floorX = xBottom - 7 * std::tan(theta);
      if (floorX < 1)
        continue;
      const std::size_t i = std::size_t(y) * s.width + x;
      const int seen = static_cast<int>(std::lround(image.rgba[4 * i] * 255.0 / 4.0));
      ++checked;
      near += std::abs(seen - static_cast<int>(std::floor(floorX))) <= 1;
      EXPECT_LT(seen, 32) << "pixel " << x << "," << y << ": the ray escaped through the side face";
    }
  }
  ASSERT_GT(checked, 20);
  EXPECT_EQ(near, checked);
}

TEST_P(Refraction, IndexOneIsInvisibleGlass)
{
  // Index 1.0 bends nothing: the floor is seen where the straight ray lands.
  Scene scene;
  scene.Floor();
  for (int x = 0; x < 64; ++x)
    for (int y = 0; y < 64; ++y)
      for (int z = 20; z < 28; ++z)
        scene.Voxel(x, y, z, 255, 255, 1.0f);
  engine->Build(scene.View(), Grid64());
  const double theta = 30.0 * M_PI / 180;
  const double dir[3] = { std::sin(theta), 0, -std::cos(theta) };
  RenderSettings s = ParallelView(dir, 32, 32, 8);
  Image image;
  engine->Render(s, image);
  int checked = 0, near = 0;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x)
    {
      double floorTop[3];
      PixelRayAtZ(s, x, y, dir, 1.0, floorTop);
      if (floorTop[0] < 1 || floorTop[0] > 63 || floorTop[1] < 1 || floorTop[1] > 63)
        continue;
      const std::size_t i = std::size_t(y) * s.width + x;
      const int seen = static_cast<int>(std::lround(image.rgba[4 * i] * 255.0 / 4.0));
      ++checked;
      near += std::abs(seen - static_cast<int>(std::floor(floorTop[0]))) <= 1;
    }
  ASSERT_GT(checked, 200);
  EXPECT_EQ(near, checked);
}

INSTANTIATE_TEST_SUITE_P(Backends, Refraction, ::testing::Values(Backend::CPU, Backend::CUDA), BackendName);
