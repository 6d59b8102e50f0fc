// Analytic scenes and extremes: pictures whose every pixel follows from
// geometry (a voxel's projected square, a checkerboard's cells, the
// reflection law, a mirror image, a shadow outline, a ray marcher over the
// same leaves), and corners of the viewport (a near plane inside a voxel,
// 1x1 and 8192x8192); the numerical extremes of the report's stability
// table (rays along faces, cameras inside and far away, depth 21, ...) are
// in TestStability.cpp.
// Every scene is laid out on the unit cube's grid (UnitCubeOptions), so a
// point at a voxel centre is that voxel, and every image is checked for
// NaN and infinity (RenderChecked). Each test runs on both backends.
#include "TestRenderSupport.h"

#include <octoray/RenderModes.h>

#include <random>
#include <set>

using namespace octoray;
using namespace octoray::test;

namespace
{
using SceneTest = BackendTest;

// A solid ball of voxel-centre points at `level` (optionally with radial
// normals), centred on the unit cube's centre, which is a grid point, so
// the set of cells is symmetric under every permutation of the axes.
Scene Ball(int level, double radius, bool normals)
{
  Scene s;
  s.withNormals = normals;
  const int cells = 1 << level;
  const float white[3] = { 0.8f, 0.8f, 0.8f };
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j)
      for (int k = 0; k < cells; ++k)
      {
        const double p[3] = { (i + 0.5) / cells - 0.5, (j + 0.5) / cells - 0.5, (k + 0.5) / cells - 0.5 };
        if (Length(p) <= radius)
        {
          const float n[3] = { float(p[0]), float(p[1]), float(p[2]) };
          s.AddCell(level, i, j, k, white, n);
        }
      }
  return s;
}

// Where the specular highlight of the lit ball lies in the image: the
// centroid of the pixels at the image's maximum brightness (a plateau of
// pixels shares one voxel's normal, so one pixel alone would be arbitrary).
void BrightestCentroid(const Image& image, double& cx, double& cy, int& count)
{
  float best = -1;
  for (std::size_t i = 0; i < image.depth.size(); ++i)
    if (image.rgba[4 * i + 3] > 0)
      best = std::max(best, image.rgba[4 * i]);
  cx = cy = 0;
  count = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
    {
      const std::size_t i = Pixel(image, x, y);
      if (image.rgba[4 * i + 3] > 0 && image.rgba[4 * i] >= best - 1e-6f)
      {
        cx += x + 0.5, cy += y + 0.5, ++count;
      }
    }
  cx /= count, cy /= count;
}
}

// ---------------------------------------------------------------- analytic scenes

TEST_P(SceneTest, OneVoxelCoversItsProjectedSquare)
{
  Scene s;
  const float colour[3] = { 0.9f, 0.3f, 0.1f };
  s.AddCell(3, 5, 2, 3, colour);
  engine->Build(s.View(), UnitCubeOptions(3));
  HostOctree t;
  engine->CopyToHost(t);
  const double lo[3] = { 5 / 8.0, 2 / 8.0, 3 / 8.0 }, hi[3] = { 6 / 8.0, 3 / 8.0, 4 / 8.0 };

  // Perspective, oblique: per pixel against the box in double. Pixels
  // within 1e-5 (a few float ulps of the unit cube) of the outline are
  // the only ones left unchecked.
  {
    const int w = 80, h = 60;
    const double eye[3] = { 2.2, -1.5, 1.8 }, target[3] = { 11 / 16.0, 5 / 16.0, 7 / 16.0 };
    const Matrix vp = ViewProjection(eye, target, kZUp, 25, double(w) / h, 0.5, 10);
    const Image image = RenderChecked(*engine, Settings(vp, w, h));
    int inside = 0, band = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
      {
        const WorldRay r = PixelRay(vp, w, h, x, y);
        const int expected = BoxHitWithMargin(r, lo, hi, 1e-5);
        const std::size_t i = Pixel(image, x, y);
        if (expected < 0)
        {
          ++band;
          continue;
        }
        ASSERT_EQ(image.rgba[4 * i + 3] > 0, expected == 1) << "pixel " << x << "," << y;
        if (expected == 1)
        {
          ++inside;
          EXPECT_TRUE(SameRgb(&image.rgba[4 * i], colour)) << "pixel " << x << "," << y;
          EXPECT_NEAR(image.depth[i], BruteForceFirstHit(t, vp, w, h, x, y).depth, 1e-5);
        }
      }
    EXPECT_GT(inside, 40);
    EXPECT_LT(band, inside);
  }

  // Parallel, looking down -z over the whole cube at 64x64: pixel (x, y)
  // has its centre at ((x + 0.5) / 64, (y + 0.5) / 64), so the square
  // [5/8, 6/8) x [2/8, 3/8) is exactly the pixels x in [40, 48), y in [16, 24).
  {
    const int w = 64, h = 64;
    const double eye[3] = { 0.5, 0.5, 3 }, target[3] = { 0.5, 0.5, 0 };
    const Matrix vp = ViewProjection(eye, target, kYUp, 0, 1.0, 1, 5, true, 0.5);
    const Image image = RenderChecked(*engine, Settings(vp, w, h));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
      {
        const bool expected = x >= 40 && x < 48 && y >= 16 && y < 24;
        const std::size_t i = Pixel(image, x, y);
        ASSERT_EQ(image.rgba[4 * i + 3] > 0, expected) << "pixel " << x << "," << y;
        if (expected)
        {
          EXPECT_TRUE(SameRgb(&image.rgba[4 * i], colour));
          // The top face z = 1/2 lies at eye distance 2.5 of the range [1, 5].
          EXPECT_NEAR(image.depth[i], (2.5 - 1) / 4, 1e-6);
        }
      }
  }
}

