// Shared pieces of the rendering tests: an OpenGL-style camera (what VTK's
// composite projection transform gives), pixel rays in world coordinates,
// and brute-force references that intersect every leaf box in double
// precision, written independently of the engine's traversal.
#pragma once

#include "TestSupport.h"

#include <octoray/Frame.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

namespace octoray::test
{
using Matrix = std::array<double, 16>;

inline RenderSettings Settings(const Matrix& vp, int w, int h)
{
  RenderSettings s;
  s.width = w;
  s.height = h;
  double inv[16];
  EXPECT_TRUE(Invert4x4(vp.data(), inv));
  std::copy(inv, inv + 16, s.inverseViewProjection);
  return s;
}

// A pixel's ray in world coordinates: o on the near plane, o + d on the far
// plane, so the clipping range is t in [0, 1].
struct WorldRay
{
  double o[3], d[3];
};

inline WorldRay PixelRay(const Matrix& vp, int w, int h, double x, double y)
{
  double inv[16];
  Invert4x4(vp.data(), inv);
  auto unproject = [&](double z, double p[3]) {
    const double ndc[4] = { 2.0 * (x + 0.5) / w - 1, 2.0 * (y + 0.5) / h - 1, z, 1 };
    double r[4] = {};
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 4; ++k)
        r[i] += inv[4 * i + k] * ndc[k];
    for (int a = 0; a < 3; ++a)
      p[a] = r[a] / r[3];
  };
  WorldRay ray;
  double e[3];
  unproject(-1, ray.o);
  unproject(1, e);
  for (int a = 0; a < 3; ++a)
    ray.d[a] = e[a] - ray.o[a];
  return ray;
}

// Slab interval of a ray through the closed box [lo, hi], clipped to
// [t0, t1]; false on a miss.
inline bool Slab(const WorldRay& r, const double lo[3], const double hi[3], double& t0, double& t1)
{
  for (int a = 0; a < 3; ++a)
  {
    if (r.d[a] == 0)
    {
      if (r.o[a] < lo[a] || r.o[a] > hi[a])
        return false;
      continue;
    }
    double ta = (lo[a] - r.o[a]) / r.d[a], tb = (hi[a] - r.o[a]) / r.d[a];
    if (ta > tb)
      std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

// The part [t0, t1] of a ray that every clipping plane keeps (the side its
// normal points to), in world coordinates; false when none is kept.
inline bool KeptSpan(const WorldRay& r, const std::vector<ClipPlane>& planes, double& t0, double& t1)
{
  for (const ClipPlane& p : planes)
  {
    double start = 0, rate = 0;
    for (int a = 0; a < 3; ++a)
    {
      start += p.normal[a] * (r.o[a] - p.origin[a]);
      rate += p.normal[a] * r.d[a];
    }
    if (rate == 0)
    {
      if (start < 0)
        return false;
      continue;
    }
    const double t = -start / rate;
    if (rate > 0)
      t0 = std::max(t0, t);
    else
      t1 = std::min(t1, t);
  }
  return t0 <= t1;
}

// World box of node n at `level` of a host octree.
inline void NodeBox(const HostOctree& t, std::uint32_t n, int level, double lo[3], double hi[3])
{
  std::uint32_t c[3];
  DecodeMorton(t.Key(n), c[0], c[1], c[2]);
  const double voxel = t.cube.size / double(1u << level);
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = t.cube.origin[a] + c[a] * voxel;
    hi[a] = lo[a] + voxel;
  }
}

// Window point (pixel coordinates, the pixel (x, y) covering [x, x+1)) of a
// world point.
inline void ProjectToPixel(const Matrix& vp, int w, int h, const double p[3], double& px, double& py)
{
  double clip[4] = {};
  const double in[4] = { p[0], p[1], p[2], 1 };
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k)
      clip[i] += vp[4 * i + k] * in[k];
  px = (clip[0] / clip[3] * 0.5 + 0.5) * w;
  py = (clip[1] / clip[3] * 0.5 + 0.5) * h;
}

struct BruteHit
{
  bool hit = false;
  std::uint32_t node = 0;
  double t = 0;
  double depth = 1;
  double p[3] = {}; // world point where the ray enters the voxel
};

