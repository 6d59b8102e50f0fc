// CPU least-significant-digit radix sort of (key, index) pairs on the low
// `bits` bits of the keys, multi-threaded, stable.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace octoray
{
// Sorts keys[0..n) with values carried along. The scratch vectors are
// resized to n and reused across calls. Passes whose digit is the same for
// every key are skipped.
void RadixSortPairs(std::uint64_t* keys, std::uint32_t* values, std::size_t n, int bits, int threads,
  std::vector<std::uint64_t>& scratchKeys, std::vector<std::uint32_t>& scratchValues);
}
