#include <octoray/DepthChoice.h>
#include <octoray/Morton.h>
#include <octoray/RootCube.h>

#include <gtest/gtest.h>

#include <random>

using namespace octoray;

TEST(Morton, RoundTripsRandomAndExtremeCells)
{
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<std::uint32_t> cell(0, (1u << 21) - 1);
  for (int i = 0; i < 100000; ++i)
  {
    const std::uint32_t x = cell(rng), y = cell(rng), z = cell(rng);
    std::uint32_t dx, dy, dz;
    DecodeMorton(EncodeMorton(x, y, z), dx, dy, dz);
    ASSERT_EQ(dx, x);
    ASSERT_EQ(dy, y);
    ASSERT_EQ(dz, z);
  }
  const std::uint32_t top = (1u << 21) - 1;
  EXPECT_EQ(EncodeMorton(top, top, top), (1ull << 63) - 1);
  EXPECT_EQ(EncodeMorton(0, 0, 0), 0u);
  EXPECT_EQ(EncodeMorton(1, 0, 0), 1u);
  EXPECT_EQ(EncodeMorton(0, 1, 0), 2u);
  EXPECT_EQ(EncodeMorton(0, 0, 1), 4u);
  EXPECT_EQ(EncodeMorton(2, 0, 0), 8u);
}

// A key at a depth, made from the cell's top bits (in 32 bits down to
// depth 10), is the full-depth key without its triples below that depth.
TEST(Morton, KeysAtADepthAreTheFullKeysShifted)
{
  std::mt19937_64 rng(2);
  std::uniform_int_distribution<std::uint32_t> cell(0, (1u << 21) - 1);
  const std::uint32_t top = (1u << 21) - 1;
  for (int i = 0; i < 20000; ++i)
  {
    const std::uint32_t x = i ? cell(rng) : top, y = i ? cell(rng) : top, z = i ? cell(rng) : top;
    for (int depth = 0; depth <= kMaxLevel; ++depth)
    {
      ASSERT_EQ(EncodeMortonAt(x, y, z, depth), EncodeMorton(x, y, z) >> (3 * (kMaxLevel - depth)))
        << "cell " << x << " " << y << " " << z << " at depth " << depth;
    }
  }
}

TEST(Morton, KeysOrderLikeTheOctree)
{
  // A parent's key is its children's keys without their last triple.
  const std::uint64_t k = EncodeMorton(123456, 654321, 2000000);
  EXPECT_EQ(AncestorKey(k, 21), k);
  EXPECT_EQ(AncestorKey(k, 20), k >> 3);
  EXPECT_EQ(AncestorKey(k, 0), 0u);
  EXPECT_EQ(OctantOf(EncodeMorton(1, 1, 0)), 3);
}

TEST(RootCube, HoldsTheBoundsAndKeepsFarOffsetDetail)
{
  const double lo[3] = { 1e7, 1e7 + 5, 1e7 - 2 };
  const double hi[3] = { 1e7 + 1, 1e7 + 5.001, 1e7 - 2 };
  const RootCube cube = RootCube::FromBounds(lo, hi);
  std::uint32_t cl[3], ch[3];
  ASSERT_TRUE(cube.GridCell(lo[0], lo[1], lo[2], cl));
  ASSERT_TRUE(cube.GridCell(hi[0], hi[1], hi[2], ch));
  EXPECT_NEAR(cube.size, 1.0, 1e-5);
  // One millimetre at 1e7 is still ~2000 cells of 2^-21.
  std::uint32_t cm[3];
  ASSERT_TRUE(cube.GridCell(lo[0] + 0.001, lo[1], lo[2], cm));
  EXPECT_NEAR(static_cast<double>(cm[0] - cl[0]), 2097.152, 1.0);
  std::uint32_t out[3];
  EXPECT_FALSE(cube.GridCell(hi[0] + 0.01, hi[1], hi[2], out));
  EXPECT_FALSE(cube.GridCell(std::nan(""), hi[1], hi[2], out));
}

