// The shared pieces under the driver and the renderer, against plain
// references: the CPU device's primitives and the driver's run starts and
// first-failure search (DeviceChecks.h, which TestCudaDevice.cu runs on the
// GPU; here whatever the thread count, the same results), the level
// sizes, the attribute list's slots, the kept threads of ChunkWorkers, the
// CUDA backend's staged pieces, and the vector vocabulary's rounding.
#include "DeviceChecks.h"

#include <octoray/CpuDevice.h>
#include <octoray/OctreeDriver.h>
#include <octoray/RenderKernels.h>
#include <octoray/StagingPieces.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <thread>

using namespace octoray;

namespace
{
// Sizes on both sides of the thresholds where loops start splitting.
const std::size_t kSizes[] = { 0, 1, 5, kParallelForMinItems + 3, kParallelPassMinItems + 17 };

// check(n, device) for every size on devices of 1, 2 and 3 threads: the
// results must not depend on how the work is split.
template <typename Check>
void OnEverySplit(Check&& check)
{
  for (std::size_t n : kSizes)
  {
    for (int threads : { 1, 2, 3 })
    {
      SCOPED_TRACE("n " + std::to_string(n) + ", threads " + std::to_string(threads));
      CpuDevice d;
      d.threads = threads;
      check(n, d);
    }
  }
}
}

TEST(CpuDevice, ForEachAndReduceCoverEveryItemOnce)
{
  OnEverySplit([](std::size_t n, CpuDevice& d) { checks::ExpectLoopsCoverEveryItemOnce(d, n); });
}

// The kept threads split each pass as ParallelChunks does, call every
// chunk (empty ones too) on as many threads, over many passes, and pass on
// the first chunk's exception once all have run.
TEST(ChunkWorkers, SplitLikeParallelChunksPassAfterPass)
{
  for (int chunks : { 1, 2, 3, 5 })
  {
    ChunkWorkers workers(chunks);
    ASSERT_EQ(workers.Chunks(), chunks);
    for (std::size_t n : { 0, 1, 4, 1000, 1001 })
    {
      SCOPED_TRACE("chunks " + std::to_string(chunks) + ", n " + std::to_string(n));
      std::vector<int> seen(n, 0);
      std::vector<std::pair<std::size_t, std::size_t>> ranges(chunks, { 1, 0 });
      std::vector<std::thread::id> ids(chunks);
      workers.Run(n, [&](std::size_t begin, std::size_t end, int c) {
        ranges[c] = { begin, end };
        ids[c] = std::this_thread::get_id();
        for (std::size_t i = begin; i < end; ++i)
        {
          seen[i] += 1;
        }
      });
      EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<long>(n));
      for (int c = 0; c < chunks; ++c)
      {
        EXPECT_EQ(ranges[c].first, n * c / chunks) << "chunk " << c;
        EXPECT_EQ(ranges[c].second, n * (c + 1) / chunks) << "chunk " << c;
      }
      EXPECT_EQ(ids[0], std::this_thread::get_id());
      std::sort(ids.begin(), ids.end());
      EXPECT_EQ(std::unique(ids.begin(), ids.end()) - ids.begin(), chunks);
    }
    std::vector<int> ran(chunks, 0);
    try
    {
      workers.Run(std::size_t(100), [&](std::size_t, std::size_t, int c) {
        ran[c] = 1;
        if (c > 0)
        {
          throw Error("chunk " + std::to_string(c));
        }
      });
      EXPECT_EQ(chunks, 1) << "no chunk threw";
    }
    catch (const Error& e)
    {
      EXPECT_STREQ(e.what(), "chunk 1");
    }
    EXPECT_EQ(std::count(ran.begin(), ran.end(), 1), chunks);
  }
}

