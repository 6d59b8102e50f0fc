// CPU least-significant-digit radix sort of (key, index) pairs whose keys
// are below 2^bits, multi-threaded, stable.
#pragma once

#include <cstddef>
#include <cstdint>

namespace octoray
{
// Sorts the n pairs (keys[i], values[i]), ping-ponging between them and the
// two scratch arrays (n entries each); returns where the result is: 0 in
// keys and values, 1 in the scratch arrays. Passes whose digit is the same
// for every key are skipped. Key: std::uint64_t or std::uint32_t.
template <typename Key>
int RadixSortPairs(Key* keys, std::uint32_t* values, std::size_t n, int bits, int threads, Key* scratchKeys,
  std::uint32_t* scratchValues);
}
