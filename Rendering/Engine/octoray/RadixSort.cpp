#include "RadixSort.h"

#include "Parallel.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace octoray
{
// 11-bit digits keep a pass's histogram (2048 counters per thread) in L1
// while needing only 6 passes for 63-bit keys; the digit width is evened
// out over the passes so that e.g. 30 bits take 3 passes of 10.
int RadixSortPasses(int bits)
{
  return (bits + 10) / 11;
}

namespace
{
// Whether the `chunks` histograms (chunk-major, each of the same digits)
// of n keys put them all under one digit.
bool OneDigit(const std::vector<std::size_t>& histogram, int chunks, std::size_t n)
{
  const std::size_t buckets = histogram.size() / chunks;
  for (std::size_t d = 0; d < buckets; ++d)
  {
    std::size_t total = 0;
    for (int c = 0; c < chunks; ++c)
    {
      total += histogram[c * buckets + d];
    }
    if (total)
    {
      return total == n;
    }
  }
  return false;
}

// The histograms' counts replaced by where each chunk's keys of each digit
// go: exclusive offsets, digit-major then chunk, which keeps the sort
// stable.
void ToExclusiveOffsets(std::vector<std::size_t>& histogram, int chunks)
{
  const std::size_t buckets = histogram.size() / chunks;
  std::size_t running = 0;
  for (std::size_t d = 0; d < buckets; ++d)
  {
    for (int c = 0; c < chunks; ++c)
    {
      const std::size_t count = histogram[c * buckets + d];
      histogram[c * buckets + d] = running;
      running += count;
    }
  }
}
}

template <typename Key, typename Value>
int RadixSort(Key* keys, Value* values, std::size_t n, int bits, int threads, Key* scratchKeys, Value* scratchValues,
  const Value* valuesIn)
{
  if (n < 2 || bits <= 0)
  {
    if (valuesIn)
    {
      std::copy_n(valuesIn, n, values);
    }
    return 0;
  }
  const int passes = RadixSortPasses(bits);
  const int digitBits = (bits + passes - 1) / passes;
  const std::size_t buckets = std::size_t(1) << digitBits;

  Key* srcK = keys;
  Key* dstK = scratchKeys;
  // The values follow their keys' buffers: [0] beside keys, [1] beside the
  // scratch keys; the first pass that moves reads them from valuesIn.
  Value* const valueBuffers[2] = { values, scratchValues };
  const Value* srcV = valuesIn ? valuesIn : values;
  int into = 1;

  const int chunks = n < kParallelPassMinItems ? 1 : threads;
  std::vector<std::size_t> histogram(static_cast<std::size_t>(chunks) * buckets);

  for (int pass = 0; pass < passes; ++pass)
  {
    const int shift = pass * digitBits;
    // The last digit may be narrower: bits from `bits` on do not count.
    const std::uint64_t digitMask = (std::uint64_t(1) << std::min(digitBits, bits - shift)) - 1;
    std::fill(histogram.begin(), histogram.end(), 0);
    ParallelChunks(n, chunks, [&](std::size_t begin, std::size_t end, int c) {
      std::size_t* h = histogram.data() + c * buckets;
      for (std::size_t i = begin; i < end; ++i)
      {
        ++h[(srcK[i] >> shift) & digitMask];
      }
    });
    // Skip a pass in which every key has the same digit: it would only copy.
    if (OneDigit(histogram, chunks, n))
    {
      continue;
    }
    ToExclusiveOffsets(histogram, chunks);
    ParallelChunks(n, chunks, [&](std::size_t begin, std::size_t end, int c) {
      std::size_t* offset = histogram.data() + c * buckets;
      for (std::size_t i = begin; i < end; ++i)
      {
        const std::size_t slot = offset[(srcK[i] >> shift) & digitMask]++;
        dstK[slot] = srcK[i];
        if (srcV)
        {
          valueBuffers[into][slot] = srcV[i];
        }
      }
    });
    std::swap(srcK, dstK);
    srcV = srcV ? valueBuffers[into] : nullptr;
    into = 1 - into;
  }
  if (valuesIn && srcV == valuesIn) // no pass moved anything
  {
    std::copy_n(valuesIn, n, values);
  }
  return srcK == keys ? 0 : 1;
}

template int RadixSort(std::uint64_t*, std::uint32_t*, std::size_t, int, int, std::uint64_t*, std::uint32_t*,
  const std::uint32_t*);
template int RadixSort(std::uint32_t*, std::uint32_t*, std::size_t, int, int, std::uint32_t*, std::uint32_t*,
  const std::uint32_t*);
template int RadixSort(std::uint32_t*, std::uint64_t*, std::size_t, int, int, std::uint32_t*, std::uint64_t*,
  const std::uint64_t*);
}