// The CUDA backend's staged copy lays a copy's arrays end to end, cuts the
// run into pieces and deals them to its threads as each becomes free
// (StagingPieces.h). For runs of one to four arrays of many sizes (empty
// ones among them, some made from twice their bytes and cut in pieces half
// as long), cut for 1 to kMaxStagingThreads threads: the pieces cover every
// array once, in order; none is empty or larger than a page-locked buffer;
// each starts at a whole multiple of kPieceAlignment into its array, so
// that no piece splits a point; and the bytes the pieces read only grow
// along the run (each piece costs the copy time beyond its bytes:
// PieceBytes), a piece that reads fewer than one before it the last of its
// array, cut where the array ends. Dealt to as many threads (ChunkWorkers), every piece is taken
// once, and each thread's buffers alternate.
TEST(StagingPieces, CoverEveryArrayInGrowingPiecesWithinTheBuffers)
{
  using namespace octoray::cuda;
  std::mt19937_64 rng(7);
  std::vector<std::vector<std::size_t>> runs = { { 1 }, { kPieceAlignment }, { kEdgePiece + 1 }, { kStagingPiece },
    { 3 * kStagingPiece + 5 }, { 0, 5 }, { 5, 0 }, { 120000000, 30000000, 40000000 },
    { 1200000000, 300000000, 400000000 }, { 120000000, 30000000, 20000000 } };
  std::vector<std::vector<bool>> halves(runs.size());
  halves.back() = { false, false, true }; // a build's positions, colours and reflectivity codes
  for (int i = 0; i < 300; ++i)
  {
    std::vector<std::size_t> run(1 + rng() % 4);
    std::vector<bool> halved;
    for (std::size_t& bytes : run)
    {
      bytes = rng() % 8 == 0 ? rng() % 3 : std::size_t(1) + rng() % (std::size_t(1) << (10 + rng() % 21));
      halved.push_back(rng() % 3 == 0);
    }
    runs.push_back(run);
    halves.push_back(halved);
  }
  for (int threads = 1; threads <= kMaxStagingThreads; threads += 3)
  {
    ChunkWorkers workers(threads);
    for (std::size_t r = 0; r < runs.size(); ++r)
    {
      const std::vector<std::size_t>& arrays = runs[r];
      StagingRun run(arrays, halves[r]);
      SCOPED_TRACE("first array " + std::to_string(arrays[0]) + " bytes of " + std::to_string(arrays.size()) +
        ", threads " + std::to_string(threads));
      const std::vector<Piece> pieces = CutPieces(run, threads);
      std::vector<std::size_t> covered(arrays.size(), 0);
      int bad = 0, shrunk = 0;
      std::size_t largest = 0; // of the pieces so far not cut where their array ends
      for (std::size_t k = 0; k < pieces.size(); ++k)
      {
        const Piece& p = pieces[k];
        const bool inOrder = k == 0 || p.array > pieces[k - 1].array ||
          (p.array == pieces[k - 1].array && p.offset == pieces[k - 1].offset + pieces[k - 1].bytes);
        bad += !inOrder || p.array >= arrays.size() || p.bytes == 0 || p.bytes > kStagingPiece ||
          p.offset + p.bytes > arrays[p.array] || p.offset % kPieceAlignment != 0;
        const bool endsItsArray = p.array < arrays.size() && p.offset + p.bytes == arrays[p.array];
        // A piece half as long reads twice its bytes, up to kPieceAlignment
        // short of a whole piece: its length stays a multiple of that.
        const bool halved = p.array < arrays.size() && run.halfPieces[p.array];
        const std::size_t read = halved ? 2 * p.bytes + kPieceAlignment : p.bytes;
        shrunk += !endsItsArray && read < largest;
        largest = std::max(largest, endsItsArray ? 0 : halved ? 2 * p.bytes : p.bytes);
        covered[p.array] += p.bytes;
      }
      EXPECT_EQ(bad, 0);
      EXPECT_EQ(shrunk, 0);
      for (std::size_t a = 0; a < arrays.size(); ++a)
      {
        EXPECT_EQ(covered[a], arrays[a]) << "array " << a;
      }

      PieceDealer dealer(pieces);
      std::vector<std::vector<std::pair<std::size_t, std::size_t>>> taken(threads);
      std::vector<int> badBuffers(threads, 0);
      workers.Run(threads, [&](std::size_t t, std::size_t, int) {
        int turn = 0;
        dealer.Take([&](const Piece& p, int buffer) {
          badBuffers[t] += buffer != turn++ % 2;
          taken[t].emplace_back(p.array, p.offset);
        });
      });
      std::vector<std::pair<std::size_t, std::size_t>> all, expected;
      for (const auto& mine : taken)
      {
        all.insert(all.end(), mine.begin(), mine.end());
      }
      for (const Piece& p : pieces)
      {
        expected.emplace_back(p.array, p.offset);
      }
      std::sort(all.begin(), all.end());
      EXPECT_EQ(all, expected);
      EXPECT_EQ(std::accumulate(badBuffers.begin(), badBuffers.end(), 0), 0);
    }
  }
}