TEST_P(SceneTest, CheckerboardCellsAreColouredPerPixel)
{
  Scene s;
  const float red[3] = { 1, 0, 0 }, blue[3] = { 0, 0, 1 };
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j)
      s.AddCell(4, i, j, 0, (i + j) % 2 ? red : blue);
  engine->Build(s.View(), UnitCubeOptions(4));
  HostOctree t;
  engine->CopyToHost(t);
  const int w = 96, h = 72;
  const double eye[3] = { 1.4, -0.6, 0.9 }, target[3] = { 0.5, 0.5, 0 };
  const Matrix vp = ViewProjection(eye, target, kZUp, 50, double(w) / h, 0.1, 10);
  const Image image = RenderChecked(*engine, Settings(vp, w, h));
  int checked = 0, skipped = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const BruteHit b = BruteForceFirstHit(t, vp, w, h, x, y);
      const std::size_t i = Pixel(image, x, y);
      ASSERT_EQ(image.rgba[4 * i + 3] > 0, b.hit) << "pixel " << x << "," << y;
      if (!b.hit || std::fabs(b.p[2] - 1 / 16.0) > 1e-9)
        continue; // background, or a side face of the plate's rim
      // The cell under the hit point, from geometry (not from the octree);
      // hit points within 1e-5 of a cell border are the band left unchecked.
      const double gx = b.p[0] * 16, gy = b.p[1] * 16;
      if (std::fabs(gx - std::round(gx)) < 1e-4 || std::fabs(gy - std::round(gy)) < 1e-4)
      {
        ++skipped;
        continue;
      }
      const int ci = int(std::floor(gx)), cj = int(std::floor(gy));
      EXPECT_TRUE(SameRgb(&image.rgba[4 * i], (ci + cj) % 2 ? red : blue))
        << "pixel " << x << "," << y << " cell " << ci << "," << cj;
      ++checked;
    }
  EXPECT_GT(checked, 1000);
  EXPECT_LT(skipped, checked / 20);
}

// A solid ball (radius 0.35, depth 6, voxel 1/64) under one directional
// light, Phong with diffuse 0 so that brightness is ambient + specular
// alone: its maximum is where the normal is the half-vector H between the
// light and the (parallel) view direction. H is chosen as (1,1,1)/sqrt 3,
// a direction the occupancy gradient can represent exactly.
struct HighlightSetup
{
  static constexpr int kSize = 128; // 128 pixels over the unit cube: a voxel is 2 pixels
  Matrix vp;
  RenderSettings settings;
  double expected[2]; // pixel where c + (R - voxel/2) H projects
};

HighlightSetup MakeHighlight()
{
  HighlightSetup h;
  double v[3] = { 0.3, -0.2, 1.0 };
  Normalize3(v);
  double hv[3] = { 1, 1, 1 };
  Normalize3(hv);
  const double vh = v[0] * hv[0] + v[1] * hv[1] + v[2] * hv[2];
  // The reflection law: L is V mirrored about H.
  const double l[3] = { 2 * vh * hv[0] - v[0], 2 * vh * hv[1] - v[1], 2 * vh * hv[2] - v[2] };
  const double c[3] = { 0.5, 0.5, 0.5 };
  const double eye[3] = { c[0] + 3 * v[0], c[1] + 3 * v[1], c[2] + 3 * v[2] };
  h.vp = ViewProjection(eye, c, kZUp, 0, 1.0, 1, 5, true, 0.5);
  h.settings = Settings(h.vp, HighlightSetup::kSize, HighlightSetup::kSize);
  h.settings.shade = ShadeMode::Phong;
  h.settings.ambient = 0.1f;
  h.settings.diffuse = 0.0f;
  h.settings.specular = 1.0f;
  h.settings.specularPower = 30.0f;
  Light sun;
  for (int a = 0; a < 3; ++a)
    sun.position[a] = l[a];
  sun.position[3] = 0;
  h.settings.lights.push_back(sun);
  const double r = 0.35 - 0.5 / 64;
  const double p[3] = { c[0] + r * hv[0], c[1] + r * hv[1], c[2] + r * hv[2] };
  ProjectToPixel(h.vp, HighlightSetup::kSize, HighlightSetup::kSize, p, h.expected[0], h.expected[1]);
  return h;
}

TEST_P(SceneTest, PhongHighlightFollowsTheReflectionLawWithPointNormals)
{
  engine->Build(Ball(6, 0.35, true).View(), UnitCubeOptions(6));
  const HighlightSetup h = MakeHighlight();
  const Image image = RenderChecked(*engine, h.settings);
  double cx, cy;
  int count;
  BrightestCentroid(image, cx, cy, count);
  // Tolerance 2 voxels (4 pixels): the voxel whose centre direction is
  // nearest H is at most sqrt(3)/2 voxel from c + R H along the surface,
  // its visible face lies up to a voxel deeper along H, and the plateau's
  // centroid lies within that voxel's footprint.
  const double tol = 4.0;
  EXPECT_NEAR(cx, h.expected[0], tol) << count << " brightest pixels";
  EXPECT_NEAR(cy, h.expected[1], tol) << count << " brightest pixels";
  EXPECT_LE(count, 16) << "the highlight should be one voxel or so, not a plateau";
}

