// Ray tracing against brute-force references that intersect every leaf box
// in double precision, on every backend.
#include "TestRenderSupport.h"

#include <octoray/DepthSignature.h>
#include <octoray/Frame.h>
#include <octoray/PacketTraversal.h>
#include <octoray/ReferenceTraversal.h>

#include <limits>
#include <string>
#include <utility>

using namespace octoray;
using namespace octoray::test;

namespace
{
using RenderTest = BackendTest;

const double kUp[3] = { 0, 0, 1 };
}

TEST_P(RenderTest, SurfaceMatchesBruteForceVoxelHits)
{
  const Cloud c = GaussianClusters(400, 41);
  HostOctree t = BuildOnHost(*engine, c.View(), 5);
  const int w = 64, h = 48;
  const double eye[3] = { 25, -30, 18 }, target[3] = { 2, 1, 1 };
  for (bool parallel : { false, true })
  {
    SCOPED_TRACE(parallel ? "parallel projection" : "perspective");
    const Matrix vp = ViewProjection(eye, target, kUp, 40, double(w) / h, 5, 120, parallel, 12);
    RenderSettings s = Settings(vp, w, h);
    s.maxBounces = 0; // the points reflect; here only the first hit counts
    Image image;
    engine->Render(s, image);
    int agree = 0, hits = 0;
    for (int y = 0; y < h; ++y)
    {
      for (int x = 0; x < w; ++x)
      {
        const BruteHit b = BruteForceFirstHit(t, vp, w, h, x, y);
        const std::size_t i = std::size_t(y) * w + x;
        ASSERT_EQ(image.rgba[4 * i + 3] > 0, b.hit) << "pixel " << x << "," << y;
        if (!b.hit)
        {
          EXPECT_EQ(image.depth[i], 1.0f);
          continue;
        }
        ++hits;
        const Rgba col = NodeColour(t, b.node);
        const bool same = std::fabs(image.rgba[4 * i] - col.r) < 1e-6 && std::fabs(image.rgba[4 * i + 1] - col.g) < 1e-6 &&
          std::fabs(image.rgba[4 * i + 2] - col.b) < 1e-6;
        agree += same;
        EXPECT_NEAR(image.depth[i], b.depth, 1e-5) << "pixel " << x << "," << y;
      }
    }
    EXPECT_GT(hits, 100);
    // Ties where a ray meets two voxels at the same face aside.
    EXPECT_GE(agree, hits * 99 / 100) << agree << " of " << hits;
  }
}

namespace
{
ClipPlane Plane(double ox, double oy, double oz, double nx, double ny, double nz)
{
  ClipPlane p;
  p.origin[0] = ox, p.origin[1] = oy, p.origin[2] = oz;
  p.normal[0] = nx, p.normal[1] = ny, p.normal[2] = nz;
  return p;
}

// Two oblique planes through the clusters (GaussianClusters) as the tests'
// cameras see them: one the rays enter through (it moves their start) and
// one they leave through (it moves their end).
std::vector<ClipPlane> TwoPlanes()
{
  return { Plane(0, 0, 0, -0.6, 0.8, -0.4), Plane(-5, 8, 1, 0.3, -0.2, 1) };
}
}

// The first voxel within what clipping planes keep, against every leaf box
// clipped in double. Rays that meet a voxel only in a sliver of the kept
// side (where float and double may disagree) allowed: 1 % of pixels.
TEST_P(RenderTest, ClippingPlanesMatchBruteForce)
{
  const Cloud c = GaussianClusters(2000, 41);
  HostOctree t = BuildOnHost(*engine, c.View(), 5);
  const int w = 80, h = 60;
  const double eye[3] = { 25, -30, 18 }, target[3] = { 2, 1, 1 };
  const Matrix vp = ViewProjection(eye, target, kUp, 40, double(w) / h, 5, 120);
  RenderSettings s = Settings(vp, w, h);
  s.maxBounces = 0;
  s.clipPlanes = TwoPlanes();
  const Image image = RenderChecked(*engine, s);
  int hits = 0, agree = 0, disagree = 0, clippedAway = 0;
  for (int y = 0; y < h; ++y)
  {
    for (int x = 0; x < w; ++x)
    {
      const BruteHit b = BruteForceFirstHit(t, vp, w, h, x, y, s.clipPlanes);
      const BruteHit whole = BruteForceFirstHit(t, vp, w, h, x, y);
      clippedAway += whole.hit && (!b.hit || b.node != whole.node);
      const std::size_t i = Pixel(image, x, y);
      if ((image.rgba[4 * i + 3] > 0) != b.hit)
      {
        ++disagree;
        continue;
      }
      if (b.hit)
      {
        ++hits;
        agree += SameRgb(&image.rgba[4 * i], NodeColour(t, b.node));
        EXPECT_NEAR(image.depth[i], b.depth, 1e-5) << "pixel " << x << "," << y;
      }
    }
  }
  std::cout << hits << " pixels hit, " << clippedAway << " hit otherwise without the planes, " << disagree
            << " disagree\n";
  EXPECT_GT(clippedAway, 100); // the planes take away much of the picture
  EXPECT_GT(hits, 200);
  EXPECT_LE(disagree * 100, w * h) << disagree << " pixels hit where the reference misses or the other way";
  EXPECT_GE(agree, hits * 99 / 100) << agree << " of " << hits;
}