// On the CPU the loops read a caller's arrays where they are: nothing is
// on its way, and whenReduced never runs.
TEST(CpuDevice, StageReducedCopiesReducesAndCallsBack)
{
  OnEverySplit([](std::size_t n, CpuDevice& d) { checks::ExpectStageReducedCopiesReducesAndCallsBack(d, n, false); });
}

TEST(CpuDevice, SmallLevelsReduceEachLevelAfterTheOneBelow)
{
  OnEverySplit([](std::size_t n, CpuDevice& d) { checks::ExpectSmallLevelsReduceEachLevelAfterTheOneBelow(d, n); });
}

TEST(CpuDevice, SelectKeepsOrderAndCounts)
{
  OnEverySplit([](std::size_t n, CpuDevice& d) { checks::ExpectSelectKeepsOrderAndCounts(d, n); });
}

TEST(CpuDevice, NestedListsHoldEachItemFromItsFirstListOn)
{
  OnEverySplit([](std::size_t n, CpuDevice& d) { checks::ExpectNestedListsHoldEachItemFromItsFirstListOn(d, n); });
}

TEST(CpuDevice, SortsAreStable)
{
  OnEverySplit([](std::size_t n, CpuDevice& d) { checks::ExpectSortsStable(d, n, n + d.threads); });
}

TEST(CpuDevice, RunStartsAndFirstFailedStep)
{
  OnEverySplit([](std::size_t n, CpuDevice& d) { checks::ExpectRunStartsAndFirstFailedStep(d, n); });
}

// Level sizes from a newNode histogram; past the 32-bit node index, an
// error naming the depth, before any array is reserved. The first key, 7
// that share only the root with their predecessors and 400 M that share 10
// levels: 8 nodes at each level from 1 to 10, 400 M + 8 from 11 on.
TEST(LevelBegins, FollowTheHistogramAndRefuseMoreNodesThanTheIndexHolds)
{
  std::uint64_t newNode[kDepthHistogramBins] = {};
  newNode[1] = 7;             // bin 0: 7 keys start a node at every level from 1 on
  newNode[11] = 400000000ull; // bin 10
  std::uint32_t levelBegin[kMaxLevel + 2];
  SetLevelBegins(newNode, 20, levelBegin);
  std::uint64_t expected = 0;
  for (int l = 0; l <= kMaxLevel + 1; ++l)
  {
    EXPECT_EQ(levelBegin[l], expected) << "level " << l;
    expected += l > 20 ? 0 : l == 0 ? 1 : l <= 10 ? 8 : 400000008ull;
  }
  EXPECT_EQ(expected, 4000000161ull); // below 2^32 - 1
  try
  {
    SetLevelBegins(newNode, 21, levelBegin);
    ADD_FAILURE() << "no error";
  }
  catch (const Error& e)
  {
    EXPECT_STREQ(e.what(), "octoray: an octree of depth 21 over these points would hold 4400000169 nodes or more, "
                           "past the 32-bit node index; choose a shallower depth");
  }
}