TEST_P(SceneTest, PhongHighlightFollowsTheReflectionLawWithGradientNormals)
{
  engine->Build(Ball(6, 0.35, false).View(), UnitCubeOptions(6));
  const HighlightSetup h = MakeHighlight();
  const Image image = RenderChecked(*engine, h.settings);
  double cx, cy;
  int count;
  BrightestCentroid(image, cx, cy, count);
  // The gradient of six neighbours takes 26 directions; the brightest
  // plateau is the patch of surface voxels whose gradient is exactly H =
  // (1,1,1)/sqrt 3. That patch is symmetric under cyclic permutation of the
  // axes (the ball is centred on a grid point), so its centroid lies on
  // the axis c + s H; what the image sees of it is weighted by visible face
  // areas, which shifts it by up to the patch's half-width (about 3 voxels
  // for this radius) plus a voxel of depth: tolerance 4 voxels, 8 pixels.
  const double tol = 8.0;
  EXPECT_NEAR(cx, h.expected[0], tol) << count << " brightest pixels";
  EXPECT_NEAR(cy, h.expected[1], tol) << count << " brightest pixels";
  EXPECT_GT(count, 4) << "a gradient-normal highlight is a plateau of equal normals";
}

TEST_P(SceneTest, MirrorPlaneShowsTheVoxelsMirrorImage)
{
  // A 32x32 floor of cells at z-level 0 (top face z = 1/32), reflectivity 1
  // and normals +z; a red non-reflecting 3x3x3 block of voxels above it
  // (big enough, about 9 pixels, to have an inside beyond the band).
  Scene s;
  s.withNormals = s.withReflectivity = true;
  const float grey[3] = { 0.5f, 0.5f, 0.5f }, red[3] = { 1, 0, 0 }, up[3] = { 0, 0, 1 };
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j)
      s.AddCell(5, i, j, 0, grey, up, 1.0f);
  for (int i = 15; i < 18; ++i)
    for (int j = 15; j < 18; ++j)
      for (int k = 8; k < 11; ++k)
        s.AddCell(5, i, j, k, red, up, 0.0f);
  engine->Build(s.View(), UnitCubeOptions(5));
  HostOctree t;
  engine->CopyToHost(t);
  const int w = 96, h = 96;
  const double eye[3] = { 0.5, -0.6, 0.7 }, target[3] = { 0.5, 0.5, 0.1 };
  const double fovy = 40;
  const Matrix vp = ViewProjection(eye, target, kZUp, fovy, 1.0, 0.1, 5);
  RenderSettings settings = Settings(vp, w, h);
  settings.maxBounces = 2;
  const Image image = RenderChecked(*engine, settings);

  // The mirror image of the block [15/32, 18/32)^2 x [8/32, 11/32) about
  // the plane z = 1/32.
  const double z0 = 1 / 32.0;
  const double lo[3] = { 15 / 32.0, 15 / 32.0, 2 * z0 - 11 / 32.0 }, hi[3] = { 18 / 32.0, 18 / 32.0, 2 * z0 - 8 / 32.0 };
  const double centre[3] = { 16.5 / 32, 16.5 / 32, 2 * z0 - 9.5 / 32 };
  const double toImage[3] = { centre[0] - eye[0], centre[1] - eye[1], centre[2] - eye[2] };
  // 1.5 pixels at the mirror image's distance: the band left unchecked.
  const double margin = 1.5 * Length(toImage) * 2 * std::tan(fovy * M_PI / 360) / h;
  int inside = 0, outside = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const BruteHit b = BruteForceFirstHit(t, vp, w, h, x, y);
      if (!b.hit || std::fabs(b.p[2] - z0) > 1e-9)
        continue; // not the floor's top face
      // Past the mirror, the reflected ray is the primary ray continued
      // into the mirrored world.
      const WorldRay r = PixelRay(vp, w, h, x, y);
      const int expected = BoxHitWithMargin(r, lo, hi, margin, b.t, 1e9);
      const float* pixel = &image.rgba[4 * Pixel(image, x, y)];
      if (expected == 1)
      {
        ++inside;
        EXPECT_TRUE(SameRgb(pixel, red)) << "pixel " << x << "," << y << " should show the mirror image";
      }
      else if (expected == 0)
      {
        ++outside;
        const float black[3] = { 0, 0, 0 };
        EXPECT_TRUE(SameRgb(pixel, black)) << "pixel " << x << "," << y << " reflects the empty sky";
      }
    }
  EXPECT_GT(inside, 10);
  EXPECT_GT(outside, 1000);
}

namespace
{
// FloorAndBlock's scene with a green block, lit by the sun from `toSun`,
// seen from above.
struct SunlitFloorAndBlock
{
  static constexpr double kBlockLo[3] = { 12 / 32.0, 12 / 32.0, 6 / 32.0 };
  static constexpr double kBlockHi[3] = { 16 / 32.0, 16 / 32.0, 8 / 32.0 };
  static constexpr int kSize = 128;
  static constexpr double kFovy = 45;
  double toSun[3] = { 0.6, 0.3, 1.0 };
  Matrix vp;

  SunlitFloorAndBlock()
  {
    Normalize3(toSun);
    const double eye[3] = { 0.5, -0.5, 1.2 }, target[3] = { 0.5, 0.5, 0 };
    vp = ViewProjection(eye, target, kZUp, kFovy, 1.0, 0.1, 5);
  }

  // The scene built at depth 5 on the unit cube, as the host sees it.
  static HostOctree BuildOn(Engine& engine)
  {
    const float green[3] = { 0.2f, 0.8f, 0.2f };
    engine.Build(FloorAndBlock(green).View(), UnitCubeOptions(5));
    HostOctree t;
    engine.CopyToHost(t);
    return t;
  }

