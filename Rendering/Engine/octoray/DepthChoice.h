// Choosing the leaf level from the data. Rule: the shallowest level at which
// at least half of the non-empty leaves hold a single point (the median leaf
// holds one point), or at which no deeper level separates any more points
// (coincident points), and at least 1. One pass over the sorted full-depth
// keys yields the answer for all 21 levels at once (over keys sorted down to
// a level, for the levels down to it: ChooseDepthWithin): two neighbouring keys
// share their ancestors down to level SharedLevels(a, b), so a key starts a
// new node at every level below that, and is alone in its node at every
// level below what it shares with either neighbour.
#pragma once

#include "Morton.h"

namespace octoray
{
// Deepest level at which keys a and b of `depth` levels (leaf keys at that
// depth; full-depth keys by default) have the same ancestor (0..depth - 1),
// or kMaxLevel when a == b: equal keys of a depth short of kMaxLevel count
// as sharing the levels below it too, which were not told apart. Keys of 32
// bits take 32-bit arithmetic: the automatic depth's count runs this three
// times a point, and on an H100 the histogram of neighbouring keys that did
// so before (Benchmarks/gpu/variants-histogram-32bit.txt) ran a fifth
// faster with it, where more reads in flight had not made it faster.
template <typename Key>
OCTORAY_HD int SharedLevels(Key a, Key b, int depth = kMaxLevel)
{
  const Key x = a ^ b;
  return x ? depth - 1 - HighestBit(x) / 3 : kMaxLevel;
}

constexpr int kDepthHistogramBins = kMaxLevel + 2; // levels -1..21

// Where sorted key i of n counts in the alone histogram: the deeper of the
// levels it shares with either neighbour (-1 where it has none), as entry
// that + 1. Every level below that one holds the key alone. The newNode
// histogram, the level each key shares with the previous one, is
// FirstNewLevels' lists, counted beside (Device::CountNested). `keys` are
// leaf keys of `depth` levels (32 or 64 bits).
template <typename Key>
struct LoneLevels
{
  const Key* keys;
  std::size_t n;
  int depth;

  OCTORAY_HD int operator()(std::size_t i) const
  {
    const Key key = keys[i];
    const int withPrev = i > 0 ? SharedLevels(keys[i - 1], key, depth) : -1;
    const int withNext = i + 1 < n ? SharedLevels(key, keys[i + 1], depth) : -1;
    return (withPrev > withNext ? withPrev : withNext) + 1;
  }
};

// The shallowest level at which sorted key i of n starts a node, which it
// starts at every level from there to the leaves: 0 for the first key,
// else one below the deepest level it shares with the previous key, its
// newNode bin (kMaxLevel + 1 where the keys are equal: none). The sorted
// keys are leaf keys of `depth` levels once shifted right by `shift` bits
// (32 or 64 bits). Level l's run starts are the keys of first new level l
// and less (the build's nested lists: OctreeDriver.h's LinkLevels).
template <typename Key>
struct FirstNewLevels
{
  const Key* keys;
  int depth;
  int shift;

  OCTORAY_HD int operator()(std::size_t i) const
  {
    return i > 0 ? SharedLevels(keys[i - 1] >> shift, keys[i] >> shift, depth) + 1 : 0;
  }
};

// Nodes at `level` (0..21) from the newNode histogram: the first key starts
// one, and so does every key that shares fewer than `level` levels with its
// predecessor.
inline std::uint64_t NodesAtLevel(const std::uint64_t newNode[kDepthHistogramBins], int level)
{
  std::uint64_t nodes = 1;
  for (int b = 0; b < level; ++b)
  {
    nodes += newNode[b + 1];
  }
  return nodes;
}

// The automatic depth sorts 32-bit keys of kProvisionalDepth levels first:
// their levels settle the depth rule for most clouds (ChooseDepthWithin).
// Where they do not, it sorts keys of kMiddleDepth levels where those may
// settle it (NextSortDepth), then full-depth keys, which always do.
constexpr int kProvisionalDepth = 10;
constexpr int kMiddleDepth = 13;
constexpr int kMostAutomaticSorts = 3;

// The depth of the automatic depth's next sort, after one of `sortedDepth`
// levels whose newNode histogram did not settle the rule. Keys of 13 levels
// (39 bits) take five passes of CUB's 8-bit digits where full-depth keys
// take eight, and four of the CPU's digits of up to 11 bits against six; but
// where they do not settle the rule either, their sort is wasted. So they
// are sorted where the provisional sort's occupied cells hold on average no
// more points than a cell of a surface splits into by kMiddleDepth (4 a
// level: 64). On an H200 the device phases for 100 M clustered points (5
// a cell; depth 11) took 10.5 ms so against 13.5 with full-depth keys at
// once, the whole call 35.7-36.4 ms against 39.0-39.4. Clusters a
// ten-thousandth of the cube wide (depth 17 at 10 M points, 19 at 100 M;
// 5e4 points a cell) go to full depth at once, where keys of 13 levels
// first had made the whole call 13-21 % longer, of 16 levels 16-24 %
// (Benchmarks/gpu/variants-middle-sort.txt). A cloud of sparse cells whose
// rule lands deeper than 13 (pairs of near-coincident points, say) still
// sorts both.
inline int NextSortDepth(const std::uint64_t newNode[kDepthHistogramBins], std::uint64_t points, int sortedDepth)
{
  constexpr int kSurfaceSplitBits = 2 * (kMiddleDepth - kProvisionalDepth);
  const bool sparse = points <= (NodesAtLevel(newNode, kProvisionalDepth) << kSurfaceSplitBits);
  return sortedDepth == kProvisionalDepth && sparse ? kMiddleDepth : kMaxLevel;
}

// The depth from the histograms of keys sorted down to level `known`
// (newNode[b + 1]: the keys that share b levels with the previous one,
// read for b < known; alone[b + 1]: the keys whose nearer neighbour shares
// b levels with them, b in -1..21; with known < kMaxLevel the bins from
// `known` on lump keys whose deeper levels were not sorted). The bins
// below `known` are exact, and they settle the rule at a level up to
// `known` unless no level up to it holds half singletons and one of them
// already has as many nodes as level `known`: whether a deeper level
// would separate more points is then not known, and the answer is 0. With
// known == kMaxLevel, never 0.
inline int ChooseDepthWithin(const std::uint64_t newNode[kDepthHistogramBins],
  const std::uint64_t alone[kDepthHistogramBins], int known)
{
  const std::uint64_t distinctAtKnown = NodesAtLevel(newNode, known);
  std::uint64_t singletons = alone[0]; // bin -1: a lone point
  for (int level = 1; level <= known; ++level)
  {
    singletons += alone[level]; // bin level-1
    const std::uint64_t distinct = NodesAtLevel(newNode, level);
    if (2 * singletons >= distinct)
    {
      return level;
    }
    if (distinct == distinctAtKnown)
    {
      return known == kMaxLevel ? level : 0; // no deeper level separates more, or none known
    }
  }
  return known == kMaxLevel ? kMaxLevel : 0;
}
}