// The attribute list's slots are laid out in its order, every bit its own.
TEST(Attributes, SlotsAndBitsFollowTheList)
{
  int slot = 0;
  unsigned bits = 0;
  ForEachAttribute([&](auto a) {
    using A = decltype(a);
    EXPECT_EQ(A::kSlot, slot) << A::kLabel;
    slot += AttributeValue<typename A::Type>::kSlots;
    EXPECT_EQ(bits & A::kBit, 0u) << A::kLabel;
    bits |= A::kBit;
  });
  EXPECT_EQ(slot, kSlotCount);
  EXPECT_EQ(bits, (1u << kAttributeCount) - 1);
  const Rgba c{ 0.25f, 0.5f, 0.75f, 1.0f };
  float v[4];
  AttributeValue<Rgba>::ToSlots(c, v);
  EXPECT_EQ(v[2], 0.75f);
  const double sum[4] = { 1.0, 2.0, 3.0, 4.0 };
  const Rgba mean = AttributeValue<Rgba>::Mean(sum, 0.5);
  EXPECT_EQ(mean.r, 0.5f);
  EXPECT_EQ(mean.a, 2.0f);
  // 8-bit colours are summed as whole bytes and stored as bytes, rounded to
  // nearest (halves up) and clamped to 255.
  const std::uint64_t bytes[4] = { 0, 255, 128, 4 * 255 };
  const Rgba8 mean8 = AttributeValue<Rgba8>::Mean(bytes, 0.5);
  EXPECT_EQ(mean8.r, 0);
  EXPECT_EQ(mean8.g, 128) << "127.5 rounds up";
  EXPECT_EQ(mean8.b, 64);
  EXPECT_EQ(mean8.a, 255);
  std::uint32_t whole[4];
  AttributeValue<Rgba8>::ToSlots(Rgba8{ 0, 51, 255, 128 }, whole);
  EXPECT_EQ(whole[1], 51u);
  EXPECT_EQ(whole[2], 255u);
  // Sums of bytes times weights beside double sums: in 64-bit integers,
  // exact, a weight of -1 too (modulo 2^64), and only the byte entries;
  // floats in double. Beside float sums, the bytes in float.
  SlotSums<double> sums;
  sums.Add(kSlotColor8, whole[2], 3u);
  sums.Add(kSlotColor8, whole[1], -1);
  sums.Add(kSlotReflectivity, 0.5f, 4u);
  EXPECT_EQ(sums.whole[kSlotColor8], 3u * 255u - 51u);
  EXPECT_EQ(sums.real[kSlotColor8], 0.0);
  EXPECT_EQ(sums.real[kSlotReflectivity], 2.0);
  static_assert(std::is_same<SlotSums<double>::Whole, std::uint64_t>::value, "exact sums of a leaf's bytes");
  static_assert(std::is_same<SlotSums<float>::Whole, float>::value, "an inner node's bytes in float");
  EXPECT_EQ(sums.Of(Attribute<kAttributeColor8>()), sums.whole + kSlotColor8);
  EXPECT_EQ(sums.Of(Attribute<kAttributeReflectivity>()), sums.real + kSlotReflectivity);
  const std::uint64_t thirds[4] = { 10, 11, 765, 0 };
  const Rgba8 third = AttributeValue<Rgba8>::Mean(thirds, 1.0 / 3.0);
  EXPECT_EQ(third.r, 3) << "3.33 rounds down";
  EXPECT_EQ(third.g, 4) << "3.67 rounds up";
  EXPECT_EQ(third.b, 255);
  EXPECT_EQ(third.a, 0);
  EXPECT_FALSE(AttributeValue<Rgba>::kRounded);
  EXPECT_TRUE(AttributeValue<Rgba8>::kRounded);
  EXPECT_EQ(kRoundedAttributes, static_cast<unsigned>(kHasColor8 | kHasScalar | kHasNormal));
}