  RenderSettings Sunlit() const
  {
    RenderSettings settings = Settings(vp, kSize, kSize);
    settings.shade = ShadeMode::Phong;
    settings.ambient = 0.2f;
    settings.diffuse = 0.7f;
    settings.specular = 0.0f; // lit floor = (ambient + diffuse n.l) grey, exactly
    settings.shadows = true;
    Light sun;
    std::copy(toSun, toSun + 3, sun.position);
    sun.position[3] = 0;
    settings.lights.push_back(sun);
    return settings;
  }

  // The lit floor: its normal is +z (its occupancy gradient vanishes inside
  // the floor, so the entry face gives it), so n.l = toSun.z.
  float LitFloor() const { return float((0.2 + 0.7 * toSun[2]) * 0.6); }

  // Whether the first hit b is on the floor's top face, away from the rim
  // (whose gradient normal tilts outwards).
  static bool OnFloorInside(const BruteHit& b)
  {
    if (!b.hit || std::fabs(b.p[2] - 1 / 32.0) > 1e-9)
      return false;
    const int ci = int(b.p[0] * 32), cj = int(b.p[1] * 32);
    return ci > 0 && ci < 31 && cj > 0 && cj < 31;
  }
};
}

TEST_P(SceneTest, BlockCastsItsShadowOnTheFloor)
{
  const SunlitFloorAndBlock scene;
  const HostOctree t = scene.BuildOn(*engine);
  const int w = SunlitFloorAndBlock::kSize, h = SunlitFloorAndBlock::kSize;
  const Matrix& vp = scene.vp;
  const double* l = scene.toSun;
  const Image image = RenderChecked(*engine, scene.Sunlit());

  const float shadowed[3] = { 0.2f * 0.6f, 0.2f * 0.6f, 0.2f * 0.6f };
  const float lit[3] = { scene.LitFloor(), scene.LitFloor(), scene.LitFloor() };
  int inShadow = 0, inLight = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const BruteHit b = BruteForceFirstHit(t, vp, w, h, x, y);
      if (!SunlitFloorAndBlock::OnFloorInside(b))
        continue;
      // The shadow from geometry: does the ray from the hit point towards
      // the light meet the block? The band left unchecked is 1 pixel's
      // footprint on the floor (the pixel's size at that distance over the
      // cosine of the view ray with the floor), on either side.
      const WorldRay r = PixelRay(vp, w, h, x, y);
      const double dist = b.t * Length(r.d) + 0.1;
      const double footprint =
        dist * 2 * std::tan(SunlitFloorAndBlock::kFovy * M_PI / 360) / h / (std::fabs(r.d[2]) / Length(r.d));
      WorldRay toLight;
      for (int a = 0; a < 3; ++a)
        toLight.o[a] = b.p[a], toLight.d[a] = l[a];
      const int blocked =
        BoxHitWithMargin(toLight, SunlitFloorAndBlock::kBlockLo, SunlitFloorAndBlock::kBlockHi, footprint, 0, 1e9);
      const float* pixel = &image.rgba[4 * Pixel(image, x, y)];
      if (blocked == 1)
      {
        ++inShadow;
        EXPECT_TRUE(SameRgb(pixel, shadowed)) << "pixel " << x << "," << y << " should be in shadow: " << pixel[0];
      }
      else if (blocked == 0)
      {
        ++inLight;
        EXPECT_TRUE(SameRgb(pixel, lit, 1e-5f)) << "pixel " << x << "," << y << " should be lit: " << pixel[0];
      }
    }
  EXPECT_GT(inShadow, 50);
  EXPECT_GT(inLight, 1000);
}

// A clipping plane that takes the block away takes its shadow too: no ray
// sees the block, and the whole floor is lit.
TEST_P(SceneTest, ClippedBlockCastsNoShadow)
{
  const SunlitFloorAndBlock scene;
  const HostOctree t = scene.BuildOn(*engine);
  const int w = SunlitFloorAndBlock::kSize, h = SunlitFloorAndBlock::kSize;
  RenderSettings settings = scene.Sunlit();
  ClipPlane below;
  below.origin[2] = 5 / 32.0; // under the block, over the floor
  below.normal[2] = -1;
  settings.clipPlanes = { below };
  const Image image = RenderChecked(*engine, settings);
  const float lit[3] = { scene.LitFloor(), scene.LitFloor(), scene.LitFloor() };
  int floor = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const BruteHit b = BruteForceFirstHit(t, scene.vp, w, h, x, y, settings.clipPlanes);
      const float* pixel = &image.rgba[4 * Pixel(image, x, y)];
      ASSERT_EQ(pixel[3] > 0, b.hit) << "pixel " << x << "," << y;
      if (SunlitFloorAndBlock::OnFloorInside(b))
      {
        ++floor;
        EXPECT_TRUE(SameRgb(pixel, lit, 1e-5f)) << "pixel " << x << "," << y << " should be lit: " << pixel[0];
      }
    }
  EXPECT_GT(floor, 5000);
}