namespace
{
// Every voxel a traversal visits, none refused, zero-length touches aside:
// a ray through an edge or corner of mid planes touches some children with
// tEnter == tExit, which the slab tests of the reference visit and
// Traverse may pass by; they hold no length of the ray.
struct VisitLog
{
  std::vector<NodeHit> hits;
  bool Visit(const NodeHit& h)
  {
    if (h.tEnter < h.tExit)
    {
      hits.push_back(h);
    }
    return false;
  }
};

bool SameHit(const NodeHit& a, const NodeHit& b)
{
  return a.node == b.node && a.level == b.level && a.tEnter == b.tEnter && a.tExit == b.tExit && a.axis == b.axis &&
    a.lo.x == b.lo.x && a.lo.y == b.lo.y && a.lo.z == b.lo.z && a.size == b.size;
}
}

namespace
{
// Rays to compare traversals with, from everywhere (inside the cube,
// outside, clipped by tMin and tMax), parallel to one or two axes and lying
// on grid planes, diagonal through the mid planes' edges, and with level of
// detail; each aimed at a corner of a leaf of t (at `depth`), so that most
// rays meet the clusters. Ray r is of kind r % 8.
struct TestRays
{
  HostOctree& t;
  int depth;
  std::mt19937_64 rng{ 11 };
  std::uniform_real_distribution<float> around{ -0.5f, 1.5f }, unit{ -1.0f, 1.0f }, share{ 0.0f, 1.0f };

  void Make(int r, Ray& ray, LevelOfDetail& lod)
  {
    const OctreeView view = t.View();
    const float cells = std::ldexp(1.0f, depth);
    const std::uint32_t leaf = view.levelBegin[depth] + static_cast<std::uint32_t>(rng() % view.LevelSize(depth));
    std::uint32_t cell[3];
    DecodeMorton(t.Key(leaf), cell[0], cell[1], cell[2]);
    const Vec3f corner{ cell[0] / cells, cell[1] / cells, cell[2] / cells };
    ray.origin = Vec3f{ around(rng), around(rng), around(rng) };
    Vec3f d = corner + Vec3f{ share(rng), share(rng), share(rng) } * (1.0f / cells) - ray.origin;
    const int kind = r % 8;
    if (kind == 1 || kind == 2) // parallel to one or two axes, on the leaf's grid planes
    {
      for (int a = 0; a < kind; ++a)
      {
        d[(r / 8 + a) % 3] = 0.0f;
        ray.origin[(r / 8 + a) % 3] = corner[(r / 8 + a) % 3];
      }
    }
    else if (kind == 3) // diagonal: x and y cross every mid plane together
    {
      ray.origin = Vec3f{ 0.0f, 0.0f, share(rng) };
      d = Vec3f{ 1.0f, 1.0f, unit(rng) * 0.5f };
    }
    SetDirection(ray, Normalize(d));
    ray.tMin = kind == 4 ? share(rng) : 0.0f;
    ray.tMax = kind == 5 ? share(rng) * 2.0f : INFINITY;
    lod = LevelOfDetail{};
    if (kind == 6)
    {
      lod.pixels = 1.0f;
      lod.footprint0 = 0.002f;
      lod.footprintSlope = 0.01f;
    }
  }
};
}

// Traverse against ReferenceTraversal.h's slab test of every child box:
// the same voxels in the same order with bit-identical spans, entry axes
// and boxes, for TestRays' rays.
TEST_P(RenderTest, TraversalVisitsWhatSlabTestsOfEachChildVisit)
{
  const Cloud c = GaussianClusters(3000, 47);
  HostOctree t = BuildOnHost(*engine, c.View(), 7);
  const OctreeView view = t.View();
  TestRays rays{ t, 7 };
  std::size_t visits = 0;
  for (int r = 0; r < 20000; ++r)
  {
    Ray ray;
    LevelOfDetail lod;
    rays.Make(r, ray, lod);
    VisitLog fast, reference;
    Traverse(view, ray, lod, fast);
    ReferenceTraverse(view, ray, lod, reference);
    ASSERT_EQ(fast.hits.size(), reference.hits.size()) << "ray " << r;
    for (std::size_t i = 0; i < fast.hits.size(); ++i)
    {
      ASSERT_TRUE(SameHit(fast.hits[i], reference.hits[i])) << "ray " << r << ", visit " << i;
    }
    visits += fast.hits.size();
  }
  EXPECT_GT(visits, 30000u); // the rays meet the clusters, not only empty space
}

