// CPU least-significant-digit radix sort of keys, alone or with a value
// each, by the keys' low `bits` bits; multi-threaded, stable.
#pragma once

#include <cstddef>
#include <cstdint>

namespace octoray
{
// The passes RadixSort makes over keys of `bits` bits (fewer where it skips some).
int RadixSortPasses(int bits);

// Sorts the n keys, and values[i] with keys[i] unless values is null,
// ping-ponging between them and the scratch arrays (n entries each; no
// scratchValues without values); returns where the result is: 0 in keys
// and values, 1 in the scratch arrays. With valuesIn the values are read
// from there instead, which stays as it is. Passes whose digit is the same
// for every key are skipped. Key: std::uint64_t or std::uint32_t; Value:
// std::uint32_t, or std::uint64_t with 32-bit keys (a leaf key and a point's
// record of two words, OctreeKernels.h's SortedKeys).
template <typename Key, typename Value = std::uint32_t>
int RadixSort(Key* keys, Value* values, std::size_t n, int bits, int threads, Key* scratchKeys, Value* scratchValues,
  const Value* valuesIn = nullptr);
}
