// The device primitives under the build driver (OctreeDriver.h's device
// interface) against plain references, written once for both devices:
// TestDevice.cpp runs each check on the CPU device split over one to three
// threads, TestCudaDevice.cu on the GPU, at sizes that span its blocks and
// warp tiles. The arrays a primitive reads and writes live where the
// device's loops read them (DeviceArray) and come back to the host to be
// compared.
#pragma once

#include <octoray/OctreeDriver.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace octoray
{
namespace checks
{
// `count` values of the device's array `data`, read back.
template <class Device, typename T>
std::vector<T> HostCopy(Device& d, const T* data, std::size_t count)
{
  std::vector<T> host(count);
  d.ToHost(data, count, host.data(), "test");
  return host;
}

// An array in the device's memory, made from a host vector and read back.
template <class Device, typename T>
class DeviceArray
{
public:
  DeviceArray(Device& d, const std::vector<T>& host)
    : D(d)
  {
    D.Upload(Data, host.data(), host.size(), "test array");
  }
  DeviceArray(Device& d, std::size_t n, T fill)
    : DeviceArray(d, std::vector<T>(n, fill))
  {
  }
  T* Get() { return Data.Get(); }
  std::vector<T> Host() const { return HostCopy(D, Data.Get(), Data.Count()); }

private:
  Device& D;
  typename Device::template Buffer<T> Data;
};

// n random keys below 2^bits.
inline std::vector<std::uint64_t> RandomKeys(std::size_t n, int bits, std::uint64_t seed)
{
  std::mt19937_64 rng(seed);
  std::vector<std::uint64_t> keys(n);
  for (auto& k : keys)
  {
    k = rng() & ((std::uint64_t(1) << bits) - 1);
  }
  return keys;
}

// ForEach calls every item once, Reduce combines every item.
template <class Device>
void ExpectLoopsCoverEveryItemOnce(Device& d, std::size_t n)
{
  DeviceArray<Device, int> seen(d, n, 0);
  int* out = seen.Get();
  d.ForEach("test", n, OCTORAY_LAMBDA(std::size_t i) { out[i] += 1; });
  const std::vector<int> calls = seen.Host();
  EXPECT_EQ(std::count(calls.begin(), calls.end(), 1), static_cast<long>(n));

  const std::uint64_t sum = d.Reduce(
    n, std::uint64_t(0), OCTORAY_LAMBDA(std::size_t i) { return std::uint64_t(i * i); },
    OCTORAY_LAMBDA(std::uint64_t a, std::uint64_t b) { return a + b; });
  std::uint64_t expected = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    expected += i * i;
  }
  EXPECT_EQ(sum, expected);
}

// Select keeps the selected items in order and writes their count.
template <class Device>
void ExpectSelectKeepsOrderAndCounts(Device& d, std::size_t n)
{
  DeviceArray<Device, std::uint32_t> out(d, n + 1, 0xDEADBEEFu);
  DeviceArray<Device, std::uint64_t> count(d, 1, 12345);
  const auto selected = OCTORAY_LAMBDA(std::size_t i) { return (i * 7919) % 5 < 2; };
  d.Select(n, selected, out.Get(), count.Get());
  std::vector<std::uint32_t> expected;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (selected(i))
    {
      expected.push_back(static_cast<std::uint32_t>(i));
    }
  }
  ASSERT_EQ(count.Host()[0], expected.size());
  const std::vector<std::uint32_t> kept = out.Host();
  EXPECT_TRUE(std::equal(expected.begin(), expected.end(), kept.begin()));
}

