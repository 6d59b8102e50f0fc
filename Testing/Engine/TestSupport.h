// Shared pieces of the engine tests: point generators, the backend fixture
// and a brute-force reference octree written independently of the engine.
#pragma once

#include "CudaOnlyTest.h"

#include <octoray/Engine.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace octoray::test
{
// Points with every attribute, so that every average is checked (colours,
// scalars and normals can be dropped: WithExactMeans).
struct Cloud
{
  std::vector<double> xyz;
  std::vector<std::uint8_t> rgb;
  std::vector<float> scalar, reflectivity, refraction, normal;

  std::size_t Size() const { return xyz.size() / 3; }

  void Add(double x, double y, double z, std::mt19937_64& rng)
  {
    std::uniform_int_distribution<int> byte(0, 255);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    xyz.insert(xyz.end(), { x, y, z });
    rgb.insert(rgb.end(), { static_cast<std::uint8_t>(byte(rng)), static_cast<std::uint8_t>(byte(rng)),
                            static_cast<std::uint8_t>(byte(rng)) });
    scalar.push_back(unit(rng) * 100.0f - 50.0f);
    reflectivity.push_back(unit(rng));
    refraction.push_back(unit(rng) < 0.5f ? 0.0f : 1.0f + unit(rng));
    normal.insert(normal.end(), { unit(rng) - 0.5f, unit(rng) - 0.5f, unit(rng) - 0.5f });
  }

  // Appends the points of `other`, every array.
  void Append(const Cloud& other)
  {
    xyz.insert(xyz.end(), other.xyz.begin(), other.xyz.end());
    rgb.insert(rgb.end(), other.rgb.begin(), other.rgb.end());
    scalar.insert(scalar.end(), other.scalar.begin(), other.scalar.end());
    reflectivity.insert(reflectivity.end(), other.reflectivity.begin(), other.reflectivity.end());
    refraction.insert(refraction.end(), other.refraction.begin(), other.refraction.end());
    normal.insert(normal.end(), other.normal.begin(), other.normal.end());
  }

  // The cloud without its colours, scalars and normals: the nodes then
  // hold no rounded means, and updates may take the in-place path
  // (Attributes.h).
  Cloud WithExactMeans() const
  {
    Cloud c = *this;
    c.rgb.clear();
    c.scalar.clear();
    c.normal.clear();
    return c;
  }

  PointCloudView View() const
  {
    PointCloudView v;
    v.count = Size();
    v.xyzDouble = xyz.data();
    v.color8 = rgb.empty() ? nullptr : rgb.data();
    v.colorComponents = 3;
    v.scalar = scalar.empty() ? nullptr : scalar.data();
    v.reflectivity = reflectivity.empty() ? nullptr : reflectivity.data();
    v.refraction = refraction.empty() ? nullptr : refraction.data();
    v.normal = normal.empty() ? nullptr : normal.data();
    return v;
  }
};

inline Cloud UniformCloud(std::size_t n, std::uint64_t seed, double lo = -1.0, double hi = 1.0)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  Cloud c;
  for (std::size_t i = 0; i < n; ++i)
  {
    c.Add(u(rng), u(rng), u(rng), rng);
  }
  return c;
}

// `clusters` tight clusters of 8 points, `spread` wide, at random places in
// the unit cube: no level holds many lone points until they split, so the
// automatic depth lands deep (level 17 for a spread of 1e-5, 300 clusters,
// seed 47).
inline Cloud TightClusters(int clusters, double spread, std::uint64_t seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cloud c;
  for (int k = 0; k < clusters; ++k)
  {
    const double x = u(rng), y = u(rng), z = u(rng);
    for (int i = 0; i < 8; ++i)
    {
      c.Add(x + spread * u(rng), y + spread * u(rng), z + spread * u(rng), rng);
    }
  }
  return c;
}

// The octree `engine` builds from `points` at `depth` (0: chosen from the
// data), copied to the host for a test to inspect or trace.
inline HostOctree BuildOnHost(Engine& engine, const PointCloudView& points, const BuildOptions& options)
{
  engine.Build(points, options);
  HostOctree t;
  engine.CopyToHost(t);
  return t;
}