TEST(RootCube, DegenerateBoundsGetAUsableCube)
{
  const double p[3] = { 3, 4, 5 };
  const RootCube cube = RootCube::FromBounds(p, p);
  EXPECT_GT(cube.size, 0.0);
  std::uint32_t c[3];
  EXPECT_TRUE(cube.GridCell(3, 4, 5, c));
}

TEST(DepthChoice, SharedLevelsOfNeighbouringKeys)
{
  EXPECT_EQ(SharedLevels<std::uint64_t>(5, 5), 21);
  // Keys that differ only in the last triple share levels 0..20.
  EXPECT_EQ(SharedLevels<std::uint64_t>(8, 9), 20);
  // Keys that differ in the top triple share only the root.
  EXPECT_EQ(SharedLevels<std::uint64_t>(0, 1ull << 62), 0);
}

// Leaf keys of a depth (in 32 bits where they fit, as the build sorts
// them) share the levels their full-depth keys share; equal ones all 21.
TEST(DepthChoice, SharedLevelsOfLeafKeysAsOfTheirFullDepthKeys)
{
  std::mt19937_64 rng(11);
  for (int depth = 1; depth <= kMaxLevel; ++depth)
  {
    const int bits = 3 * depth;
    const int shift = 3 * kMaxLevel - bits;
    for (int k = 0; k < 300; ++k)
    {
      const std::uint64_t a = rng() >> (64 - bits);
      // Equal, one bit apart (any level), or unrelated.
      const std::uint64_t b = k % 3 == 0 ? a : k % 3 == 1 ? a ^ (1ull << (rng() % bits)) : rng() >> (64 - bits);
      const int full = SharedLevels(a << shift, b << shift);
      SCOPED_TRACE(testing::Message() << "depth " << depth << ", keys " << a << ", " << b);
      EXPECT_EQ(SharedLevels(a, b, depth), full);
      if (bits <= 32)
      {
        EXPECT_EQ(SharedLevels(static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b), depth), full);
      }
      EXPECT_EQ(full, a == b ? kMaxLevel : depth - 1 - (63 - __builtin_clzll(a ^ b)) / 3);
    }
  }
}

// After the provisional sort, keys of 13 levels where the occupied level-10
// cells hold 64 points or fewer on average, else full-depth keys; after the
// 13 levels' sort, full-depth keys whatever the cells hold.
TEST(DepthChoice, NextSortDepthByThePointsALevel10CellHolds)
{
  const std::uint64_t points = 6400;
  for (const std::uint64_t cells : { std::uint64_t(1), std::uint64_t(99), std::uint64_t(100), std::uint64_t(6400) })
  {
    std::uint64_t newNode[kDepthHistogramBins] = {};
    newNode[kProvisionalDepth] = cells - 1; // the first key starts the first cell
    ASSERT_EQ(NodesAtLevel(newNode, kProvisionalDepth), cells);
    SCOPED_TRACE(testing::Message() << cells << " cells of level 10");
    EXPECT_EQ(NextSortDepth(newNode, points, kProvisionalDepth), cells >= 100 ? kMiddleDepth : kMaxLevel);
    EXPECT_EQ(NextSortDepth(newNode, points, kMiddleDepth), kMaxLevel);
  }
}

#include <octoray/RenderKernels.h>

TEST(PortablePow, AgreesWithLibmToAFewUlps)
{
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<float> base(1e-6f, 1.0f), exponent(0.0f, 200.0f);
  for (int i = 0; i < 100000; ++i)
  {
    const float b = base(rng), e = exponent(rng);
    const double exact = std::pow(double(b), double(e));
    if (exact < 1e-30)
      continue;
    EXPECT_NEAR(PortablePow(b, e) / exact, 1.0, 2e-5) << b << "^" << e;
  }
  EXPECT_EQ(PortablePow(0.0f, 2.0f), 0.0f);
  EXPECT_NEAR(PortablePow(0.5f, 1.0f), 0.5f, 1e-7f);
  EXPECT_NEAR(PortablePow(1.0f, 1e4f), 1.0f, 1e-6f);
}