// 16-bit scalars (Scalar16.h): within half a step of the range anywhere in
// it, also far from zero; the ends exact; one value alone exact; -inf, +inf
// and NaN kept, and means with them behave as float means do.
TEST(Scalar16, ErrorsStayWithinHalfAStepOfTheRange)
{
  std::mt19937_64 rng(12);
  for (const ScalarRange range : { ScalarRange{ -1024.0f, 3071.0f }, ScalarRange{ 1000.0f, 1000.5f } })
  {
    EXPECT_EQ(DecodeScalar(range, EncodeUnitScalar(range.ToUnit(range.lo))), range.lo);
    EXPECT_EQ(DecodeScalar(range, EncodeUnitScalar(range.ToUnit(range.hi))), range.hi);
    std::uniform_real_distribution<float> value(range.lo, range.hi);
    double worst = 0.0;
    for (int i = 0; i < 100000; ++i)
    {
      const float x = value(rng);
      worst = std::max(worst, std::fabs(double(DecodeScalar(range, EncodeUnitScalar(range.ToUnit(x)))) - x));
    }
    // Half a step, and decoding's float rounding. Where the steps are finer
    // than the floats (1000 to 1000.5), every float decodes to itself.
    EXPECT_LE(worst, range.HalfStep() + range.DecodingError()) << range.lo << " to " << range.hi;
    if (range.HalfStep() > range.DecodingError())
    {
      EXPECT_GT(worst, 0.5 * range.HalfStep()) << "the bound is not loose";
    }
    else
    {
      EXPECT_EQ(worst, 0.0) << "floats coarser than the steps decode to themselves";
    }
  }
  const ScalarRange one{ 7.5f, 7.5f };
  EXPECT_EQ(DecodeScalar(one, EncodeUnitScalar(one.ToUnit(7.5f))), 7.5f);
  const ScalarRange r{ 0.0f, 1.0f };
  for (float special : { -INFINITY, INFINITY })
  {
    EXPECT_EQ(DecodeScalar(r, EncodeUnitScalar(r.ToUnit(special))), special);
  }
  EXPECT_TRUE(std::isnan(DecodeScalar(r, EncodeUnitScalar(r.ToUnit(NAN)))));
  // A mean with +inf in it is +inf, with both infinities NaN.
  float v[2];
  AttributeValue<Scalar16>::ToSlots(EncodeUnitScalar(INFINITY), v);
  AttributeValue<Scalar16>::ToSlots(EncodeUnitScalar(0.25f), v + 1);
  const double withInf[1] = { double(v[0]) + v[1] };
  EXPECT_EQ(AttributeValue<Scalar16>::Mean(withInf, 0.5).code, kScalarPlusInfinity);
  const double bothInf[1] = { double(INFINITY) + double(-INFINITY) };
  EXPECT_EQ(AttributeValue<Scalar16>::Mean(bothInf, 0.5).code, kScalarNaN);
}

