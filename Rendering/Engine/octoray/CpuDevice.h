// The CPU backend's device for the driver (OctreeDriver.h): loops split over
// std::thread chunks (Parallel.h), a multi-threaded radix sort, and buffers
// in host memory. Chunks are contiguous and combined in order, so every
// result is the same whatever the thread count.
#pragma once

#include "Config.h"
#include "Parallel.h"
#include "RadixSort.h"
#include "Scalar16.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <numeric>
#include <tuple>
#include <vector>

namespace octoray
{
// An array in host memory with the interface of DeviceBuffer: it keeps its
// allocation while a smaller count fits, and leaves new elements
// uninitialised (every step writes all it reserves).
template <typename T>
class HostBuffer
{
public:
  void Reserve(std::size_t n)
  {
    if (n > Capacity)
    {
      Data.reset(new T[n]);
      Capacity = n;
    }
    Size = n;
  }
  void Release()
  {
    Data.reset();
    Capacity = Size = 0;
  }

  T* Get() const { return Data.get(); }
  std::size_t Count() const { return Size; }
  std::size_t Bytes() const { return Capacity * sizeof(T); }
  bool Empty() const { return Size == 0; }

private:
  std::unique_ptr<T[]> Data;
  std::size_t Capacity = 0;
  std::size_t Size = 0;
};

class CpuDevice
{
public:
  template <typename T>
  using Buffer = HostBuffer<T>;

  // The caller's array, read in place: host memory is this device's memory;
  // or values made from it, which it owns (PrepareUnitCodes).
  template <typename T>
  struct Staged
  {
    const T* data = nullptr;
    std::shared_ptr<const std::vector<T>> made;
    const T* Get() const { return data; }
  };

  // Marks the host's time: loops have run when they return.
  class Clock
  {
  public:
    int Mark()
    {
      Marks.push_back(std::chrono::steady_clock::now());
      return static_cast<int>(Marks.size()) - 1;
    }
    double Seconds(int from, int to) const { return std::chrono::duration<double>(Marks[to] - Marks[from]).count(); }

  private:
    std::vector<std::chrono::steady_clock::time_point> Marks;
  };

  // Host allocations do not fail short of the whole process failing, so a
  // build reuses the current state's allocations instead of filling a new
  // one aside (which would hold two copies of the points at once).
  static constexpr bool kBuildsAside = false;

  int threads = DefaultThreadCount();

  struct NoScope
  {
  };
  NoScope Scope() const { return {}; }

  template <typename T>
  void Reserve(Buffer<T>& buffer, std::size_t n, const char*)
  {
    buffer.Reserve(n);
  }
  template <typename T>
  void Release(Buffer<T>& buffer)
  {
    buffer.Release();
  }
  template <typename T>
  Staged<T> Stage(const T* host, std::size_t, const char*)
  {
    return Staged<T>{ host };
  }
  // Loops read a caller's arrays where they are: nothing to copy.
  struct Fills
  {
  };
  template <typename T, typename R, typename Map, typename Combine>
  Staged<T> StageReduced(const T* host, std::size_t n, int stride, const char* what, R identity, Map map,
    Combine combine, R& result, const std::function<void(Fills&)>& prepareAlong = nullptr,
    const std::function<void(const R&, const T*)>& = nullptr) // nothing is on its way: whenReduced never runs
  {
    if (prepareAlong)
    {
      Fills none;
      prepareAlong(none);
    }
    result = Reduce(n / stride, identity, [&](std::size_t i) { return map(i, host); }, combine);
    return Stage(host, n, what);
  }
  template <typename T>
  Staged<T> Prepare(const T* host, std::size_t n, const char* what, Fills&)
  {
    return Stage(host, n, what);
  }
  // The Scalar16 codes of a caller's unit values (Attributes.h's UnitInput).
  Staged<std::uint16_t> PrepareUnitCodes(const float* host, std::size_t n, const char*, Fills&)
  {
    if (!host)
    {
      return {};
    }
    auto codes = std::make_shared<std::vector<std::uint16_t>>(n);
    EncodeUnitScalars(host, n, codes->data());
    return Staged<std::uint16_t>{ codes->data(), std::move(codes) };
  }
  template <typename T>
  void Adopt(const Staged<T>& staged, Buffer<T>& buffer, std::size_t n)
  {
    if (!staged.Get())
    {
      buffer.Release();
      return;
    }
    buffer.Reserve(n);
    std::copy_n(staged.Get(), n, buffer.Get());
  }
  template <typename T>
  void Upload(Buffer<T>& buffer, const T* host, std::size_t n, const char* what)
  {
    Adopt(Stage(host, n, what), buffer, n);
  }
  template <typename T>
  void Download(const Buffer<T>& buffer, std::vector<T>& host)
  {
    host.assign(buffer.Get(), buffer.Get() + buffer.Count());
  }
  template <typename T>
  void ToHost(const T* data, std::size_t n, T* host, const char*)
  {
    std::copy_n(data, n, host);
  }
  void QueueToHost(const std::uint64_t* data, std::size_t n, const char*) { Queued.assign(data, data + n); }
  void WaitToHost(std::uint64_t* host, const char*) { std::copy(Queued.begin(), Queued.end(), host); }
  template <typename T>
  void FillBytes(T* data, std::size_t n, unsigned char byte)
  {
    std::memset(data, byte, n * sizeof(T));
  }
  void Synchronize(const char*) {}
  std::size_t ScratchBytes() const
  {
    return std::apply([](const auto&... buffer) { return (buffer.Bytes() + ...); }, Scratch);
  }
  void ReleaseScratch()
  {
    std::apply([](auto&... buffer) { (buffer.Release(), ...); }, Scratch);
  }
  std::size_t CachedBytes() const { return 0; }
  void TrimCache() {}