// Every leaf box against the pixel's ray, in double; world coordinates.
// With clipping planes, the part of the ray they keep.
inline BruteHit BruteForceFirstHit(
  const HostOctree& t, const Matrix& vp, int w, int h, int x, int y, const std::vector<ClipPlane>& planes = {})
{
  const WorldRay r = PixelRay(vp, w, h, x, y);
  BruteHit best;
  best.t = std::numeric_limits<double>::infinity();
  double kept0 = 0, kept1 = 1; // the clipping range is t in [0, 1]
  if (!KeptSpan(r, planes, kept0, kept1))
    return best;
  for (std::uint32_t n = t.levelBegin[t.depth]; n < t.levelBegin[t.depth + 1]; ++n)
  {
    double lo[3], hi[3], t0 = kept0, t1 = kept1;
    NodeBox(t, n, t.depth, lo, hi);
    // Half-open boxes where the ray runs along a face plane, as the engine
    // defines them (a ray on a shared face belongs to exactly one voxel).
    bool miss = false;
    for (int a = 0; a < 3; ++a)
      miss = miss || (r.d[a] == 0 && !(r.o[a] >= lo[a] && r.o[a] < hi[a]));
    if (!miss && Slab(r, lo, hi, t0, t1) && t0 < best.t)
    {
      best.hit = true;
      best.node = n;
      best.t = t0;
    }
  }
  if (best.hit)
  {
    double clip[4] = {};
    for (int a = 0; a < 3; ++a)
      best.p[a] = r.o[a] + best.t * r.d[a];
    const double p[4] = { best.p[0], best.p[1], best.p[2], 1 };
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 4; ++k)
        clip[i] += vp[4 * i + k] * p[k];
    best.depth = 0.5 * clip[2] / clip[3] + 0.5;
  }
  return best;
}

inline std::size_t Pixel(const Image& image, int x, int y)
{
  return std::size_t(y) * image.width + x;
}

// Every image a test makes: the right size, and no NaN or infinity in
// colour or depth anywhere.
inline void ExpectFiniteImage(const Image& image, int w, int h)
{
  ASSERT_EQ(image.width, w);
  ASSERT_EQ(image.height, h);
  ASSERT_EQ(image.rgba.size(), 4 * std::size_t(w) * h);
  ASSERT_EQ(image.depth.size(), std::size_t(w) * h);
  std::size_t bad = 0, first = 0;
  for (std::size_t i = 0; i < image.rgba.size(); ++i)
  {
    if (!std::isfinite(image.rgba[i]) && bad++ == 0)
      first = i / 4;
  }
  for (std::size_t i = 0; i < image.depth.size(); ++i)
  {
    if (!(image.depth[i] >= 0.0f && image.depth[i] <= 1.0f) && bad++ == 0)
      first = i;
  }
  EXPECT_EQ(bad, 0u) << "non-finite values, the first at pixel " << first % w << "," << first / w;
}

// Renders and checks the image for size and finiteness.
inline Image RenderChecked(Engine& engine, const RenderSettings& s, RenderStats* stats = nullptr)
{
  Image image;
  const RenderStats st = engine.Render(s, image);
  if (stats)
    *stats = st;
  ExpectFiniteImage(image, s.width, s.height);
  return image;
}

// Bit-for-bit equality of two images (NaN payloads included).
inline bool BitIdentical(const Image& a, const Image& b)
{
  return a.width == b.width && a.height == b.height && a.rgba.size() == b.rgba.size() &&
    a.depth.size() == b.depth.size() &&
    std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * sizeof(float)) == 0 &&
    std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)) == 0;
}

// Build options for a scene laid out on the unit cube's grid: points placed
// at voxel centres land where the test says, whatever their bounds.
inline BuildOptions UnitCubeOptions(int depth)
{
  BuildOptions o;
  o.depth = depth;
  o.fixedCube = true;
  o.cube.origin[0] = o.cube.origin[1] = o.cube.origin[2] = 0.0;
  o.cube.size = 1.0;
  return o;
}

// ---------------------------------------------------------------- scenes on the unit cube

inline const double kZUp[3] = { 0, 0, 1 };
inline const double kYUp[3] = { 0, 1, 0 };

// Points with float colours and, when a test asks, normals, reflectivity
// and scalars (each array is either complete or absent).
struct Scene
{
  std::vector<double> xyz;
  std::vector<float> rgb, normal, reflectivity, scalar;
  bool withNormals = false, withReflectivity = false, withScalar = false;