// A ray along the diagonal of a layer of voxels, through its empty squares
// (i, i), beside a line of full ones, (i, i + 1) or (i + 1, i): it crosses
// the x and y mid planes of every node on its way at once, and touches the
// full squares only at their corners. Such a touch has no length, but a ray
// that drops it sees through a solid-looking lattice (a dotted line of
// holes in a picture), so the first hit must be the slab tests'. Keeping
// only one of the two octants between two mid planes the ray crosses at
// once (one comparison per pair of axes in MetOctants) fails it.
TEST_P(RenderTest, RaysThroughLatticeCornersTouchTheVoxels)
{
  for (int side : { 1, -1 })
  {
    std::mt19937_64 rng(5);
    Cloud c;
    for (int i = 0; i < 31; ++i)
      c.Add(i + (side < 0) + 0.5, i + (side > 0) + 0.5, 0.5, rng);
    BuildOptions options; // cells of side 1, so that the diagonal runs through their corners exactly
    options.depth = 5;
    options.fixedCube = true;
    options.cube.size = 32.0;
    HostOctree t = BuildOnHost(*engine, c.View(), options);
    const OctreeView view = t.View();
    for (float direction : { 1.0f, -1.0f })
    {
      SCOPED_TRACE("full squares on the " + std::string(side > 0 ? "+y" : "+x") + " side, direction " +
        std::to_string(direction));
      const float start = (direction > 0 ? 0.5f : 31.5f) / 32;
      Ray ray;
      ray.origin = Vec3f{ start, start, 0.5f / 32 };
      SetDirection(ray, Normalize(Vec3f{ direction, direction, 0.0f }));
      ray.tMin = 0.0f;
      ray.tMax = INFINITY;
      LevelOfDetail lod;
      FirstHitVisitor fast, reference;
      Traverse(view, ray, lod, fast);
      ReferenceTraverse(view, ray, lod, reference);
      ASSERT_TRUE(reference.found);
      EXPECT_EQ(reference.hit.tEnter, reference.hit.tExit); // a touch
      ASSERT_TRUE(fast.found);
      EXPECT_EQ(fast.hit.tEnter, reference.hit.tEnter);
    }
  }
}

TEST_P(RenderTest, FullPlaneHasNoCracksAtAnyAngle)
{
  // Every cell of a 32x32 plane at depth 5 occupied.
  std::mt19937_64 rng(42);
  Cloud c;
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j)
      c.Add(i + 0.5, j + 0.5, 0.0, rng);
  c.Add(0, 0, 0, rng);
  c.Add(32, 32, 0, rng);
  HostOctree t = BuildOnHost(*engine, c.View(), 5);
  const int w = 96, h = 96;
  const double target[3] = { 16, 16, 0 };
  const double eyes[][3] = { { 16, 16, 60 }, { 16.0, -20, 25 }, { 50, -30, 5 }, { 16, 16.0001, 80 } };
  for (const auto& eye : eyes)
  {
    const double up[3] = { 0, 1, 0 };
    const Matrix vp = ViewProjection(eye, target, eye[0] == 16 && eye[1] == 16 ? up : kUp, 50, 1.0, 1, 200);
    const RenderSettings s = Settings(vp, w, h);
    Image image;
    engine->Render(s, image);
    // Inside the plane's outline (brute force says hit), the tracer hits.
    int missing = 0, inside = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
      {
        if (BruteForceFirstHit(t, vp, w, h, x, y).hit)
        {
          ++inside;
          missing += image.rgba[4 * (std::size_t(y) * w + x) + 3] == 0;
        }
      }
    EXPECT_GT(inside, 100);
    EXPECT_EQ(missing, 0) << "eye " << eye[0] << "," << eye[1] << "," << eye[2];
  }
}