  template <typename Fn>
  void ForEach(const char*, std::size_t n, Fn fn)
  {
    ParallelFor(n, threads, fn);
  }

  // CountNested's chunks, which PlaceNested follows.
  int NestedChunks(std::size_t n) const { return n < kParallelPassMinItems ? 1 : threads; }

  // Levels of at most kSmallLevelItems children, from `top` down to 0 in
  // turn (OctreeDriver.h's LinkLevels): levels.Reduce(l, j, starts[j],
  // starts[j + 1]) for each node j of level l, `starts` its nested list.
  // Here one thread's loop, as a loop of so few items was.
  static constexpr std::size_t kSmallLevelItems = kParallelForMinItems;
  template <typename Levels>
  void ReduceSmallLevels(const char*, int top, const Levels& levels, const NestedLists& lists)
  {
    for (int l = top; l >= 0; --l)
    {
      const std::uint32_t* starts = lists.List(l, levels.view.levelBegin[l]);
      for (std::uint32_t j = 0; j < levels.view.LevelSize(l); ++j)
      {
        levels.Reduce(l, j, starts[j], starts[j + 1]);
      }
    }
  }

  // Each chunk counts its items by their first list (tally[c * lists + f]:
  // chunk c's items of first list f), and into `side`'s bins, then places
  // them after the chunks before it, in each of their lists from the last
  // one up, so that each list records the item's place in the list after it.
  template <typename FirstList, typename Side = NoSideHistogram>
  void CountNested(const char*, std::size_t n, int lists, FirstList firstList, Buffer<std::uint32_t>& tally,
    std::uint64_t* counts, Side side = {})
  {
    const int chunks = NestedChunks(n);
    tally.Reserve(static_cast<std::size_t>(chunks) * lists);
    std::vector<std::uint64_t> sideTally(static_cast<std::size_t>(chunks) * Side::kBins, 0);
    // Each chunk counts and places in arrays of its own: the chunks' rows
    // share cache lines. Counting and placing in them, the level phase of a
    // 10 M-point build on two threads took 104-109 ms, 90-95 so
    // (octoray_bench_build --points 1e7 --backend cpu).
    ParallelChunks(n, chunks, [&](std::size_t begin, std::size_t end, int c) {
      std::uint32_t count[NestedLists::kMaxLists] = {};
      std::uint64_t sideCount[Side::kBins > 0 ? Side::kBins : 1] = {};
      for (std::size_t i = begin; i < end; ++i)
      {
        const int first = firstList(i);
        if (first < lists)
        {
          ++count[first];
        }
        if constexpr (Side::kBins > 0)
        {
          const int bin = side.binOf(i);
          if (bin >= 0)
          {
            ++sideCount[bin];
          }
        }
      }
      std::copy_n(count, lists, tally.Get() + static_cast<std::size_t>(c) * lists);
      std::copy_n(sideCount, Side::kBins, sideTally.data() + static_cast<std::size_t>(c) * Side::kBins);
    });
    for (std::size_t k = 0; k < tally.Count(); ++k)
    {
      counts[k % lists] += tally.Get()[k];
    }
    if constexpr (Side::kBins > 0)
    {
      for (std::size_t k = 0; k < sideTally.size(); ++k)
      {
        side.counts[k % Side::kBins] += sideTally[k];
      }
    }
  }