// The first `lists` of the `counted` lists that `tally` holds placed
// (ExpectNestedListsHoldEachItemFromItsFirstListOn).
template <class Device, typename FirstList, typename Tally>
void ExpectNestedListsPlaced(Device& d, std::size_t n, FirstList firstList, const Tally& tally, int counted, int lists)
{
  std::vector<std::vector<std::uint32_t>> expected(lists);
  for (std::size_t i = 0; i < n; ++i)
  {
    std::uint32_t below = static_cast<std::uint32_t>(i);
    for (int l = lists - 1; l >= firstList(i); --l)
    {
      expected[l].push_back(below);
      below = static_cast<std::uint32_t>(expected[l].size() - 1);
    }
  }
  for (int l = lists - 1; l >= 0; --l) // after its items, the next list's size (without its own end)
  {
    expected[l].push_back(l + 1 < lists ? static_cast<std::uint32_t>(expected[l + 1].size() - 1)
                                        : static_cast<std::uint32_t>(n));
  }
  std::vector<std::uint32_t> packed;
  for (int l = 0; l + 1 < lists; ++l)
  {
    packed.insert(packed.end(), expected[l].begin(), expected[l].end());
  }
  for (const std::size_t room : { packed.size(), packed.size() - 1 })
  {
    DeviceArray<Device, std::uint32_t> last(d, n + 1, 0xDEADBEEFu);
    DeviceArray<Device, std::uint32_t> packedOut(d, packed.size(), 0xDEADBEEFu);
    d.PlaceNested("test", n, firstList, tally, counted, NestedLists{ lists, last.Get(), packedOut.Get(), room });
    const std::vector<std::uint32_t> lastOut = last.Host();
    EXPECT_TRUE(std::equal(expected[lists - 1].begin(), expected[lists - 1].end(), lastOut.begin())) << room;
    EXPECT_EQ(packedOut.Host() == packed, room == packed.size()) << room;
  }
}

// A side histogram's bins: runs that lanes of a warp share, as in sorted
// points, in every other 32 items, and -1 (none) among the others.
struct TestSideBins
{
  static constexpr int kBins = 7;
  OCTORAY_HD int operator()(std::size_t i) const
  {
    return i % 64 < 32 ? static_cast<int>(i / 40 % kBins) : static_cast<int>((i * 13 + i / 7) % (kBins + 1)) - 1;
  }
};

// Nested lists against their definition, item by item: list l holds, in
// order, the items whose first list is l or less (the last list the items
// themselves, each other list an item's place in the next), then the size
// of the next list; the counts are those of each first list, and a side
// histogram's counts those of each bin, added to what they held. First
// lists past the last (an item in no list) come too. The lists before the
// last go end to end, and only where they fit: with one entry too few,
// the last list alone. Lists counted with more after them are placed as
// if counted alone.
template <class Device>
void ExpectNestedListsHoldEachItemFromItsFirstListOn(Device& d, std::size_t n)
{
  constexpr int kLists = 5;
  const auto firstList = OCTORAY_LAMBDA(std::size_t i) { return static_cast<int>((i * 7919 + i / 3) % 7); };
  for (const int counted : { kLists, kLists + 1 })
  {
    SCOPED_TRACE("lists counted: " + std::to_string(counted));
    typename Device::template Buffer<std::uint32_t> tally;
    std::vector<std::uint64_t> expectedCounts(counted, 0);
    std::vector<std::uint64_t> expectedSide(TestSideBins::kBins, 0);
    expectedSide[0] = 5; // added to, not replaced
    DeviceArray<Device, std::uint64_t> counts(d, counted, 0);
    DeviceArray<Device, std::uint64_t> side(d, expectedSide);
    d.CountNested("test", n, counted, firstList, tally, counts.Get(),
      SideHistogram<TestSideBins::kBins, TestSideBins>{ {}, side.Get() });
    for (std::size_t i = 0; i < n; ++i)
    {
      if (firstList(i) < counted)
      {
        ++expectedCounts[firstList(i)];
      }
      if (TestSideBins()(i) >= 0)
      {
        ++expectedSide[TestSideBins()(i)];
      }
    }
    EXPECT_EQ(counts.Host(), expectedCounts);
    EXPECT_EQ(side.Host(), expectedSide);
    ExpectNestedListsPlaced(d, n, firstList, tally, counted, kLists);
  }
}


// Keys and values sorted stably by the key's low `bits` bits: the
// reference the sorts are held to.
template <typename Key, typename Value>
std::vector<std::pair<Key, Value>> StablySorted(const std::vector<Key>& keys, const std::vector<Value>& values,
  int bits)
{
  const Key mask = static_cast<Key>(bits >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << bits) - 1);
  std::vector<std::pair<Key, Value>> pairs;
  for (std::size_t i = 0; i < keys.size(); ++i)
  {
    pairs.emplace_back(keys[i], values[i]);
  }
  std::stable_sort(pairs.begin(), pairs.end(),
    [mask](const auto& a, const auto& b) { return (a.first & mask) < (b.first & mask); });
  return pairs;
}