namespace
{
// A solid grey block of depth-5 cells (8..23 on each axis), cut through
// its centre by a clipping plane that faces the camera, under a sun, with
// shadows on. With `noisyNormals` each point has a pseudo-random unit
// normal, as a CT's gradient inside bone. Counts the pixels that see the
// cut (the brute-force first hit at the start of the kept span), the block
// rim's included, and those whose colour is not ambient + diffuse n.l of
// the grey by the plane's normal (within 1e-5).
void CountCutPixelsOffThePlanesLight(Engine& engine, bool noisyNormals, int& cutPixels, int& off)
{
  Scene s;
  s.withNormals = noisyNormals;
  std::mt19937_64 rng(49);
  std::normal_distribution<float> gauss;
  const float grey[3] = { 0.6f, 0.6f, 0.6f };
  for (int i = 8; i < 24; ++i)
    for (int j = 8; j < 24; ++j)
      for (int k = 8; k < 24; ++k)
      {
        const float n[3] = { gauss(rng), gauss(rng), gauss(rng) };
        s.AddCell(5, i, j, k, grey, n);
      }
  engine.Build(s.View(), UnitCubeOptions(5));
  HostOctree t;
  engine.CopyToHost(t);
  double kept[3] = { -0.6, 0.5, -0.62 }, toSun[3] = { 0.8, -0.4, 0.62 };
  Normalize3(kept);
  Normalize3(toSun);
  ClipPlane cut;
  cut.origin[0] = cut.origin[1] = cut.origin[2] = 0.5;
  std::copy(kept, kept + 3, cut.normal);
  const double target[3] = { 0.5, 0.5, 0.5 };
  const double eye[3] = { 0.5 - 2 * kept[0], 0.5 - 2 * kept[1] + 0.3, 0.5 - 2 * kept[2] };
  const int w = 96, h = 96;
  const Matrix vp = ViewProjection(eye, target, kZUp, 40, 1.0, 0.1, 5);
  RenderSettings settings = Settings(vp, w, h);
  settings.clipPlanes = { cut };
  settings.shade = ShadeMode::Phong;
  settings.ambient = 0.2f;
  settings.diffuse = 0.7f;
  settings.specular = 0.0f;
  settings.shadows = true;
  Light sun;
  std::copy(toSun, toSun + 3, sun.position);
  sun.position[3] = 0;
  settings.lights.push_back(sun);
  const Image image = RenderChecked(engine, settings);
  // The cut faces the viewer: its normal is -kept.
  const double nl = -(kept[0] * toSun[0] + kept[1] * toSun[1] + kept[2] * toSun[2]);
  ASSERT_GT(nl, 0.2);
  const float litValue = float((0.2 + 0.7 * nl) * 0.6);
  const float lit[3] = { litValue, litValue, litValue };
  cutPixels = off = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const WorldRay r = PixelRay(vp, w, h, x, y);
      double kept0 = 0, kept1 = 1;
      const BruteHit b = BruteForceFirstHit(t, vp, w, h, x, y, settings.clipPlanes);
      if (!b.hit || !KeptSpan(r, settings.clipPlanes, kept0, kept1) || b.t != kept0)
        continue; // not on the cut
      ++cutPixels;
      off += SameRgb(&image.rgba[4 * Pixel(image, x, y)], lit, 1e-5f) ? 0 : 1;
    }
}
}

// Where a clipping plane cuts a solid block, the cut is a flat face lit by
// the plane's normal: every pixel that sees the cut has ambient + diffuse
// n.l of the grey, with shadows on (the part of the block the plane takes
// away casts none). That holds at the block's rim, where the occupancy
// gradient tilts outwards, and where the points' own normals point every
// way (a CT's gradient inside bone), which lit the cut before.
TEST_P(SceneTest, CutFaceIsLitByTheClippingPlane)
{
  for (const bool noisyNormals : { false, true })
  {
    int cutPixels = 0, off = 0;
    CountCutPixelsOffThePlanesLight(*engine, noisyNormals, cutPixels, off);
    std::printf("%s: %d of %d pixels on the cut not lit by the plane\n",
      noisyNormals ? "random point normals" : "no normals", off, cutPixels);
    EXPECT_GT(cutPixels, 1000);
    EXPECT_EQ(off, 0) << (noisyNormals ? "random point normals" : "no normals");
  }
}

// ---------------------------------------------------------------- volume blend modes

namespace
{
// Brute-force ray marcher: every leaf the pixel's ray passes, in double,
// ordered by entry, each within the part of the ray the clipping planes
// keep; distances in the unit cube (the scenes use the unit cube, so world
// and unit lengths agree). `ambiguous` when some leaf is only grazed (a
// contact shorter than 1e-5), where the two may differ.
struct Segment
{
  double t0, length;
  std::uint32_t node;
};

std::vector<Segment> MarchLeaves(
  const HostOctree& t, const WorldRay& r, const std::vector<ClipPlane>& planes, bool& ambiguous)
{
  std::vector<Segment> segments;
  ambiguous = false;
  const double scale = Length(r.d);
  double kept0 = 0, kept1 = 1;
  if (!KeptSpan(r, planes, kept0, kept1))
    return segments;
  for (std::uint32_t n = t.levelBegin[t.depth]; n < t.levelBegin[t.depth + 1]; ++n)
  {
    double lo[3], hi[3], t0 = kept0, t1 = kept1;
    NodeBox(t, n, t.depth, lo, hi);
    // Grown by 1e-5: a contact with the grown box but not a solid one with
    // the box itself is a graze.
    double gl[3], gh[3], g0 = kept0 - 1e-5 / scale, g1 = kept1 + 1e-5 / scale;
    for (int a = 0; a < 3; ++a)
      gl[a] = lo[a] - 1e-5, gh[a] = hi[a] + 1e-5;
    const bool near = Slab(r, gl, gh, g0, g1);
    const bool solid = Slab(r, lo, hi, t0, t1) && (t1 - t0) * scale > 1e-5;
    if (near && !solid)
      ambiguous = true;
    if (solid)
      segments.push_back(Segment{ t0 * scale, (t1 - t0) * scale, n });
  }
  std::sort(segments.begin(), segments.end(), [](const Segment& a, const Segment& b) { return a.t0 < b.t0; });
  return segments;
}

int TableIndex(double value, const TransferFunction& tf)
{
  double u = (value - tf.range[0]) / (tf.range[1] - tf.range[0]);
  u = std::min(1.0, std::max(0.0, u));
  return int(u * (tf.table.size() - 1) + 0.5);
}
}