  // The first out.count of the `counted` lists that CountNested counted.
  template <typename FirstList>
  void PlaceNested(const char*, std::size_t n, FirstList firstList, const Buffer<std::uint32_t>& tally, int counted,
    const NestedLists& out)
  {
    const int lists = out.count;
    const int chunks = NestedChunks(n);
    // next[c * lists + l]: chunk c's first place in list l, which holds the
    // items of first list l and less; the row after the last chunk: the sizes.
    std::vector<std::uint32_t> next(static_cast<std::size_t>(chunks + 1) * lists, 0);
    for (int c = 0; c < chunks; ++c)
    {
      std::uint32_t inList = 0;
      for (int l = 0; l < lists; ++l)
      {
        inList += tally.Get()[static_cast<std::size_t>(c) * counted + l];
        next[static_cast<std::size_t>(c + 1) * lists + l] = next[static_cast<std::size_t>(c) * lists + l] + inList;
      }
    }
    const std::uint32_t* size = next.data() + static_cast<std::size_t>(chunks) * lists;
    std::size_t itemsBefore[NestedLists::kMaxLists] = {};
    for (int l = 1; l < lists; ++l)
    {
      itemsBefore[l] = itemsBefore[l - 1] + size[l - 1];
    }
    const int lowest = out.PackedFit(itemsBefore[lists - 1]) ? 0 : lists - 1;
    std::uint32_t* list[NestedLists::kMaxLists] = {}; // those written
    for (int l = lowest; l < lists; ++l)
    {
      list[l] = out.List(l, itemsBefore[l]);
    }
    ParallelChunks(n, chunks, [&](std::size_t begin, std::size_t end, int c) {
      std::uint32_t place[NestedLists::kMaxLists];
      std::copy_n(next.data() + static_cast<std::size_t>(c) * lists, lists, place);
      for (std::size_t i = begin; i < end; ++i)
      {
        const int first = std::max(firstList(i), lowest);
        std::uint32_t below = static_cast<std::uint32_t>(i);
        for (int l = lists - 1; l >= first; --l)
        {
          list[l][place[l]] = below;
          below = place[l]++;
        }
      }
    });
    for (int l = lowest; l < lists; ++l)
    {
      list[l][size[l]] = l + 1 < lists ? size[l + 1] : static_cast<std::uint32_t>(n);
    }
  }

  template <typename T, typename Map, typename Combine>
  T Reduce(std::size_t n, T identity, Map map, Combine combine)
  {
    const int chunks = n < kParallelPassMinItems ? 1 : threads;
    std::vector<T> partial(chunks, identity);
    ParallelChunks(n, chunks, [&](std::size_t begin, std::size_t end, int c) {
      T sum = identity;
      for (std::size_t i = begin; i < end; ++i)
      {
        sum = combine(sum, map(i));
      }
      partial[c] = sum;
    });
    T sum = identity;
    for (const T& p : partial)
    {
      sum = combine(sum, p);
    }
    return sum;
  }

  template <typename Predicate>
  void Select(std::size_t n, Predicate selected, std::uint32_t* out, std::uint64_t* count)
  {
    const int chunks = n < kParallelPassMinItems ? 1 : threads;
    std::vector<std::size_t> offsets(chunks + 1, 0);
    ParallelChunks(n, chunks, [&](std::size_t begin, std::size_t end, int c) {
      std::size_t k = 0;
      for (std::size_t i = begin; i < end; ++i)
      {
        k += selected(i) ? 1 : 0;
      }
      offsets[c + 1] = k;
    });
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    ParallelChunks(n, chunks, [&](std::size_t begin, std::size_t end, int c) {
      std::size_t k = offsets[c];
      for (std::size_t i = begin; i < end; ++i)
      {
        if (selected(i))
        {
          out[k++] = static_cast<std::uint32_t>(i);
        }
      }
    });
    *count = offsets[chunks];
  }

  template <typename Key, typename Value>
  int SortPairs(Key* const keys[2], Value* const values[2], std::size_t n, int bits, const char*)
  {
    return RadixSort(keys[0], values[0], n, bits, threads, keys[1], values[1]);
  }

  // SortPairs with the values read from valuesIn, which stays as it is,
  // and written in sorted order to valuesOut.
  template <typename Key, typename Value>
  int SortPairsFrom(Key* const keys[2], const Value* valuesIn, Value* valuesOut, std::size_t n, int bits, const char*)
  {
    Value* second = SortScratch<Value>(n);
    // The values end beside their keys: in valuesOut where the passes end
    // in the keys' second array.
    const bool odd = RadixSortPasses(bits) % 2 == 1;
    const int result = RadixSort(keys[0], odd ? second : valuesOut, n, bits, threads, keys[1],
      odd ? valuesOut : second, valuesIn);
    if ((result == 1) != odd) // a pass was skipped
    {
      std::copy_n(second, n, valuesOut);
    }
    return result;
  }

  template <typename Key>
  int SortKeys(Key* const keys[2], std::size_t n, int bits, const char*)
  {
    return RadixSort<Key, std::uint32_t>(keys[0], nullptr, n, bits, threads, keys[1], nullptr);
  }

private:
  // SortPairsFrom's second value array, kept while later sorts fit.
  template <typename Value>
  Value* SortScratch(std::size_t n)
  {
    HostBuffer<Value>& buffer = std::get<HostBuffer<Value>>(Scratch);
    buffer.Reserve(n);
    return buffer.Get();
  }

  std::tuple<HostBuffer<std::uint32_t>, HostBuffer<std::uint64_t>> Scratch;
  std::vector<std::uint64_t> Queued; // QueueToHost's words
};
}