inline HostOctree BuildOnHost(Engine& engine, const PointCloudView& points, int depth)
{
  BuildOptions options;
  options.depth = depth;
  return BuildOnHost(engine, points, options);
}

inline Cloud GaussianClusters(std::size_t n, std::uint64_t seed)
{
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const double centres[4][3] = { { 0, 0, 0 }, { 10, 2, -3 }, { -5, 8, 1 }, { 3, -7, 6 } };
  const double sigma[4] = { 1.0, 0.2, 2.5, 0.05 };
  Cloud c;
  for (std::size_t i = 0; i < n; ++i)
  {
    const int k = static_cast<int>(i % 4);
    c.Add(centres[k][0] + sigma[k] * g(rng), centres[k][1] + sigma[k] * g(rng), centres[k][2] + sigma[k] * g(rng), rng);
  }
  return c;
}

// The fixture of every backend-parametrised suite: CUDA cases skip, saying
// why, where no GPU is usable.
class BackendTest : public ::testing::TestWithParam<Backend>
{
protected:
  void SetUp() override
  {
    const std::string why = GetParam() == Backend::CUDA ? CudaSkipReason() : std::string();
    if (!why.empty())
    {
      GTEST_SKIP() << why;
    }
    engine = CreateEngine(GetParam());
  }
  std::unique_ptr<Engine> engine;
};

inline std::string BackendName(const ::testing::TestParamInfo<Backend>& info)
{
  return ToString(info.param);
}

// Brute force: every point's cell computed here with a bit-by-bit Morton
// interleave, then per level a map from key prefix to the points under it.
struct ReferenceNode
{
  std::uint32_t count = 0;
  double sum[10] = {}; // r g b a scalar reflectivity refraction nx ny nz
  std::uint8_t childMask = 0;
};

inline std::uint64_t ReferenceKey(const RootCube& cube, const double p[3])
{
  std::uint64_t cell[3];
  for (int a = 0; a < 3; ++a)
  {
    const double g = std::floor((p[a] - cube.origin[a]) / cube.size * 2097152.0);
    EXPECT_GE(g, 0.0) << "point outside the root cube";
    EXPECT_LT(g, 2097152.0) << "point outside the root cube";
    cell[a] = static_cast<std::uint64_t>(g);
  }
  std::uint64_t key = 0;
  for (int bit = 0; bit < 21; ++bit)
  {
    for (int a = 0; a < 3; ++a)
    {
      key |= ((cell[a] >> bit) & 1u) << (3 * bit + a);
    }
  }
  return key;
}

inline std::vector<std::map<std::uint64_t, ReferenceNode>> ReferenceLevels(const Cloud& c, const RootCube& cube,
  int depth)
{
  std::vector<std::map<std::uint64_t, ReferenceNode>> levels(depth + 1);
  for (std::size_t i = 0; i < c.Size(); ++i)
  {
    const std::uint64_t key = ReferenceKey(cube, &c.xyz[3 * i]);
    double v[10] = { 0, 0, 0, 1.0, c.scalar.empty() ? 0.0 : c.scalar[i],
      c.reflectivity.empty() ? 0.0 : c.reflectivity[i], c.refraction.empty() ? 0.0 : c.refraction[i], 0, 0, 0 };
    for (int k = 0; k < 3 && !c.rgb.empty(); ++k)
    {
      v[k] = c.rgb[3 * i + k] / 255.0;
    }
    const double nx = c.normal.empty() ? 0.0 : c.normal[3 * i];
    const double ny = c.normal.empty() ? 0.0 : c.normal[3 * i + 1];
    const double nz = c.normal.empty() ? 0.0 : c.normal[3 * i + 2];
    const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
    if (len > 0)
    {
      v[7] = nx / len;
      v[8] = ny / len;
      v[9] = nz / len;
    }
    for (int l = 0; l <= depth; ++l)
    {
      const std::uint64_t prefix = key >> (3 * (21 - l));
      ReferenceNode& node = levels[l][prefix];
      ++node.count;
      for (int s = 0; s < 10; ++s)
      {
        node.sum[s] += v[s];
      }
      if (l > 0)
      {
        levels[l - 1][prefix >> 3].childMask |= static_cast<std::uint8_t>(1u << (prefix & 7u));
      }
    }
  }
  return levels;
}