// The sorted arrays against the reference, position by position.
template <typename Key, typename Value>
void ExpectPairsEqual(const std::vector<Key>& keys, const std::vector<Value>& values,
  const std::vector<std::pair<Key, Value>>& reference)
{
  for (std::size_t i = 0; i < reference.size(); ++i)
  {
    ASSERT_EQ(keys[i], reference[i].first) << "position " << i;
    ASSERT_EQ(values[i], reference[i].second) << "position " << i;
  }
}

// SortPairs: stable, for both key widths with 32-bit values and for 32-bit
// keys with 64-bit ones (a leaf key with a record of two words), keys below
// 2^bits (the passes cover `bits`), with the result where the return value
// says.
template <typename Key, typename Value, class Device>
void ExpectStableSort(Device& d, std::size_t n, int bits, std::uint64_t seed)
{
  SCOPED_TRACE("bits " + std::to_string(bits) + ", values of " + std::to_string(8 * sizeof(Value)) + " bits");
  const std::vector<std::uint64_t> random = RandomKeys(n, bits, seed);
  const std::vector<Key> k(random.begin(), random.end());
  std::vector<Value> v(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    v[i] = static_cast<Value>(i);
    if constexpr (sizeof(Value) == 8)
    {
      v[i] |= ~static_cast<Value>(i) << 32; // both halves travel
    }
  }
  DeviceArray<Device, Key> k0(d, k), k1(d, n, 0);
  DeviceArray<Device, Value> v0(d, v), v1(d, n, 0);
  Key* keys[2] = { k0.Get(), k1.Get() };
  Value* values[2] = { v0.Get(), v1.Get() };
  const int result = d.SortPairs(keys, values, n, bits, "test");
  ASSERT_TRUE(result == 0 || result == 1);
  ExpectPairsEqual((result ? k1 : k0).Host(), (result ? v1 : v0).Host(), StablySorted(k, v, bits));
}

// SortPairsFrom: the same order as a stable sort, the values written to
// their own array and their input left as it is; keys of `keyBits` random
// bits sorted by `bits`, so that passes over all-zero digits are skipped
// (which changes where the passes end).
template <typename Key, typename Value, class Device>
void ExpectSortFromLeavesItsInput(Device& d, std::size_t n, int bits, int keyBits, std::uint64_t seed)
{
  SCOPED_TRACE("bits " + std::to_string(bits) + " of keys of " + std::to_string(keyBits));
  const std::vector<std::uint64_t> random = RandomKeys(n, keyBits, seed);
  const std::vector<Key> k(random.begin(), random.end());
  std::vector<Value> v(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    v[i] = static_cast<Value>(~i);
  }
  DeviceArray<Device, Key> k0(d, k), k1(d, n, 0);
  DeviceArray<Device, Value> in(d, v), out(d, n, 0);
  Key* keys[2] = { k0.Get(), k1.Get() };
  const int result = d.SortPairsFrom(keys, in.Get(), out.Get(), n, bits, "test");
  ASSERT_TRUE(result == 0 || result == 1);
  EXPECT_EQ(in.Host(), v) << "the input values changed";
  ExpectPairsEqual((result ? k1 : k0).Host(), out.Host(), StablySorted(k, v, bits));
}

// SortKeys: the keys alone, by their low `bits`, with random bits above
// them that tell apart keys the sort sees as equal: stable (the last pass
// masks its digit at `bits`).
template <typename Key, class Device>
void ExpectStableKeySort(Device& d, std::size_t n, int bits, std::uint64_t seed)
{
  SCOPED_TRACE("bits " + std::to_string(bits) + " of keys of " + std::to_string(8 * sizeof(Key)));
  const std::vector<std::uint64_t> random = RandomKeys(n, 8 * sizeof(Key) - 1, seed);
  const std::vector<Key> k(random.begin(), random.end());
  DeviceArray<Device, Key> k0(d, k), k1(d, n, 0);
  Key* keys[2] = { k0.Get(), k1.Get() };
  const int result = d.SortKeys(keys, n, bits, "test");
  ASSERT_TRUE(result == 0 || result == 1);
  const std::vector<Key> sorted = (result ? k1 : k0).Host();
  ExpectPairsEqual(sorted, sorted, StablySorted(k, k, bits)); // each key its own value
}