TEST_P(RenderTest, MaximumIntensityMatchesBruteForce)
{
  const Cloud c = UniformCloud(300, 43);
  HostOctree t = BuildOnHost(*engine, c.View(), 4);
  const int w = 40, h = 40;
  const double eye[3] = { 3, -4, 2 }, target[3] = { 0, 0, 0 };
  const Matrix vp = ViewProjection(eye, target, kUp, 45, 1.0, 0.5, 20);
  RenderSettings s = Settings(vp, w, h);
  s.blend = BlendMode::Maximum;
  s.transfer.range[0] = -50;
  s.transfer.range[1] = 50;
  for (int i = 0; i < 101; ++i)
  {
    const float v = i / 100.0f;
    s.transfer.table.push_back(Rgba{ v, v, v, 1.0f });
  }
  Image image;
  engine->Render(s, image);
  int checked = 0;
  for (int y = 0; y < h; ++y)
  {
    for (int x = 0; x < w; ++x)
    {
      // Brute force: the largest scalar of every leaf the ray passes.
      const WorldRay ray = PixelRay(vp, w, h, x, y);
      float maxScalar = -INFINITY;
      for (std::uint32_t n = t.levelBegin[4]; n < t.levelBegin[5]; ++n)
      {
        double lo[3], hi[3], t0 = 0, t1 = 1;
        NodeBox(t, n, 4, lo, hi);
        // Skip grazing contacts, where the two methods may differ.
        if (Slab(ray, lo, hi, t0, t1) && t1 - t0 > 1e-6)
          maxScalar = std::max(maxScalar, t.Scalar(n));
      }
      const std::size_t i = std::size_t(y) * w + x;
      if (maxScalar == -INFINITY)
        continue;
      const float expected = std::round((maxScalar + 50) / 100 * 100) / 100;
      EXPECT_NEAR(image.rgba[4 * i], expected, 0.0101f) << "pixel " << x << "," << y;
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);
}

TEST_P(RenderTest, PhongShadowsReflectionsAndRepeatability)
{
  Cloud c = GaussianClusters(3000, 44);
  BuildOptions options;
  options.depth = 7;
  engine->Build(c.View(), options);
  const int w = 48, h = 32;
  const double eye[3] = { 20, -25, 15 }, target[3] = { 2, 1, 1 };
  const Matrix vp = ViewProjection(eye, target, kUp, 40, double(w) / h, 1, 100);
  RenderSettings s = Settings(vp, w, h);
  s.shade = ShadeMode::Phong;
  Light sun;
  sun.position[0] = 1, sun.position[1] = -1, sun.position[2] = 2, sun.position[3] = 0;
  s.lights.push_back(sun);
  s.shadows = true;
  Image a, b;
  const RenderStats stats = engine->Render(s, a);
  engine->Render(s, b);
  EXPECT_EQ(a.rgba, b.rgba) << "repeated renders differ";
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_GT(stats.secondaryRays, 0u); // shadow and mirror rays were cast
  s.shadows = false;
  s.maxBounces = 0;
  Image plain;
  const RenderStats plainStats = engine->Render(s, plain);
  EXPECT_EQ(plainStats.secondaryRays, 0u);
  EXPECT_NE(plain.rgba, a.rgba);
  EXPECT_EQ(plain.depth, a.depth); // secondary rays never change the first hit
}

TEST_P(RenderTest, BadSettingsAreErrors)
{
  const Cloud c = UniformCloud(100, 45);
  engine->Build(c.View(), BuildOptions());
  RenderSettings s;
  Image image;
  try
  {
    engine->Render(s, image);
    FAIL() << "no error for an empty viewport";
  }
  catch (const Error& e)
  {
    EXPECT_STREQ(e.what(), "octoray: the viewport must be at least 1x1, got 0x0");
  }
  s.width = s.height = 4;
  try
  {
    engine->Render(s, image);
    FAIL() << "no error for a singular matrix";
  }
  catch (const Error& e)
  {
    EXPECT_STREQ(e.what(), "octoray: the inverse view-projection matrix is singular");
  }
  const double eye[3] = { 3, -4, 2 }, target[3] = { 0, 0, 0 };
  s = Settings(ViewProjection(eye, target, kUp, 45, 1.0, 0.5, 20), 4, 4);
  s.clipPlanes.assign(kMaxClipPlanes + 1, ClipPlane());
  try
  {
    engine->Render(s, image);
    FAIL() << "no error for too many clipping planes";
  }
  catch (const Error& e)
  {
    EXPECT_STREQ(e.what(), "octoray: at most 12 clipping planes, got 13");
  }
  s.clipPlanes = { ClipPlane(), Plane(1, 2, 3, 0, 0, 0) };
  try
  {
    engine->Render(s, image);
    FAIL() << "no error for a plane without a normal";
  }
  catch (const Error& e)
  {
    EXPECT_STREQ(e.what(), "octoray: clipping plane 1 needs a finite origin and a non-zero normal, got (1.000000, "
                           "2.000000, 3.000000) and (0.000000, 0.000000, 0.000000)");
  }
  s.clipPlanes.clear();
  const std::pair<float RenderSettings::*, const char*> numbers[] = { { &RenderSettings::ambient,
                                                                        "ambient coefficient" },
    { &RenderSettings::diffuse, "diffuse coefficient" }, { &RenderSettings::specular, "specular coefficient" },
    { &RenderSettings::specularPower, "specular power" }, { &RenderSettings::depthCue, "depth cue" },
    { &RenderSettings::lodPixels, "level-of-detail pixel size" },
    { &RenderSettings::opacityUnitDistance, "opacity unit distance" } };
  for (const auto& number : numbers)
  {
    RenderSettings bad = s;
    bad.*number.first = std::numeric_limits<float>::quiet_NaN();
    try
    {
      engine->Render(bad, image);
      FAIL() << "no error for a NaN " << number.second;
    }
    catch (const Error& e)
    {
      EXPECT_EQ(e.what(), "octoray: the " + std::string(number.second) + " must be a finite number, got nan");
    }
  }
  engine->Render(s, image); // the same settings without a NaN draw
}

TEST_P(RenderTest, EightBitOutputIsTheRoundedFloatPicture)
{
  const Cloud c = GaussianClusters(2000, 47);
  BuildOptions options;
  options.depth = 6;
  engine->Build(c.View(), options);
  const int w = 40, h = 30;
  const double eye[3] = { 20, -25, 15 }, target[3] = { 2, 1, 1 };
  const Matrix vp = ViewProjection(eye, target, kUp, 40, double(w) / h, 1, 100);
  for (BlendMode blend : { BlendMode::Surface, BlendMode::Composite })
  {
    RenderSettings s = Settings(vp, w, h);
    s.blend = blend;
    s.shade = ShadeMode::Phong;
    s.transfer.range[0] = -50;
    s.transfer.range[1] = 50;
    s.transfer.table = { Rgba{ 0, 0, 1, 0.05f }, Rgba{ 1, 1, 0, 0.05f } };
    Image f, b;
    engine->Render(s, f);
    s.rgba8 = true;
    engine->Render(s, b);
    ASSERT_EQ(f.rgba.size(), 4u * w * h);
    ASSERT_TRUE(f.rgba8.empty());
    ASSERT_EQ(b.rgba8.size(), 4u * w * h);
    ASSERT_TRUE(b.rgba.empty());
    int lit = 0;
    for (std::size_t i = 0; i < f.rgba.size(); ++i)
    {
      ASSERT_EQ(b.rgba8[i], ChannelToByte(f.rgba[i])) << "channel " << i;
      lit += b.rgba8[i] > 0;
    }
    EXPECT_GT(lit, 100);
    EXPECT_EQ(f.depth, b.depth);
  }
}

// A depth buffer in device memory (what the VTK layer maps from OpenGL)
// stops rays exactly where the same depth from the host does, and its
// signature on the device is the host's. The CPU backend refuses one.
TEST_P(RenderTest, DepthBufferInDeviceMemory)
{
  const Cloud c = GaussianClusters(3000, 48);
  BuildOptions options;
  options.depth = 6;
  engine->Build(c.View(), options);
  const int w = 48, h = 36;
  const double eye[3] = { 20, -25, 15 }, target[3] = { 2, 1, 1 };
  const Matrix vp = ViewProjection(eye, target, kUp, 40, double(w) / h, 1, 100);
  RenderSettings s = Settings(vp, w, h);
  s.maxBounces = 0;
  Image first;
  engine->Render(s, first);
  if (GetParam() == Backend::CPU)
  {
    s.deviceDepthBuffer = first.depth.data();
    EXPECT_THROW(engine->Render(s, first), Error);
    EXPECT_THROW(engine->DeviceDepthSignature(first.depth.data(), first.depth.size()), Error);
    return;
  }
  // The opaque geometry: a second engine's picture of a cluster between the
  // camera and the cloud, whose depth stays in device memory.
  Cloud front = GaussianClusters(500, 49);
  for (std::size_t i = 0; i < front.xyz.size(); i += 3)
  {
    for (int a = 0; a < 3; ++a)
    {
      front.xyz[i + a] = 0.8 * front.xyz[i + a] + 0.3 * (eye[a] + target[a]);
    }
  }
  auto occluder = CreateEngine(Backend::CUDA);
  occluder->Build(front.View(), options);
  Image opaque;
  occluder->Render(s, opaque);
  const DeviceImage device = occluder->LastDeviceImage();
  ASSERT_NE(device.depth, nullptr);
  EXPECT_EQ(occluder->DeviceDepthSignature(device.depth, opaque.depth.size()),
    DepthSignature(opaque.depth.data(), opaque.depth.size()));
  // The cloud behind it, with that depth read on the device and from the host.
  RenderSettings d = s;
  d.deviceDepthBuffer = device.depth;
  Image fromDevice, fromHost;
  engine->Render(d, fromDevice);
  d.deviceDepthBuffer = nullptr;
  d.depthBuffer = opaque.depth;
  engine->Render(d, fromHost);
  EXPECT_EQ(fromDevice.rgba, fromHost.rgba);
  EXPECT_EQ(fromDevice.depth, fromHost.depth);
  int blocked = 0;
  for (std::size_t i = 0; i < first.depth.size(); ++i)
  {
    blocked += first.rgba[4 * i + 3] > 0 && fromHost.rgba[4 * i + 3] == 0;
  }
  EXPECT_GT(blocked, 20) << "the opaque depth must hide part of the cloud";
  d.deviceDepthBuffer = device.depth;
  EXPECT_THROW(engine->Render(d, fromDevice), Error) << "host and device depth at once";
}

INSTANTIATE_TEST_SUITE_P(Backends, RenderTest, ::testing::Values(Backend::CPU, Backend::CUDA), BackendName);

// The device's traversal reads mirrored child masks from this table
// (OctantMirror); the CUDA pictures' tests above check its use.
TEST(Traversal, MirroredMasksFlipOctantsByTheRaySigns)
{
  const MirroredMasks table = EveryMirroredMask();
  for (unsigned signs = 0; signs < 8; ++signs)
  {
    const OctantMirror mirror(signs);
    for (unsigned mask = 0; mask < 256; ++mask)
    {
      unsigned expected = 0;
      for (unsigned octant = 0; octant < 8; ++octant)
      {
        expected |= ((mask >> octant) & 1u) << (octant ^ signs);
      }
      ASSERT_EQ(table.bySigns[signs][mask], expected) << "signs " << signs << ", mask " << mask;
      ASSERT_EQ(mirror(mask), expected) << "signs " << signs << ", mask " << mask;
    }
  }
}

TEST(DepthSignature, ChangesWithAnyPixel)
{
  std::vector<float> depth(640 * 480);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float& z : depth)
  {
    z = u(rng);
  }
  const std::uint64_t base = DepthSignature(depth.data(), depth.size());
  EXPECT_EQ(base, DepthSignature(depth.data(), depth.size()));
  std::vector<float> moved(depth);
  moved[12345] = std::nextafter(moved[12345], 2.0f); // one ulp
  EXPECT_NE(base, DepthSignature(moved.data(), moved.size()));
  std::swap(moved[1], moved[2]);
  moved[12345] = depth[12345];
  EXPECT_NE(base, DepthSignature(moved.data(), moved.size())) << "two pixels swapped";
  EXPECT_NE(base, DepthSignature(depth.data(), depth.size() - 1));
}