// Checks an engine's octree node by node against the brute-force reference.
inline void ExpectMatchesReference(const HostOctree& t, const Cloud& c)
{
  ASSERT_GE(t.depth, 1);
  ASSERT_LE(t.depth, 21);
  const auto levels = ReferenceLevels(c, t.cube, t.depth);
  ASSERT_EQ(t.levelBegin.size(), 23u);
  std::size_t total = 0;
  for (int l = 0; l <= t.depth; ++l)
  {
    ASSERT_EQ(t.levelBegin[l + 1] - t.levelBegin[l], levels[l].size()) << "level " << l;
    total += levels[l].size();
  }
  ASSERT_EQ(t.NodeCount(), total);
  // Eight nodes' masks to a word, the last word's spare bytes zero; one
  // first child per group of eight (Attributes.h).
  ASSERT_EQ(t.childMasks.size(), (total + 7) / 8);
  ASSERT_EQ(t.childBase.size(), (total + 7) / 8);
  const std::size_t used = 1 + (total - 1) % 8;
  if (used < 8)
  {
    EXPECT_EQ(t.childMasks.back() >> (8 * used), 0u) << "spare bytes of the last word";
  }
  ASSERT_EQ(t.scalar.empty(), c.scalar.empty());
  if (!c.scalar.empty())
  {
    // The scalars' codes are relative to their range (Scalar16.h).
    const auto [lo, hi] = std::minmax_element(c.scalar.begin(), c.scalar.end());
    EXPECT_EQ(t.scalarRange.lo, *lo);
    EXPECT_EQ(t.scalarRange.hi, *hi);
  }
  for (int l = 0; l <= t.depth; ++l)
  {
    std::uint32_t n = t.levelBegin[l];
    for (const auto& [key, ref] : levels[l])
    {
      SCOPED_TRACE("level " + std::to_string(l) + " node " + std::to_string(n));
      ASSERT_EQ(t.Key(n), key);
      ASSERT_EQ(t.pointCount[n], ref.count);
      ASSERT_EQ(ChildMaskOf(t, n), ref.childMask);
      if (l == t.depth)
      {
        EXPECT_EQ(FirstChildOf(t, n), t.NodeCount()) << "a leaf's children would follow every node";
      }
      else
      {
        const std::uint32_t f = FirstChildOf(t, n);
        ASSERT_GE(f, t.levelBegin[l + 1]);
        ASSERT_LT(f, t.levelBegin[l + 2]);
        EXPECT_EQ(t.Key(f) >> 3, key);
        EXPECT_TRUE(f == t.levelBegin[l + 1] || (t.Key(f - 1) >> 3) != key) << "first child is not the first";
      }
      const double inv = 1.0 / ref.count;
      // Means of float data, a leaf's points summed in double and an inner
      // node's children in float (ReduceChildren): ~1e-7 relative a level.
      const float tol = 2e-6f;
      ASSERT_EQ(t.color8.empty(), c.rgb.empty());
      ASSERT_TRUE(t.color.empty()) << "8-bit colours are kept as 8-bit";
      if (!t.color8.empty())
      {
        // Stored as bytes (Attributes.h): a leaf's within half a step of
        // its mean, each level up half a step more at most.
        const Rgba color = ToRgba(t.color8[n]);
        const double bound = ColourErrorBound(t.depth, l) + tol;
        EXPECT_NEAR(color.r, ref.sum[0] * inv, bound);
        EXPECT_NEAR(color.g, ref.sum[1] * inv, bound);
        EXPECT_NEAR(color.b, ref.sum[2] * inv, bound);
        EXPECT_EQ(color.a, 1.0f);
      }
      if (!t.scalar.empty())
      {
        // 16 bits over the range, rounded per level; 5e-5 for the float
        // rounding of means of scalars that span 100.
        EXPECT_NEAR(t.Scalar(n), ref.sum[4] * inv, ScalarErrorBound(t.scalarRange, t.depth, l) + 5e-5);
      }
      ASSERT_EQ(t.reflectivity.empty(), c.reflectivity.empty());
      if (!t.reflectivity.empty())
      {
        // The points' values in Scalar16's unit steps (Attributes.h's
        // UnitInput), each within half a step; their means in float.
        EXPECT_NEAR(t.reflectivity[n], ref.sum[5] * inv, 0.5 / kScalarSteps + tol);
      }
      ASSERT_EQ(t.refraction.empty(), c.refraction.empty());
      if (!t.refraction.empty())
      {
        EXPECT_NEAR(t.refraction[n], ref.sum[6] * inv, 4 * tol);
      }
      ASSERT_EQ(t.normal.empty(), c.normal.empty());
      if (!t.normal.empty())
      {
        // Stored on the octahedron (OctahedralNormal.h), rounded per level.
        const Vec3d stored = ToDouble(DecodeNormal(t.normal[n]));
        const Vec3d exact{ ref.sum[7] * inv, ref.sum[8] * inv, ref.sum[9] * inv };
        EXPECT_LE(Length(stored - exact), NormalErrorBound(t.depth, l) + tol) << "node " << n << " level " << l;
      }
      ++n;
    }
  }
}