  void Add(double x, double y, double z, const float c[3], const float n[3] = nullptr, float refl = 0.0f,
    float s = 0.0f)
  {
    xyz.insert(xyz.end(), { x, y, z });
    rgb.insert(rgb.end(), { c[0], c[1], c[2] });
    normal.insert(normal.end(), { n ? n[0] : 0.0f, n ? n[1] : 0.0f, n ? n[2] : 1.0f });
    reflectivity.push_back(refl);
    scalar.push_back(s);
  }
  // A point at the centre of cell (i, j, k) of the unit cube's grid at `level`.
  void AddCell(int level, int i, int j, int k, const float c[3], const float n[3] = nullptr, float refl = 0.0f,
    float s = 0.0f)
  {
    const double v = std::ldexp(1.0, -level);
    Add((i + 0.5) * v, (j + 0.5) * v, (k + 0.5) * v, c, n, refl, s);
  }
  PointCloudView View() const
  {
    PointCloudView v;
    v.count = xyz.size() / 3;
    v.xyzDouble = xyz.data();
    v.colorFloat = rgb.data();
    v.colorComponents = 3;
    v.normal = withNormals ? normal.data() : nullptr;
    v.reflectivity = withReflectivity ? reflectivity.data() : nullptr;
    v.scalar = withScalar ? scalar.data() : nullptr;
    return v;
  }
};

// Floor cells at z-level 0 of depth 5 (top face z = 1/32), grey, and a
// 4x4x2 block of `blockColour` above it (cells 12..15, 12..15, 6..7).
inline Scene FloorAndBlock(const float blockColour[3])
{
  Scene s;
  const float grey[3] = { 0.6f, 0.6f, 0.6f };
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j)
      s.AddCell(5, i, j, 0, grey);
  for (int i = 12; i < 16; ++i)
    for (int j = 12; j < 16; ++j)
      for (int k = 6; k < 8; ++k)
        s.AddCell(5, i, j, k, blockColour);
  return s;
}

// Whether a ray (t >= tFrom) meets the box [lo, hi] grown by `margin` on
// every side: +1 when it meets even the box shrunk by the margin, 0 when it
// misses even the grown box, -1 in between (the band within `margin` of
// the outline, where the pixel may go either way).
inline int BoxHitWithMargin(const WorldRay& r, const double lo[3], const double hi[3], double margin, double tFrom = 0,
  double tTo = 1)
{
  auto meets = [&](double m) {
    double l[3], h[3], t0 = tFrom, t1 = tTo;
    for (int a = 0; a < 3; ++a)
      l[a] = lo[a] - m, h[a] = hi[a] + m;
    return Slab(r, l, h, t0, t1);
  };
  if (meets(-margin))
    return 1;
  return meets(margin) ? -1 : 0;
}

inline double Length(const double v[3])
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

inline void Normalize3(double v[3])
{
  const double l = Length(v);
  for (int a = 0; a < 3; ++a)
    v[a] /= l;
}

inline bool SameRgb(const float* pixel, const float c[3], float tol = 1e-6f)
{
  return std::fabs(pixel[0] - c[0]) <= tol && std::fabs(pixel[1] - c[1]) <= tol && std::fabs(pixel[2] - c[2]) <= tol;
}

inline bool SameRgb(const float* pixel, const Rgba& c, float tol = 1e-6f)
{
  return SameRgb(pixel, &c.r, tol);
}

// A node's averaged colour as the engine draws it: float or 8-bit.
inline Rgba NodeColour(const HostOctree& t, std::uint32_t node)
{
  return t.color.empty() ? ToRgba(t.color8.at(node)) : t.color[node];
}

// One cloud built at `depth` by the CPU backend and by CUDA, for tests that
// hold CUDA's pictures to the CPU's.
struct BothBackends
{
  std::unique_ptr<Engine> cpu = CreateEngine(Backend::CPU);
  std::unique_ptr<Engine> gpu = CreateEngine(Backend::CUDA);

  BothBackends(const PointCloudView& points, int depth)
  {
    BuildOptions options;
    options.depth = depth;
    cpu->Build(points, options);
    gpu->Build(points, options);
  }
};

// Issue 4's rule for two backends' pictures of one frame: 99.9 % of the
// pixels identical (colour), none off by more than 2/255 in any channel.
inline ::testing::AssertionResult PicturesAgree(const Image& a, const Image& b)
{
  if (a.rgba.size() != b.rgba.size())
    return ::testing::AssertionFailure() << "sizes differ";
  const std::size_t pixels = a.rgba.size() / 4;
  std::size_t identical = 0;
  float worst = 0;
  for (std::size_t i = 0; i < pixels; ++i)
  {
    float diff = 0;
    for (int k = 0; k < 4; ++k)
      diff = std::max(diff, std::fabs(a.rgba[4 * i + k] - b.rgba[4 * i + k]));
    identical += diff == 0;
    worst = std::max(worst, diff);
  }
  if (identical * 1000 < pixels * 999 || worst > 2.0f / 255)
    return ::testing::AssertionFailure() << identical << " of " << pixels << " pixels identical, the worst off by "
                                         << worst * 255 << "/255";
  return ::testing::AssertionSuccess();
}
}