// The host's loop of codes (EncodeUnitScalars, eight values at a time)
// makes the codes that EncodeUnitScalar makes of each value, and those
// round as the floor of the scaled value and a half: finite values across
// 0..1 and beyond, every seventh step's midpoint and its neighbours (a
// length that leaves a tail of six), then values with NaN and infinities
// among them, which the loop codes again one at a time.
TEST(Scalar16, CodesOfManyValuesAreTheCodesOfEach)
{
  std::vector<float> finite;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> around(-0.25f, 1.25f);
  for (int i = 0; i < 100000; ++i)
  {
    finite.push_back(around(rng));
  }
  for (int step = 0; step < kScalarSteps; step += 7)
  {
    const float middle = (step + 0.5f) / kScalarSteps;
    finite.insert(finite.end(), { std::nextafter(middle, 0.0f), middle, std::nextafter(middle, 1.0f) });
  }
  ASSERT_EQ(finite.size() % 8, 6u);
  for (const std::vector<float>& values : { finite, checks::UnitValues(70001) })
  {
    std::vector<std::uint16_t> codes(values.size());
    EncodeUnitScalars(values.data(), values.size(), codes.data());
    EXPECT_EQ(codes, checks::UnitCodesOf(values));
    for (std::size_t i = 0; i < values.size(); ++i)
    {
      if (std::isfinite(values[i]))
      {
        const float clamped = std::min(std::max(values[i], 0.0f), 1.0f);
        ASSERT_EQ(codes[i], static_cast<std::uint16_t>(std::floor(clamped * kScalarSteps + 0.5f))) << values[i];
      }
    }
  }
}

// Normals on the octahedron (OctahedralNormal.h): the axes exactly, every
// direction within the stated angle, every vector no longer than 1 within
// the stated distance, a stored vector unmoved when stored again.
TEST(OctahedralNormal, ErrorsStayWithinTheirBounds)
{
  for (int a = 0; a < 3; ++a)
  {
    for (float sign : { -1.0f, 1.0f })
    {
      Vec3f axis{ 0.0f, 0.0f, 0.0f };
      axis[a] = sign;
      const Vec3f back = DecodeNormal(EncodeNormal(axis));
      EXPECT_EQ(back.x, axis.x);
      EXPECT_EQ(back.y, axis.y);
      EXPECT_EQ(back.z, axis.z);
    }
  }
  EXPECT_EQ(EncodeNormal(Vec3f{ 0.0f, 0.0f, 0.0f }).bits, 0u);
  EXPECT_EQ(EncodeNormal(Vec3f{ 0.0f, 0.0f, 0.49f / kLengthSteps }).bits, 0u) << "under half a length step";
  EXPECT_NEAR(Length(DecodeNormal(EncodeNormal(Vec3f{ 0.0f, 0.51f / kLengthSteps, 0.0f }))), 1.0 / kLengthSteps,
    1e-7);
  std::mt19937_64 rng(11);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  double worstAngle = 0.0, worstDistance = 0.0;
  int recoded = 0;
  for (int i = 0; i < 200000; ++i)
  {
    Vec3f d = Normalize(Vec3f{ gauss(rng), gauss(rng), gauss(rng) });
    if (i % 4 == 0)
    {
      d[i % 3] = 0.0f; // on a fold line or the equator
      d = Normalize(d);
    }
    const Vec3d back = ToDouble(DecodeNormal(EncodeNormal(d)));
    worstAngle = std::max(worstAngle, std::acos(std::min(1.0, Dot(back, ToDouble(d)) / Length(back))));
    const Vec3f v = d * unit(rng);
    worstDistance = std::max(worstDistance, Length(ToDouble(DecodeNormal(EncodeNormal(v))) - ToDouble(v)));
    // The square's outer edge holds each direction twice, so a code may
    // re-encode to its twin, but never to another vector.
    const Vec3f once = DecodeNormal(EncodeNormal(v));
    const Vec3f twice = DecodeNormal(EncodeNormal(once));
    recoded += !(once.x == twice.x && once.y == twice.y && once.z == twice.z);
  }
  EXPECT_EQ(recoded, 0) << "vectors that move when stored again";
  EXPECT_LE(worstAngle, kOctDirectionError);
  EXPECT_LE(worstDistance, kOctVectorError);
  // The bounds are not loose by much: measured against stated.
  EXPECT_GT(worstAngle, 0.25 * kOctDirectionError);
  EXPECT_GT(worstDistance, 0.25 * kOctVectorError);
  std::printf("octahedral normals: worst angle %.3g rad (bound %.3g), worst distance %.3g (bound %.3g)\n", worstAngle,
    kOctDirectionError, worstDistance, kOctVectorError);
}