// Two octrees with the same topology and the same means: exactly (two
// backends' builds of the same points), or within float rounding, 1e-5
// (means an update adjusted by deltas against fresh ones; rounded means are
// never adjusted). Every node array of Attributes.h is compared.
inline void ExpectSameOctree(const HostOctree& a, const HostOctree& b, bool exact = false)
{
  ASSERT_EQ(a.depth, b.depth);
  ASSERT_EQ(a.scalarRange.lo, b.scalarRange.lo);
  ASSERT_EQ(a.scalarRange.hi, b.scalarRange.hi);
  ASSERT_EQ(a.levelBegin, b.levelBegin);
  ASSERT_EQ(a.attributes, b.attributes);
  ForEachNodeArray([&](auto array) {
    using A = decltype(array);
    const auto& x = A::Of(a);
    const auto& y = A::Of(b);
    if (::testing::Test::HasFatalFailure())
    {
      return;
    }
    ASSERT_EQ(x.size(), y.size()) << "node " << A::kLabel;
    if constexpr (A::kBit == 0)
    {
      ASSERT_EQ(x, y) << "node " << A::kLabel;
    }
    else
    {
      using Value = AttributeValue<typename A::Type>;
      for (std::size_t n = 0; n < x.size(); ++n)
      {
        typename Value::Slot u[Value::kSlots], v[Value::kSlots];
        Value::ToSlots(x[n], u);
        Value::ToSlots(y[n], v);
        for (int k = 0; k < Value::kSlots; ++k)
        {
          const double tol = exact ? 0.0 : 1e-5;
          ASSERT_NEAR(double(u[k]), double(v[k]), tol) << "node " << A::kLabel << " slot " << k << " of node " << n;
        }
      }
    }
  });
}

// Builds c at `depth` (0: automatic) and checks the octree and the build
// statistics against the brute-force reference.
inline void BuildAndCompare(Engine& engine, const Cloud& c, int depth)
{
  BuildOptions options;
  options.depth = depth;
  const BuildStats stats = engine.Build(c.View(), options);
  HostOctree t;
  engine.CopyToHost(t);
  if (depth)
  {
    EXPECT_EQ(t.depth, depth);
  }
  EXPECT_EQ(stats.depth, t.depth);
  EXPECT_EQ(stats.nodes, t.NodeCount());
  EXPECT_EQ(stats.points, c.Size());
  ExpectMatchesReference(t, c);
}

// The automatic depth rule (DepthChoice.h): at the chosen depth at least
// half of the non-empty leaves hold one point, one level up fewer do, unless
// deeper levels would separate nothing more.
inline void ExpectDepthRule(const HostOctree& t, const Cloud& c)
{
  const auto levels = ReferenceLevels(c, t.cube, 21);
  auto singles = [&](int l) {
    std::size_t s = 0;
    for (const auto& [key, node] : levels[l])
    {
      s += node.count == 1;
    }
    return s;
  };
  const bool separatesNothingDeeper = levels[t.depth].size() == levels[21].size();
  EXPECT_TRUE(2 * singles(t.depth) >= levels[t.depth].size() || separatesNothingDeeper) << "depth " << t.depth;
  if (t.depth > 1)
  {
    EXPECT_LT(2 * singles(t.depth - 1), levels[t.depth - 1].size()) << "depth " << t.depth;
    EXPECT_LT(levels[t.depth - 1].size(), levels[21].size());
  }
}
}