namespace
{
// The voxels a traversal shows, until `limit` of them.
struct VisitRecord
{
  std::size_t limit = 1;
  std::vector<NodeHit> hits;
  bool Visit(const NodeHit& h)
  {
    hits.push_back(h);
    return hits.size() >= limit;
  }
};

// What each lane's visitor is shown by a packet against what Traverse shows
// it for the lane's ray alone, in every value and in order, through each
// instruction set this processor has: the first voxel, the first three
// (visitors that stop part of the way, as composite does) and all of them
// (MIP). `valid` has a bit per lane whose ray exists.
void ExpectPacketVisitsAreTraverses(
  const OctreeView& view, const Ray rays[kPacketLanes], const LevelOfDetail lods[kPacketLanes], unsigned valid)
{
  for (std::size_t limit : { std::size_t{ 1 }, std::size_t{ 3 }, SIZE_MAX })
  {
    for (bool avx2 : { false, true })
    {
      if (avx2 && !HasAvx2())
      {
        continue;
      }
      VisitRecord packed[kPacketLanes];
      for (VisitRecord& v : packed)
      {
        v.limit = limit;
      }
      avx2 ? TracePacketAvx2(view, rays, lods, valid, packed) : TracePacketBaseline(view, rays, lods, valid, packed);
      for (int lane = 0; lane < kPacketLanes; ++lane)
      {
        VisitRecord alone{ limit, {} };
        if ((valid >> lane) & 1u)
        {
          Traverse(view, rays[lane], lods[lane], alone);
        }
        const std::string where = "lane " + std::to_string(lane) + ", up to " + std::to_string(limit) +
          " voxels, " + (avx2 ? "AVX2" : "baseline");
        ASSERT_EQ(packed[lane].hits.size(), alone.hits.size()) << where;
        for (std::size_t k = 0; k < alone.hits.size(); ++k)
        {
          ASSERT_TRUE(SameHit(packed[lane].hits[k], alone.hits[k])) << where << ", voxel " << k;
        }
      }
    }
  }
}
}