TEST_P(SceneTest, VolumeBlendModesMatchABruteForceRayMarcher)
{
  // 300 points uniform in the unit cube with scalars in [0, 1], depth 4.
  Scene s;
  s.withScalar = true;
  std::mt19937_64 rng(47);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const float white[3] = { 1, 1, 1 };
  for (int i = 0; i < 300; ++i)
  {
    const double x = u(rng), y = u(rng), z = u(rng);
    s.Add(x, y, z, white, nullptr, 0.0f, float(u(rng)));
  }
  engine->Build(s.View(), UnitCubeOptions(4));
  HostOctree t;
  engine->CopyToHost(t);
  const int w = 40, h = 40;
  const double eye[3] = { 2.2, -1.6, 1.5 }, target[3] = { 0.5, 0.5, 0.5 };
  const Matrix vp = ViewProjection(eye, target, kZUp, 40, 1.0, 0.5, 8);

  // Clipped, rays start and end inside voxels: one plane the rays enter
  // through, one they leave through.
  ClipPlane enter, leave;
  enter.origin[0] = 0.7, enter.origin[1] = 0.3, enter.origin[2] = 0.6;
  enter.normal[0] = -1, enter.normal[1] = 1, enter.normal[2] = -0.5;
  leave.origin[0] = 0.6, leave.origin[1] = 0.6, leave.origin[2] = 0.5;
  leave.normal[0] = 0.3, leave.normal[1] = -1, leave.normal[2] = 0.8;
  for (const std::vector<ClipPlane>& planes : { std::vector<ClipPlane>(), std::vector<ClipPlane>{ enter, leave } })
  {
    for (BlendMode mode : { BlendMode::Composite, BlendMode::Minimum, BlendMode::Average, BlendMode::Additive })
    {
      SCOPED_TRACE("blend mode " + std::to_string(int(mode)) + ", clipping planes " + std::to_string(planes.size()));
      RenderSettings settings = Settings(vp, w, h);
      settings.clipPlanes = planes;
      settings.blend = mode;
      settings.transfer.range[0] = 0;
      settings.transfer.range[1] = mode == BlendMode::Additive ? 0.5f : 1.0f;
      for (int i = 0; i <= 100; ++i)
      {
        const float v = i / 100.0f;
        settings.transfer.table.push_back(
          mode == BlendMode::Composite ? Rgba{ v, 1 - v, 0.5f, 0.3f } : Rgba{ v, v, v, 1.0f });
      }
      // Opacity 0.3 per 0.1 of length: about 0.2 per voxel of 1/16, so that
      // rays composite several voxels before they saturate.
      settings.opacityUnitDistance = 0.1f;
      const Image image = RenderChecked(*engine, settings);
      const TransferFunction& tf = settings.transfer;
      int checked = 0, skipped = 0, empty = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
        {
          bool ambiguous;
          const std::vector<Segment> seg = MarchLeaves(t, PixelRay(vp, w, h, x, y), planes, ambiguous);
          const float* pixel = &image.rgba[4 * Pixel(image, x, y)];
          if (ambiguous)
          {
            ++skipped;
            continue;
          }
          if (seg.empty())
          {
            ++empty;
            EXPECT_EQ(pixel[3], 0.0f) << "pixel " << x << "," << y << " meets no voxel";
            continue;
          }
          ++checked;
          if (mode == BlendMode::Composite)
          {
            // Front to back, opacity corrected for each voxel's length, with
            // the engine's documented early termination at alpha 0.995.
            double acc[4] = { 0, 0, 0, 0 };
            for (const Segment& sg : seg)
            {
              const Rgba c = tf.table[TableIndex(t.Scalar(sg.node), tf)];
              const double alpha = 1 - std::pow(1 - c.a, sg.length / settings.opacityUnitDistance);
              const double wgt = (1 - acc[3]) * alpha;
              acc[0] += wgt * c.r, acc[1] += wgt * c.g, acc[2] += wgt * c.b, acc[3] += wgt;
              if (acc[3] > 0.995)
                break;
            }
            for (int k = 0; k < 4; ++k)
              EXPECT_NEAR(pixel[k], acc[k], 1e-4) << "pixel " << x << "," << y << " channel " << k;
            continue;
          }
          double value = mode == BlendMode::Minimum ? INFINITY : 0.0, length = 0;
          for (const Segment& sg : seg)
          {
            if (mode == BlendMode::Minimum)
              value = std::min(value, double(t.Scalar(sg.node)));
            else
              value += t.Scalar(sg.node) * sg.length, length += sg.length;
          }
          if (mode == BlendMode::Average)
            value /= length;
          // One table step of slack: a value on a bin boundary may round
          // either way in float.
          const float expected = tf.table[TableIndex(value, tf)].r;
          EXPECT_NEAR(pixel[0], expected, 0.0101f) << "pixel " << x << "," << y << " value " << value;
          EXPECT_EQ(pixel[3], 1.0f);
        }
      EXPECT_GT(checked, planes.empty() ? 300 : 200);
      EXPECT_GT(empty, 50);
      EXPECT_LT(skipped, checked / 10);
    }
  }
}