// Every sort, both key widths and both value widths, over full and
// partial key bits.
template <class Device>
void ExpectSortsStable(Device& d, std::size_t n, std::uint64_t seed)
{
  ExpectStableSort<std::uint64_t, std::uint32_t>(d, n, 63, seed);
  ExpectStableSort<std::uint64_t, std::uint32_t>(d, n, 30, seed);
  ExpectStableSort<std::uint32_t, std::uint32_t>(d, n, 29, seed);
  ExpectStableSort<std::uint32_t, std::uint32_t>(d, n, 5, seed);
  ExpectStableSort<std::uint32_t, std::uint64_t>(d, n, 30, seed);
  ExpectStableSort<std::uint32_t, std::uint64_t>(d, n, 6, seed);
  ExpectSortFromLeavesItsInput<std::uint32_t, std::uint64_t>(d, n, 30, 30, seed); // 3 passes
  ExpectSortFromLeavesItsInput<std::uint32_t, std::uint64_t>(d, n, 30, 20, seed); // the third skipped
  ExpectSortFromLeavesItsInput<std::uint32_t, std::uint32_t>(d, n, 24, 24, seed); // 3 passes
  ExpectSortFromLeavesItsInput<std::uint32_t, std::uint32_t>(d, n, 12, 12, seed); // 2 passes
  ExpectSortFromLeavesItsInput<std::uint32_t, std::uint32_t>(d, n, 12, 0, seed);  // none moves
  ExpectStableKeySort<std::uint64_t>(d, n, 30, seed);
  ExpectStableKeySort<std::uint64_t>(d, n, 3, seed);
  ExpectStableKeySort<std::uint64_t>(d, n, 29, seed);
  ExpectStableKeySort<std::uint32_t>(d, n, 30, seed);
  ExpectStableKeySort<std::uint32_t>(d, n, 5, seed);
}

// A copy of `count` values from `from` to `to`, a loop on the device.
template <class Device, typename T>
void CopyOnDevice(Device& d, const T* from, T* to, std::size_t count)
{
  d.ForEach("test", count, OCTORAY_LAMBDA(std::size_t i) { to[i] = from[i]; });
}

// The bytes of the arrays ExpectStageReducedCopiesReducesAndCallsBack
// stages for n items: the reduced one of three floats an item, an 8-bit
// and a float array along, and the 16-bit codes of unit values.
inline std::vector<std::size_t> StagedArrayBytes(std::size_t n)
{
  return { 3 * n * sizeof(float), n * sizeof(std::uint8_t), n * sizeof(float), n * sizeof(std::uint16_t) };
}

// n unit values (Attributes.h's UnitInput): a sweep of 0..1 and, every
// seventh, one of the values its code clamps or keeps apart.
inline std::vector<float> UnitValues(std::size_t n)
{
  const float odd[] = { -0.5f, 1.5f, -0.0f, 1.0f, INFINITY, -INFINITY, NAN };
  std::vector<float> values(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    values[i] = i % 7 == 3 ? odd[(i / 7) % 7] : static_cast<float>(i % 1000) / 999.0f;
  }
  return values;
}

// Their codes one value at a time (Scalar16.h's EncodeUnitScalar).
inline std::vector<std::uint16_t> UnitCodesOf(const std::vector<float>& values)
{
  std::vector<std::uint16_t> codes;
  for (float v : values)
  {
    codes.push_back(EncodeUnitScalar(v).code);
  }
  return codes;
}