// PacketTraversal.h against Traverse, lane by lane: packets of TestRays'
// rays (lanes of every kind and octant side by side, some lanes empty) and
// packets of neighbouring pixels as the CPU engine traces them, from
// cameras outside and inside the cube, in perspective and parallel
// projection, looking along an axis (lanes parallel to it, and rows whose
// directions change octant), with level of detail and a depth buffer.
TEST(PacketTraversal, EveryLaneSeesWhatTraverseShows)
{
  const Cloud c = GaussianClusters(3000, 47);
  auto cpu = CreateEngine(Backend::CPU);
  HostOctree t = BuildOnHost(*cpu, c.View(), 7);
  const OctreeView view = t.View();
  TestRays scattered{ t, 7 };
  for (int packet = 0; packet < 4000; ++packet)
  {
    SCOPED_TRACE("scattered packet " + std::to_string(packet));
    Ray rays[kPacketLanes];
    LevelOfDetail lods[kPacketLanes];
    for (int lane = 0; lane < kPacketLanes; ++lane)
    {
      scattered.Make(packet * kPacketLanes + lane, rays[lane], lods[lane]);
    }
    ExpectPacketVisitsAreTraverses(view, rays, lods, packet % 5 == 0 ? 0xB5u : 0xFFu);
  }
  const int w = 61, h = 45; // rows end in a part of a packet
  const double target[3] = { 2, 1, 1 };
  const double eyes[][3] = { { 25, -30, 18 }, { 2, 1, 30 }, { 1.5, 0.5, 1.2 } };
  for (const auto& eye : eyes)
  {
    for (bool parallel : { false, true })
    {
      const bool down = eye[0] == target[0];
      const Matrix vp = ViewProjection(eye, target, down ? kYUp : kUp, 40, double(w) / h, 0.5, 120, parallel, 12);
      RenderSettings s = Settings(vp, w, h);
      s.lodPixels = parallel ? 0.0f : 1.5f;
      s.depthBuffer.assign(std::size_t(w) * h, 1.0f);
      for (std::size_t i = 0; i < s.depthBuffer.size(); i += 7)
      {
        s.depthBuffer[i] = 0.995f;
      }
      const FrameConstants f = MakeFrame(s, view);
      int packed = 0;
      for (int y = 0; y < h; ++y)
      {
        for (int x0 = 0; x0 < w; x0 += kPacketLanes)
        {
          SCOPED_TRACE("pixels from " + std::to_string(x0) + "," + std::to_string(y));
          Ray rays[kPacketLanes];
          LevelOfDetail lods[kPacketLanes];
          unsigned valid = 0;
          for (int lane = 0; lane < kPacketLanes && x0 + lane < w; ++lane)
          {
            CameraRay pixel;
            float rgba[4], depth;
            if (StartPixel(f, x0 + lane, y, pixel, rgba, depth))
            {
              valid |= 1u << lane;
              rays[lane] = pixel.ray;
              lods[lane] = pixel.lod;
            }
          }
          packed += valid != 0;
          ExpectPacketVisitsAreTraverses(view, rays, lods, valid);
        }
      }
      EXPECT_GT(packed, h); // the camera sees the cube
    }
  }
}