// ---------------------------------------------------------------- level of detail

// Parallel projection makes a pixel's footprint the same everywhere (1/128
// of the unit cube here), so the level where the traversal stops is the same
// for every ray: the first level L whose voxel 2^-L is below k pixels. The
// picture must then be that of an octree built at depth L from the same
// points. Thresholds sit between powers of two, away from the boundary.
TEST_P(SceneTest, LevelOfDetailDrawsTheCoarserOctree)
{
  std::mt19937_64 rng(48);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Scene s;
  for (int i = 0; i < 20000; ++i)
  {
    double p[3] = { u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5 };
    if (Length(p) > 0.45)
      continue;
    const float c[3] = { float(u(rng)), float(u(rng)), float(u(rng)) };
    s.Add(p[0] + 0.5, p[1] + 0.5, p[2] + 0.5, c);
  }
  const int w = 128, h = 128, depth = 7;
  engine->Build(s.View(), UnitCubeOptions(depth));
  auto coarse = CreateEngine(GetParam());
  const double eye[3] = { 2.5, -1.9, 1.4 }, target[3] = { 0.5, 0.5, 0.5 };
  const Matrix vp = ViewProjection(eye, target, kZUp, 0, 1.0, 1, 8, true, 0.5);

  for (ShadeMode shade : { ShadeMode::Flat, ShadeMode::Phong })
  {
    RenderSettings settings = Settings(vp, w, h);
    settings.shade = shade;
    const Image full = RenderChecked(*engine, settings);
    // k = 0.5: a voxel of 1/128 is never below half a pixel (1/256): the
    // leaves are drawn, bit for bit the k = 0 picture.
    settings.lodPixels = 0.5f;
    EXPECT_TRUE(BitIdentical(RenderChecked(*engine, settings), full)) << "k = 0.5 differs from k = 0";

    const std::pair<float, int> cases[] = { { 3.0f, 6 }, { 6.0f, 5 }, { 12.0f, 4 }, { 48.0f, 2 } };
    for (const auto& [k, level] : cases)
    {
      SCOPED_TRACE("k = " + std::to_string(k) + " shade " + std::to_string(int(shade)));
      settings.lodPixels = k;
      const Image lod = RenderChecked(*engine, settings);
      coarse->Build(s.View(), UnitCubeOptions(level));
      settings.lodPixels = 0;
      const Image reference = RenderChecked(*coarse, settings);
      int differ = 0, hits = 0, colourDiffer = 0;
      for (std::size_t i = 0; i < lod.depth.size(); ++i)
      {
        hits += reference.rgba[4 * i + 3] > 0;
        differ += (lod.rgba[4 * i + 3] > 0) != (reference.rgba[4 * i + 3] > 0) || lod.depth[i] != reference.depth[i];
        // Node averages summed in another order round differently: 1e-5.
        colourDiffer += !SameRgb(&lod.rgba[4 * i], &reference.rgba[4 * i], 1e-5f);
      }
      EXPECT_GT(hits, 3000);
      EXPECT_EQ(differ, 0) << "pixels whose hit or depth differ from the depth-" << level << " octree";
      EXPECT_EQ(colourDiffer, 0);
      EXPECT_FALSE(BitIdentical(lod, full)) << "level of detail changed nothing";
    }
  }
}

// ---------------------------------------------------------------- extremes

TEST_P(SceneTest, NearPlaneInsideAVoxel)
{
  // Depth 2: voxel (1,1,1) is [1/4, 1/2)^3; the camera looks along +z from
  // z = -1/2 with the near plane at z = 3/8, through the voxel's middle.
  Scene s;
  const float c[3] = { 0.7f, 0.2f, 0.4f }, d[3] = { 0.1f, 0.9f, 0.1f };
  s.AddCell(2, 1, 1, 1, c);
  s.AddCell(2, 3, 3, 3, d);
  engine->Build(s.View(), UnitCubeOptions(2));
  HostOctree t;
  engine->CopyToHost(t);
  const int w = 32, h = 32;
  const double eye[3] = { 0.375, 0.375, -0.5 }, target[3] = { 0.375, 0.375, 1 };
  const Matrix vp = ViewProjection(eye, target, kYUp, 30, 1.0, 0.875, 5);
  const Image image = RenderChecked(*engine, Settings(vp, w, h));
  int atNear = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const BruteHit b = BruteForceFirstHit(t, vp, w, h, x, y);
      const std::size_t i = Pixel(image, x, y);
      ASSERT_EQ(image.rgba[4 * i + 3] > 0, b.hit) << "pixel " << x << "," << y;
      if (!b.hit)
        continue;
      EXPECT_TRUE(SameRgb(&image.rgba[4 * i], NodeColour(t, b.node)));
      EXPECT_NEAR(image.depth[i], b.depth, 1e-6);
      if (b.t == 0)
      {
        ++atNear;
        EXPECT_TRUE(SameRgb(&image.rgba[4 * i], c));
        EXPECT_NEAR(image.depth[i], 0.0f, 1e-6) << "a hit on the near plane has window depth 0";
      }
    }
  EXPECT_GT(atNear, 50);
}