// StageReduced: the array where the device's loops read it, the reduction
// of its items of three floats (their largest value: exact in any order),
// and the arrays Prepare adds along (an 8-bit and a float one, and the codes
// PrepareUnitCodes makes of unit values) copied in the same call.
// whenReduced runs where `expectWhenReduced` says (CUDA's
// staged copy in one pass of several arrays), with the final result, and
// the loop it queues, while the arrays along are still on their way, reads
// the whole array: a copy of it made there must miss no piece.
template <class Device>
void ExpectStageReducedCopiesReducesAndCallsBack(Device& d, std::size_t n, bool expectWhenReduced)
{
  std::mt19937 rng(static_cast<unsigned>(n));
  std::uniform_real_distribution<float> coordinate(-1000.0f, 1000.0f);
  std::vector<float> xyz(3 * n);
  std::generate(xyz.begin(), xyz.end(), [&] { return coordinate(rng); });
  std::vector<std::uint8_t> bytes(n);
  std::vector<float> values(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    bytes[i] = static_cast<std::uint8_t>(i * 7);
    values[i] = 0.5f * static_cast<float>(i);
  }
  const float none = -std::numeric_limits<float>::infinity();
  const float largest = xyz.empty() ? none : *std::max_element(xyz.begin(), xyz.end());

  const std::vector<float> units = UnitValues(n);
  typename Device::template Staged<std::uint8_t> bytesStaged;
  typename Device::template Staged<float> valuesStaged;
  typename Device::template Staged<std::uint16_t> codesStaged;
  DeviceArray<Device, float> copied(d, 3 * n, 0.0f);
  float* copy = copied.Get();
  bool called = false;
  float given = 0.0f;
  float result = 0.0f;
  const auto staged = d.StageReduced(
    xyz.data(), 3 * n, 3, "test positions", none,
    OCTORAY_LAMBDA(std::size_t i, const float* p) {
      const float a = p[3 * i] > p[3 * i + 1] ? p[3 * i] : p[3 * i + 1];
      return a > p[3 * i + 2] ? a : p[3 * i + 2];
    },
    OCTORAY_LAMBDA(float a, float b) { return a > b ? a : b; }, result,
    [&](typename Device::Fills& fills) {
      bytesStaged = d.Prepare(bytes.data(), n, "test bytes", fills);
      valuesStaged = d.Prepare(values.data(), n, "test values", fills);
      codesStaged = d.PrepareUnitCodes(units.data(), n, "test unit values", fills);
    },
    std::function<void(const float&, const float*)>([&](const float& r, const float* landed) {
      called = true;
      given = r;
      CopyOnDevice(d, landed, copy, 3 * n);
    }));
  d.Synchronize("test");
  EXPECT_EQ(result, largest);
  EXPECT_EQ(HostCopy(d, staged.Get(), 3 * n), xyz);
  EXPECT_EQ(HostCopy(d, bytesStaged.Get(), n), bytes);
  EXPECT_EQ(HostCopy(d, valuesStaged.Get(), n), values);
  EXPECT_EQ(HostCopy(d, codesStaged.Get(), n), UnitCodesOf(units));
  ASSERT_EQ(called, expectWhenReduced);
  if (called)
  {
    EXPECT_EQ(given, largest);
    EXPECT_EQ(copied.Host(), xyz) << "whenReduced's loop ran before the array had landed";
  }
}

// Levels of a test tree for ReduceSmallLevels: each node's result is the
// size of its subtree, from its children's one level down, which must be
// complete when it is reduced.
struct SubtreeSizes
{
  struct Levels
  {
    std::uint32_t levelBegin[NestedLists::kMaxLists + 1];
    OCTORAY_HD std::uint32_t LevelSize(int l) const { return levelBegin[l + 1] - levelBegin[l]; }
  } view;
  std::uint32_t* size; // one a node, level after level; the leaves' set to 1

  OCTORAY_HD void Reduce(int l, std::uint32_t j, std::uint32_t c0, std::uint32_t c1) const
  {
    const std::uint32_t* children = size + view.levelBegin[l + 1];
    std::uint32_t sum = 1;
    for (std::uint32_t c = c0; c < c1; ++c)
    {
      sum += children[c];
    }
    size[view.levelBegin[l] + j] = sum;
  }
};

