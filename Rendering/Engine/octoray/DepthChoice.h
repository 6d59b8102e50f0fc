// Choosing the leaf level from the data. Rule: the shallowest level at which
// at least half of the non-empty leaves hold a single point (the median leaf
// holds one point), or at which no deeper level separates any more points
// (coincident points), and at least 1. One pass over the sorted full-depth
// keys yields the answer for all 21 levels at once: two neighbouring keys
// share their ancestors down to level SharedLevels(a, b), so a key starts a
// new node at every level below that, and is alone in its node at every
// level below what it shares with either neighbour.
#pragma once

#include "Config.h"

namespace octoray
{
// Deepest level at which full-depth keys a and b have the same ancestor
// (0..20), or 21 when a == b.
OCTORAY_HD int SharedLevels(std::uint64_t a, std::uint64_t b)
{
  const std::uint64_t x = a ^ b;
  if (!x)
  {
    return kMaxLevel;
  }
#if defined(__CUDA_ARCH__)
  const int highest = 63 - __clzll(static_cast<long long>(x));
#else
  const int highest = 63 - __builtin_clzll(x);
#endif
  return kMaxLevel - 1 - highest / 3;
}

// Histogram bins for sorted key i of n: `newNodeBin` (0..21) is the level
// shared with the previous key, -1 for i == 0 (not counted); `aloneBin`
// (-1..21) the deeper of the levels shared with either neighbour.
OCTORAY_HD void DepthHistogramBins(const std::uint64_t* sortedKeys, std::size_t n, std::size_t i, int& newNodeBin,
  int& aloneBin)
{
  const int withPrev = i > 0 ? SharedLevels(sortedKeys[i - 1], sortedKeys[i]) : -1;
  const int withNext = i + 1 < n ? SharedLevels(sortedKeys[i], sortedKeys[i + 1]) : -1;
  newNodeBin = withPrev;
  aloneBin = withPrev > withNext ? withPrev : withNext;
}

constexpr int kDepthHistogramBins = kMaxLevel + 2; // levels -1..21

// newNode[b + 1] and alone[b + 1] count keys per bin b in -1..21.
inline int ChooseDepthFromHistograms(const std::uint64_t newNode[kDepthHistogramBins],
  const std::uint64_t alone[kDepthHistogramBins])
{
  auto distinctAt = [&](int level) {
    std::uint64_t d = 1; // the first key
    for (int b = 0; b < level; ++b)
    {
      d += newNode[b + 1];
    }
    return d;
  };
  const std::uint64_t distinctAtMax = distinctAt(kMaxLevel);
  std::uint64_t singletons = alone[0]; // bin -1: a lone point
  for (int level = 1; level <= kMaxLevel; ++level)
  {
    singletons += alone[level]; // bin level-1
    const std::uint64_t distinct = distinctAt(level);
    if (2 * singletons >= distinct || distinct == distinctAtMax)
    {
      return level;
    }
  }
  return kMaxLevel;
}
}