// The vector operators round like the per-component expressions they stand
// for (the backends' pictures depend on it): products and sums in the
// written order, division by a length as a division.
TEST(VecMath, OperatorsRoundLikeTheComponentExpressions)
{
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  for (int i = 0; i < 10000; ++i)
  {
    const Vec3f a{ u(rng), u(rng), u(rng) }, b{ u(rng), u(rng), u(rng) };
    const float s = u(rng);
    EXPECT_EQ(Dot(a, b), a.x * b.x + a.y * b.y + a.z * b.z);
    const Vec3f r = a - 2.0f * s * b;
    EXPECT_EQ(r.y, a.y - 2.0f * s * b.y);
    const float len = std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
    const Vec3f n = Normalize(a);
    EXPECT_EQ(n.x, a.x / len);
    EXPECT_EQ(n.z, a.z / len);
    const Vec3d w = ToDouble(a) + double(s) * ToDouble(b);
    EXPECT_EQ(w.y, double(a.y) + double(s) * double(b.y));
    Vec3f m = a;
    m[1] = 7.0f;
    EXPECT_EQ(m.y, 7.0f);
    EXPECT_EQ(m[2], a.z);
  }
  EXPECT_EQ(Normalize(Vec3f{ 0, 0, 0 }).x, 0.0f);
  EXPECT_EQ(Clamp01(-0.5f), 0.0f);
  EXPECT_EQ(Clamp01(1.5), 1.0);
  EXPECT_EQ(Clamp01(0.25f), 0.25f);
  EXPECT_EQ(Clamp01(NAN), 0.0f);
  EXPECT_EQ(Clamp01(-0.0), 0.0);
}

TEST(VecMath, ChannelToByteRoundsToNearest)
{
  EXPECT_EQ(ChannelToByte(-1.0f), 0);
  EXPECT_EQ(ChannelToByte(2.0f), 255);
  EXPECT_EQ(ChannelToByte(0.5f / 255.0f), 1);
  EXPECT_EQ(ChannelToByte(0.49f / 255.0f), 0);
  EXPECT_EQ(ChannelToByte(127.5f / 255.0f), 128);
  // A byte read as a channel rounds back to itself (the leaf export of
  // 8-bit colours relies on it).
  for (int b = 0; b < 256; ++b)
  {
    const std::uint8_t byte = static_cast<std::uint8_t>(b);
    EXPECT_EQ(ToRgba8(ToRgba(Rgba8{ byte, 0, 255, byte })).r, byte);
  }
}

// One transfer-function lookup for node colours and projected values: the
// scalar range maps onto the table's entries, rounded to the nearest;
// outside it the ends; NaN the first entry.
TEST(VecMath, TransferLookupClampsAndRounds)
{
  FrameConstants f;
  const Rgba table[5] = { { 0, 0, 0, 0 }, { 1, 0, 0, 0 }, { 2, 0, 0, 0 }, { 3, 0, 0, 0 }, { 4, 0, 0, 0 } };
  f.transfer = table;
  f.transferSize = 5;
  f.transferRange[0] = -1.0f;
  f.transferRange[1] = 1.0f;
  EXPECT_EQ(TransferLookup(f, -1.0f).r, 0.0f);
  EXPECT_EQ(TransferLookup(f, 1.0f).r, 4.0f);
  EXPECT_EQ(TransferLookup(f, 0.0f).r, 2.0f);
  EXPECT_EQ(TransferLookup(f, 0.2f).r, 2.0f);
  EXPECT_EQ(TransferLookup(f, 0.3f).r, 3.0f);
  EXPECT_EQ(TransferLookup(f, -7.0f).r, 0.0f);
  EXPECT_EQ(TransferLookup(f, 9.0f).r, 4.0f);
  EXPECT_EQ(TransferLookup(f, NAN).r, 0.0f);
}