namespace
{
// The CPU engine's picture against RenderPixel's, pixel by pixel, in every
// value. Returns the pixels hit.
std::size_t ExpectRenderPixelsPicture(Engine& cpu, HostOctree& t, const RenderSettings& s)
{
  Image image;
  const RenderStats stats = cpu.Render(s, image);
  const OctreeView view = t.View();
  const FrameConstants f = MakeFrame(s, view);
  std::size_t rays = 0, hits = 0;
  DispatchFeatures(f, [&](auto features) {
    using F = decltype(features);
    for (int y = 0; y < s.height; ++y)
    {
      for (int x = 0; x < s.width; ++x)
      {
        const std::size_t i = std::size_t(y) * s.width + x;
        float rgba[4], depth;
        RenderPixel<F>(f, view, x, y, rgba, depth, rays);
        hits += depth < 1.0f;
        ASSERT_EQ(image.depth[i], depth) << "pixel " << x << "," << y;
        for (int k = 0; k < 4; ++k)
        {
          ASSERT_EQ(image.rgba[4 * i + k], rgba[k]) << "pixel " << x << "," << y << ", channel " << k;
        }
      }
    }
  });
  EXPECT_EQ(stats.secondaryRays, rays);
  return hits;
}
}

// The CPU engine traces primary rays, and the first hits' shadow rays, in
// packets: its pictures are those of RenderPixel pixel by pixel, in every
// value, with as many secondary rays. Surfaces flat, depth-cued and lit with
// shadows (a directional light, a point light and one of each, the
// headlight), with and without reflections (the clusters' points reflect);
// every volume blend mode; with and without level of detail; two clipping
// planes in the variants that reflect.
TEST(PacketTraversal, CpuPicturesAreThePixelByPixelOnes)
{
  const Cloud c = GaussianClusters(20000, 46);
  auto cpu = CreateEngine(Backend::CPU);
  BuildOptions options;
  options.depth = 8;
  HostOctree t = BuildOnHost(*cpu, c.View(), options);
  const int w = 61, h = 45; // rows end in a part of a packet
  const double eye[3] = { 9, -11, 7 }, target[3] = { 1, 1, 0 };
  const Matrix vp = ViewProjection(eye, target, kUp, 40, double(w) / h, 1, 100);
  for (BlendMode blend : { BlendMode::Surface, BlendMode::Composite, BlendMode::Maximum, BlendMode::Minimum,
         BlendMode::Average, BlendMode::Additive })
  {
    for (ShadeMode shade : { ShadeMode::Flat, ShadeMode::DepthCue, ShadeMode::Phong })
    {
      for (int variant = 0; variant < 4; ++variant)
      {
        RenderSettings s = Settings(vp, w, h);
        s.blend = blend;
        s.shade = shade;
        s.maxBounces = variant % 2 == 0 ? 0 : 2;
        s.lodPixels = variant < 2 ? 0.0f : 2.0f;
        if (variant % 2 == 1)
        {
          s.clipPlanes = TwoPlanes();
        }
        if (blend != BlendMode::Surface && (shade != ShadeMode::Flat || s.maxBounces > 0))
        {
          continue; // the volume modes neither shade nor bounce
        }
        SCOPED_TRACE("variant " + std::to_string(variant) + ", blend " + std::to_string(int(blend)) + ", shade " +
          std::to_string(int(shade)) + ", bounces " + std::to_string(s.maxBounces) + ", level of detail " +
          std::to_string(s.lodPixels) + ", clipping planes " + std::to_string(s.clipPlanes.size()));
        if (shade == ShadeMode::Phong)
        {
          Light sun, lamp;
          sun.position[0] = 1, sun.position[1] = -1, sun.position[2] = 2, sun.position[3] = 0;
          lamp.position[0] = 3, lamp.position[1] = -2, lamp.position[2] = 4, lamp.position[3] = 1;
          if (variant != 2)
          {
            s.lights.push_back(variant == 3 ? lamp : sun);
          }
          if (variant == 1)
          {
            s.lights.push_back(lamp);
          }
          s.shadows = true;
        }
        s.transfer.range[0] = -50;
        s.transfer.range[1] = 50;
        for (int i = 0; i < 64 && blend != BlendMode::Surface; ++i)
        {
          s.transfer.table.push_back(
            Rgba{ i / 63.0f, 0.5f, 1 - i / 63.0f, blend == BlendMode::Composite ? 0.05f : 1.0f });
        }
        EXPECT_GT(ExpectRenderPixelsPicture(*cpu, t, s), std::size_t(w) * h / 10);
      }
    }
  }
}