TEST_P(SceneTest, OneByOneViewport)
{
  Scene s;
  const float c[3] = { 0.2f, 0.4f, 0.6f };
  s.AddCell(3, 4, 4, 4, c);
  engine->Build(s.View(), UnitCubeOptions(3));
  HostOctree t;
  engine->CopyToHost(t);
  const double eye[3] = { 2, -1.5, 1.7 };
  const double at[3] = { 9 / 16.0, 9 / 16.0, 9 / 16.0 }, away[3] = { 4, -4, 4 };
  for (const double* target : { at, away })
  {
    const Matrix vp = ViewProjection(eye, target, kZUp, 30, 1.0, 0.5, 10);
    const Image image = RenderChecked(*engine, Settings(vp, 1, 1));
    const BruteHit b = BruteForceFirstHit(t, vp, 1, 1, 0, 0);
    EXPECT_EQ(image.rgba[3] > 0, b.hit);
    EXPECT_EQ(b.hit, target == at);
    if (b.hit)
    {
      EXPECT_TRUE(SameRgb(image.rgba.data(), c));
      EXPECT_NEAR(image.depth[0], b.depth, 1e-6);
    }
  }
}

// 8192x8192 (1.25 GiB of colour and depth): the right size, and each 8x8
// block equals the 1024x1024 picture's pixel where the block is uniform.
// With a parallel view down -z the voxel's image is an axis-aligned square,
// so the 1024 pixel's centre, which lies among its block's 64 centres,
// shares their verdict; only blocks on the square's outline are mixed.
TEST_P(SceneTest, HugeViewportMatchesASmallerOne)
{
  Scene s;
  const float c[3] = { 0.9f, 0.9f, 0.1f };
  s.AddCell(3, 3, 4, 0, c);
  engine->Build(s.View(), UnitCubeOptions(3));
  const double eye[3] = { 0.45, 0.55, 3 }, target[3] = { 0.45, 0.55, 0 };
  const Matrix vp = ViewProjection(eye, target, kYUp, 0, 1.0, 1, 5, true, 0.5);
  const int big = 8192, small = 1024;
  Image large;
  try
  {
    large = RenderChecked(*engine, Settings(vp, big, big));
  }
  catch (const std::bad_alloc&)
  {
    GTEST_SKIP() << "not enough memory for an 8192x8192 image here";
  }
  const Image reference = RenderChecked(*engine, Settings(vp, small, small));
  int uniform = 0, mixed = 0, wrong = 0;
  for (int by = 0; by < small; ++by)
    for (int bx = 0; bx < small; ++bx)
    {
      const std::size_t first = Pixel(large, 8 * bx, 8 * by);
      bool same = true;
      for (int y = 0; y < 8 && same; ++y)
        for (int x = 0; x < 8 && same; ++x)
        {
          const std::size_t i = Pixel(large, 8 * bx + x, 8 * by + y);
          same = std::memcmp(&large.rgba[4 * i], &large.rgba[4 * first], 4 * sizeof(float)) == 0 &&
            large.depth[i] == large.depth[first];
        }
      if (!same)
      {
        ++mixed;
        continue;
      }
      ++uniform;
      const std::size_t r = Pixel(reference, bx, by);
      wrong += std::memcmp(&reference.rgba[4 * r], &large.rgba[4 * first], 4 * sizeof(float)) != 0 ||
        reference.depth[r] != large.depth[first];
    }
  EXPECT_EQ(wrong, 0);
  // The square is 128 pixels of 1024 wide: at most its outline is mixed.
  EXPECT_LE(mixed, 4 * 130);
  int covered = 0;
  for (std::size_t i = 0; i < reference.depth.size(); ++i)
    covered += reference.rgba[4 * i + 3] > 0;
  EXPECT_EQ(covered, 128 * 128);
}

TEST_P(SceneTest, RepeatedRendersAreBitIdenticalInEveryMode)
{
  Cloud c = GaussianClusters(3000, 51);
  BuildOptions options;
  options.depth = 7;
  engine->Build(c.View(), options);
  const int w = 64, h = 48;
  const double eye[3] = { 20, -25, 15 }, target[3] = { 2, 1, 1 };
  const Matrix vp = ViewProjection(eye, target, kZUp, 40, double(w) / h, 1, 100);
  for (const NamedRenderMode& m : kRenderModes)
  {
    SCOPED_TRACE(m.name);
    RenderSettings s = Settings(vp, w, h);
    m.ApplyTo(s);
    Light sun;
    sun.position[0] = 1, sun.position[1] = -1, sun.position[2] = 2, sun.position[3] = 0;
    s.lights.push_back(sun);
    s.transfer.range[0] = -50;
    s.transfer.range[1] = 50;
    for (int i = 0; i < 64; ++i)
      s.transfer.table.push_back(Rgba{ i / 63.0f, 0.5f, 1 - i / 63.0f, m.blend == BlendMode::Composite ? 0.05f : 1.0f });
    engine->SetThreadCount(0);
    const Image a = RenderChecked(*engine, s);
    const Image b = RenderChecked(*engine, s);
    EXPECT_TRUE(BitIdentical(a, b)) << "two renders differ";
    // One thread against all of them: rows are split differently.
    engine->SetThreadCount(1);
    EXPECT_TRUE(BitIdentical(a, RenderChecked(*engine, s))) << "one thread differs from many";
    engine->SetThreadCount(0);
    int covered = 0;
    for (std::size_t i = 0; i < a.depth.size(); ++i)
      covered += a.rgba[4 * i + 3] > 0;
    EXPECT_GT(covered, 100);
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, SceneTest, ::testing::Values(Backend::CPU, Backend::CUDA), BackendName);