// ReduceSmallLevels over a random tree of `leaves` leaves (each node one
// to a dozen children, four on average): the levels from the one above
// the leaves to the root, in turn, against the subtree sizes counted on the
// host. The children's run starts are the nested lists' packed lists, as
// LinkLevels passes them.
template <class Device>
void ExpectSmallLevelsReduceEachLevelAfterTheOneBelow(Device& d, std::size_t leaves)
{
  // starts[k]: the run starts of the k-th level from the leaves up.
  std::vector<std::vector<std::uint32_t>> starts;
  std::mt19937 rng(static_cast<unsigned>(leaves));
  for (std::size_t children = leaves; children > 1; children = starts.back().size() - 1)
  {
    std::vector<std::uint32_t> runs{ 0 };
    for (std::uint32_t c = 1; c < children; ++c)
    {
      if (rng() % 4 == 0 || c - runs.back() == 12)
      {
        runs.push_back(c);
      }
    }
    runs.push_back(static_cast<std::uint32_t>(children));
    starts.push_back(runs);
  }
  const int depth = static_cast<int>(starts.size());
  if (leaves == 0 || depth == 0)
  {
    return; // no level above the leaves
  }
  ASSERT_LT(depth, NestedLists::kMaxLists);
  std::reverse(starts.begin(), starts.end()); // level l's runs at starts[l]
  SubtreeSizes levels{};
  std::vector<std::uint32_t> packed;
  std::uint32_t levelBegin = 0;
  for (int l = 0; l < depth; ++l)
  {
    levels.view.levelBegin[l] = levelBegin;
    levelBegin += static_cast<std::uint32_t>(starts[l].size() - 1);
    packed.insert(packed.end(), starts[l].begin(), starts[l].end());
  }
  const std::uint32_t leafBegin = levelBegin;
  levels.view.levelBegin[depth] = leafBegin;
  levels.view.levelBegin[depth + 1] = leafBegin + static_cast<std::uint32_t>(leaves);
  std::vector<std::uint32_t> expected(levels.view.levelBegin[depth + 1], 1);
  for (int l = depth - 1; l >= 0; --l)
  {
    for (std::uint32_t j = 0; j < levels.view.LevelSize(l); ++j)
    {
      std::uint32_t& size = expected[levels.view.levelBegin[l] + j];
      for (std::uint32_t c = starts[l][j]; c < starts[l][j + 1]; ++c)
      {
        size += expected[levels.view.levelBegin[l + 1] + c];
      }
    }
  }
  // The reference's own check: one root, whose subtree holds every node.
  ASSERT_EQ(expected[0], expected.size());
  std::vector<std::uint32_t> initial(expected.size(), 0xFFFFFFFFu);
  std::fill(initial.begin() + leafBegin, initial.end(), 1u);
  DeviceArray<Device, std::uint32_t> sizes(d, initial), lists(d, packed);
  levels.size = sizes.Get();
  NestedLists nested;
  nested.count = depth + 1;
  nested.packed = lists.Get();
  nested.last = nullptr; // the leaves' runs: not read by the levels above them
  nested.packedRoom = packed.size();
  d.ReduceSmallLevels("test", depth - 1, levels, nested);
  EXPECT_EQ(sizes.Host(), expected);
}

// The driver's run starts (a Select) and first failing step (a loop and an
// atomic minimum), against their definitions.
template <class Device>
void ExpectRunStartsAndFirstFailedStep(Device& d, std::size_t n)
{
  DriverScratch<Device> scratch;
  d.Reserve(scratch.counters, kCounterSlots, "counters");
  std::vector<std::uint64_t> keys = RandomKeys(n, 12, n);
  std::sort(keys.begin(), keys.end());
  DeviceArray<Device, std::uint64_t> deviceKeys(d, keys);
  DeviceArray<Device, std::uint32_t> starts(d, n + 1, 0);
  RunStarts(d, scratch, deviceKeys.Get(), n, starts.Get());
  std::vector<std::uint32_t> expected;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (i == 0 || keys[i] != keys[i - 1])
    {
      expected.push_back(static_cast<std::uint32_t>(i));
    }
  }
  expected.push_back(static_cast<std::uint32_t>(n));
  std::uint64_t selected = 0;
  d.ToHost(scratch.counters.Get() + kCounterSelected, 1, &selected, "test");
  EXPECT_EQ(selected, expected.size());
  const std::vector<std::uint32_t> found = starts.Host();
  EXPECT_TRUE(std::equal(expected.begin(), expected.end(), found.begin()));
  const std::size_t bad = n / 3 + 1;
  std::uint64_t first = kNoIndex;
  for (std::size_t i = n; i-- > 0;)
  {
    first = i >= bad && i % 2 == 0 ? i : first;
  }
  EXPECT_EQ(FirstFailedStep(d, scratch, "test", n, OCTORAY_LAMBDA(std::size_t i) { return i < bad || i % 2; }),
    first);
}
}
}