// Suites that only the CUDA backend has: skipped, saying why, without a GPU.
using RenderCUDA = CudaOnlyTest;

// The CUDA picture against the CPU one (the reference), per mode.
TEST_F(RenderCUDA, ImagesEqualTheCpuBackend)
{
  Cloud c = GaussianClusters(20000, 46);
  const BothBackends engines(c.View(), 8);
  Engine& cpu = *engines.cpu;
  Engine& gpu = *engines.gpu;
  const int w = 160, h = 120;
  const double eye[3] = { 20, -25, 15 }, target[3] = { 2, 1, 1 };
  const Matrix vp = ViewProjection(eye, target, kUp, 40, double(w) / h, 1, 100);
  for (BlendMode blend : { BlendMode::Surface, BlendMode::Composite, BlendMode::Maximum, BlendMode::Minimum,
         BlendMode::Average, BlendMode::Additive })
  {
    for (ShadeMode shade : { ShadeMode::Flat, ShadeMode::DepthCue, ShadeMode::Phong })
    {
      if (blend != BlendMode::Surface && shade != ShadeMode::Flat)
        continue;
      for (bool clipped : { false, true })
      {
        RenderSettings s = Settings(vp, w, h);
        s.blend = blend;
        s.shade = shade;
        if (clipped)
          s.clipPlanes = TwoPlanes();
        s.transfer.range[0] = -50;
        s.transfer.range[1] = 50;
        for (int i = 0; i < 64; ++i)
          s.transfer.table.push_back(
            Rgba{ i / 63.0f, 0.5f, 1 - i / 63.0f, blend == BlendMode::Composite ? 0.05f : 1.0f });
        Image a, b;
        cpu.Render(s, a);
        gpu.Render(s, b);
        SCOPED_TRACE("blend " + std::to_string(int(blend)) + " shade " + std::to_string(int(shade)) +
          (clipped ? ", clipped" : ""));
        EXPECT_TRUE(PicturesAgree(a, b));
      }
    }
  }
}

// A viewport taller than the CUDA grid's y limit (65535 blocks of 8 rows):
// every row is still traced, and equals the CPU's.
TEST_F(RenderCUDA, ViewportTallerThanTheGridEqualsTheCpu)
{
  const Cloud c = GaussianClusters(5000, 48);
  const BothBackends engines(c.View(), 6);
  Engine& cpu = *engines.cpu;
  Engine& gpu = *engines.gpu;
  const int w = 2, h = 600000;
  const double eye[3] = { 20, -25, 15 }, target[3] = { 2, 1, 1 };
  const Matrix vp = ViewProjection(eye, target, kUp, 40, double(w) / h * 4000, 1, 100);
  RenderSettings s = Settings(vp, w, h);
  s.maxBounces = 0;
  Image a, b;
  cpu.Render(s, a);
  gpu.Render(s, b);
  ASSERT_EQ(b.rgba.size(), a.rgba.size());
  std::size_t hits = 0;
  for (std::size_t i = 0; i < b.depth.size(); ++i)
  {
    hits += a.depth[i] < 1.0f;
  }
  EXPECT_GT(hits, 1000u);
  // Every row written (NaN-free, the background where nothing is hit), and
  // the issue 4 rule: 99.9% of pixels identical, none off by > 2/255.
  std::size_t identical = 0;
  for (std::size_t i = 0; i < b.depth.size(); ++i)
  {
    float diff = std::fabs(a.depth[i] - b.depth[i]);
    for (int k = 0; k < 4; ++k)
    {
      ASSERT_FALSE(std::isnan(b.rgba[4 * i + k])) << "pixel row " << i / w;
      diff = std::max(diff, std::fabs(a.rgba[4 * i + k] - b.rgba[4 * i + k]));
    }
    identical += diff == 0.0f;
    ASSERT_LE(diff, 2.0f / 255) << "pixel row " << i / w;
  }
  EXPECT_GE(identical * 1000, b.depth.size() * 999);
}
