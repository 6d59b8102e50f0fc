// The CUDA backend's device for the driver (OctreeDriver.h): one kernel per
// loop, CUB for sorting, selection and reductions, and buffers in the
// engine's memory pool (DeviceMemoryPool). Everything runs in order on the
// default stream; a loop returns before the GPU has run it, and the host
// waits only where it reads a result (ToHost, Reduce) or Synchronize. The
// copies of a caller's arrays (StageReduced, Upload: CudaUpload.h) return
// complete. Only compiled by nvcc.
#pragma once

#include "CudaSupport.h"
#include "CudaUpload.h"

#include <cub/block/block_reduce.cuh>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>
#include <cub/device/device_select.cuh>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

namespace octoray
{
namespace cuda
{
constexpr int kBlock = 256;

inline unsigned Blocks(std::size_t n)
{
  return static_cast<unsigned>((n + kBlock - 1) / kBlock);
}

// At least MinBlocks blocks of kBlock threads on a multiprocessor:
// kLoopBlocks (4, 64 registers a thread) unless the loop asks for more
// (Occupying). The build's level loops, which read each node's children or
// points and sum their attributes in double, took 80 to 96 registers and ran
// 1.2 to 1.6 times longer on an H100 without that bound
// (Benchmarks/gpu/variants-records.txt).
template <int MinBlocks, typename Fn>
__global__ void __launch_bounds__(kBlock, MinBlocks) ForEachKernel(std::size_t n, Fn fn)
{
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i < n)
  {
    fn(i);
  }
}

// The levels of CudaDevice::ReduceSmallLevels in one block, in one launch,
// the block in step between levels. A CUB select and a loop a level took
// three launches of 13-19 us each for levels of a few thousand nodes near
// the root; levels 4 to 0 of 10 M points took 32 us so, where they took 82
// (Benchmarks/gpu/variants-levels-near-root.txt).
constexpr int kSmallLevelThreads = 1024;

template <typename Levels>
__global__ void __launch_bounds__(kSmallLevelThreads, 1) SmallLevelsKernel(int top, Levels levels, NestedLists lists)
{
  for (int l = top; l >= 0; --l)
  {
    const std::uint32_t* starts = lists.List(l, levels.view.levelBegin[l]);
    for (std::uint32_t j = threadIdx.x; j < levels.view.LevelSize(l); j += blockDim.x)
    {
      levels.Reduce(l, j, starts[j], starts[j + 1]);
    }
    __syncthreads(); // the level above reads these nodes
  }
}

// CudaDevice's nested lists in warp tiles of kNestedItemsPerLane rounds of
// 32 items: each warp tile counts its items in each list
// (NestedCountKernel), one scan over those counts, list after list, gives
// each warp tile its first place in each list, and each warp tile places
// its items (NestedPlaceKernel). Lane l keeps list l's count or place; a
// round's items go to a list by one ballot, and a round visits the lists
// from the first of any of its items on: in sorted points, the few levels
// nearest the leaves. The placement, at 48 registers, waits mostly on its
// loads (ncu's long-scoreboard stalls). Tiles of 8 rounds, twice as many
// warps as 16 rounds make, took it from 72.8 to 56.5 us at 10 M points and
// from 536 to 389 at 100 M on an H100, and the count's scan of twice as
// many tiles 28 us longer at 100 M (Benchmarks/gpu/variants-nested-tiles.txt);
// 32 rounds were slower than 16 (variants-nested-levels.txt).
constexpr int kNestedItemsPerLane = 8;
constexpr std::size_t kNestedWarpTile = 32 * std::size_t(kNestedItemsPerLane);
static_assert(NestedLists::kMaxLists <= 32, "a warp's lane l holds list l's count");
static_assert(kBlock % 32 == 0, "whole warps a block");

inline std::size_t NestedWarpTiles(std::size_t n)
{
  return std::max<std::size_t>(1, (n + kNestedWarpTile - 1) / kNestedWarpTile);
}

// The least of the warp's values (the PTX for GPUs before sm_80, which the
// CUDA build also carries, has no redux instruction).
__device__ inline int WarpMin(int value)
{
#if __CUDA_ARCH__ >= 800
  return __reduce_min_sync(0xFFFFFFFFu, value);
#else
  for (int offset = 16; offset > 0; offset /= 2)
  {
    value = min(value, __shfl_xor_sync(0xFFFFFFFFu, value, offset));
  }
  return value;
#endif
}

// The first lists of this lane's items in its warp's tile (`lists`, in
// none, past the last item), loaded before they are used so that the loads
// overlap; the tile's number.
template <typename FirstList>
__device__ inline std::size_t LoadFirstLists(std::size_t n, int lists, FirstList firstList,
  int (&first)[kNestedItemsPerLane])
{
  const std::size_t tile = (blockIdx.x * std::size_t(blockDim.x) + threadIdx.x) / 32;
  const std::size_t begin = tile * kNestedWarpTile + (threadIdx.x & 31u);
#pragma unroll
  for (int r = 0; r < kNestedItemsPerLane; ++r)
  {
    const std::size_t i = begin + 32 * std::size_t(r);
    const int f = i < n ? firstList(i) : lists;
    first[r] = f < lists ? f : lists;
  }
  return tile;
}

// The sum of the warp's values (as WarpMin).
__device__ inline unsigned WarpSum(unsigned value)
{
#if __CUDA_ARCH__ >= 800
  return __reduce_add_sync(0xFFFFFFFFu, value);
#else
  for (int offset = 16; offset > 0; offset /= 2)
  {
    value += __shfl_xor_sync(0xFFFFFFFFu, value, offset);
  }
  return value;
#endif
}

// A lane's items counted by their first list, in 5-bit fields of two
// 64-bit words: lists 0 to 11 in the first, 12 on in the second (the
// first list `lists`, none, lands in a field that nobody reads). Each item
// adds one to its field, where the count took a ballot a list and a round,
// from the round's first list on: its kernel took 34 us at 10 M points so
// against 40 on an H100 (Benchmarks/gpu/variants-count-fields.txt).
struct FirstListFields
{
  static constexpr int kBits = 5;
  static constexpr int kPerWord = 12;
  unsigned long long word[2] = { 0, 0 };

  __device__ void Add(int first)
  {
    const bool high = first >= kPerWord;
    const unsigned long long one = 1ull << (kBits * (high ? first - kPerWord : first));
    word[0] += high ? 0 : one;
    word[1] += high ? one : 0;
  }
  // Of list f, where f is known when compiled (the loop is unrolled).
  __device__ unsigned Of(int f) const { return (word[f / kPerWord] >> (kBits * (f % kPerWord))) & 31u; }
};
static_assert(kNestedItemsPerLane < 32, "a lane's count of one list fits FirstListFields' 5 bits");
static_assert(kNestedWarpTile < (1u << 16), "a tile's count of one list fits a 16-bit half");
static_assert(NestedLists::kMaxLists < 2 * FirstListFields::kPerWord, "every first list, none too, has a field");

// The items of this lane's warp tile counted into the side histogram's
// bins in the block's `blockCount`: the lanes of a round that share a bin
// (most do, in sorted points) add to it once.
template <typename Side>
__device__ inline void CountSideBins(std::size_t n, std::size_t tile, const Side& side, std::uint32_t* blockCount)
{
  const int lane = threadIdx.x & 31u;
  const std::size_t begin = tile * kNestedWarpTile + lane;
#pragma unroll
  for (int r = 0; r < kNestedItemsPerLane; ++r)
  {
    const std::size_t i = begin + 32 * std::size_t(r);
    const int bin = i < n ? side.binOf(i) : -1;
    const unsigned peers = __match_any_sync(0xFFFFFFFFu, bin);
    if (bin >= 0 && lane == __ffs(peers) - 1)
    {
      atomicAdd(&blockCount[bin], static_cast<std::uint32_t>(__popc(peers)));
    }
  }
}

// counts[l * tiles + tile]: warp tile `tile`'s items in list l (those of
// first list l and less); then one 0, so that the scan's last entry is the
// size of every list together. histogram[f] += the items of first list f,
// and side.counts[b] += the items of side bin b, added up in the block
// first. The warp adds its lanes' fields up two lists at a time, in 16-bit
// halves (kNestedWarpTile items a tile at most).
template <typename FirstList, typename Side>
__global__ void NestedCountKernel(std::size_t n, int lists, std::size_t tiles, FirstList firstList, Side side,
  std::uint32_t* counts, unsigned long long* histogram)
{
  __shared__ std::uint32_t blockCount[NestedLists::kMaxLists];
  __shared__ std::uint32_t sideCount[Side::kBins > 0 ? Side::kBins : 1];
  if (threadIdx.x < NestedLists::kMaxLists)
  {
    blockCount[threadIdx.x] = 0;
  }
  if constexpr (Side::kBins > 0)
  {
    for (int b = threadIdx.x; b < Side::kBins; b += blockDim.x)
    {
      sideCount[b] = 0;
    }
  }
  __syncthreads();
  int first[kNestedItemsPerLane];
  const std::size_t tile = LoadFirstLists(n, lists, firstList, first);
  const int lane = threadIdx.x & 31u;
  if constexpr (Side::kBins > 0)
  {
    CountSideBins(n, tile, side, sideCount);
  }
  FirstListFields fields;
#pragma unroll
  for (int r = 0; r < kNestedItemsPerLane; ++r)
  {
    fields.Add(first[r]);
  }
  std::uint32_t ofFirstList = 0; // lane l: the tile's items of first list l
#pragma unroll
  for (int pair = 0; pair < NestedLists::kMaxLists / 2; ++pair)
  {
    if (2 * pair >= lists)
    {
      break;
    }
    const unsigned both = WarpSum(fields.Of(2 * pair) | fields.Of(2 * pair + 1) << 16);
    ofFirstList = lane / 2 == pair ? (lane & 1 ? both >> 16 : both & 0xFFFFu) : ofFirstList;
  }
  std::uint32_t mine = ofFirstList; // lane l: list l's, the items of first list l and less
  for (int offset = 1; offset < 32; offset *= 2)
  {
    const std::uint32_t below = __shfl_up_sync(0xFFFFFFFFu, mine, offset);
    mine += lane >= offset ? below : 0;
  }
  if (tile < tiles && lane < lists)
  {
    counts[lane * tiles + tile] = mine;
    if (ofFirstList)
    {
      atomicAdd(&blockCount[lane], ofFirstList);
    }
  }
  if (tile == 0 && lane == 0)
  {
    counts[lists * tiles] = 0;
  }
  __syncthreads();
  if (threadIdx.x < lists && blockCount[threadIdx.x])
  {
    atomicAdd(&histogram[threadIdx.x], static_cast<unsigned long long>(blockCount[threadIdx.x]));
  }
  if constexpr (Side::kBins > 0)
  {
    for (int b = threadIdx.x; b < Side::kBins; b += blockDim.x)
    {
      if (sideCount[b])
      {
        atomicAdd(reinterpret_cast<unsigned long long*>(&side.counts[b]),
          static_cast<unsigned long long>(sideCount[b]));
      }
    }
  }
}

// Places each warp tile's items, round by round, in each of their lists,
// the last first, so that list l records the place in list l + 1; the
// lists before the last only where they fit. `firstPlace` is the exclusive
// scan of NestedCountKernel's counts: list l's entries for the warp tiles,
// after those of the lists before it.
template <typename FirstList>
__global__ void NestedPlaceKernel(std::size_t n, std::size_t tiles, FirstList firstList, NestedLists out,
  const std::uint32_t* firstPlace)
{
  const int lists = out.count;
  int first[kNestedItemsPerLane];
  const std::size_t tile = LoadFirstLists(n, lists, firstList, first);
  if (tile >= tiles)
  {
    return;
  }
  const int lane = threadIdx.x & 31u;
  const int lowest = out.PackedFit(firstPlace[(lists - 1) * tiles]) ? 0 : lists - 1;
  std::uint32_t next = 0; // lane l: the tile's next place in list l
  std::uint32_t* list = nullptr; // lane l: list l, where it is written
  if (lane < lists)
  {
    const std::uint32_t itemsBefore = firstPlace[lane * tiles];
    list = lane >= lowest ? out.List(lane, itemsBefore) : nullptr;
    next = firstPlace[lane * tiles + tile] - itemsBefore;
    if (tile == 0 && lane >= lowest) // after its items, each list records the next one's size
    {
      const std::uint32_t size = firstPlace[(lane + 1) * tiles] - itemsBefore;
      list[size] = lane + 1 < lists ? firstPlace[(lane + 2) * tiles] - firstPlace[(lane + 1) * tiles]
                                    : static_cast<std::uint32_t>(n);
    }
  }
  const std::size_t begin = tile * kNestedWarpTile + lane;
#pragma unroll
  for (int r = 0; r < kNestedItemsPerLane; ++r)
  {
    std::uint32_t below = static_cast<std::uint32_t>(begin + 32 * std::size_t(r));
    const int low = max(WarpMin(first[r]), lowest);
    for (int l = lists - 1; l >= low; --l)
    {
      const unsigned in = __ballot_sync(0xFFFFFFFFu, first[r] <= l);
      const std::uint32_t listNext = __shfl_sync(0xFFFFFFFFu, next, l);
      auto* const listOf = reinterpret_cast<std::uint32_t*>(
        __shfl_sync(0xFFFFFFFFu, reinterpret_cast<unsigned long long>(list), l));
      if (first[r] <= l)
      {
        const std::uint32_t place = listNext + __popc(in & ((1u << lane) - 1u));
        listOf[place] = below;
        below = place;
      }
      next += lane == l ? __popc(in) : 0;
    }
  }
}

// A reduction over a few items is one block; over many, a grid of at most
// kMaxRangeBlocks that strides through them.
constexpr std::size_t kRangeItemsPerThread = 16;
constexpr unsigned kMaxRangeBlocks = 1024;

inline unsigned RangeBlocks(std::size_t items)
{
  return std::max(1u, std::min(kMaxRangeBlocks, Blocks((items + kRangeItemsPerThread - 1) / kRangeItemsPerThread)));
}

// The reduction of items [0, n) of `data`: combine over every
// map(i, data), one result a block in partial[blockIdx.x].
template <typename T, typename R, typename Map, typename Combine>
__global__ void ReduceRangeKernel(const T* data, std::size_t n, R identity, Map map, Combine combine, R* partial)
{
  using BlockReduce = cub::BlockReduce<R, kBlock>;
  __shared__ typename BlockReduce::TempStorage temp;
  R sum = identity;
  const std::size_t stride = gridDim.x * std::size_t(blockDim.x);
  for (std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x; i < n; i += stride)
  {
    sum = combine(sum, map(i, data));
  }
  sum = BlockReduce(temp).Reduce(sum, combine);
  if (threadIdx.x == 0)
  {
    partial[blockIdx.x] = sum;
  }
}

// A page-locked host buffer of a few 64-bit words and an event: a copy from
// the device that returns at once and is waited for later
// (CudaDevice::QueueToHost), so that the host can queue more work first.
class QueuedRead
{
public:
  static constexpr std::size_t kWords = 64;
  QueuedRead() = default;
  QueuedRead(const QueuedRead&) = delete;
  QueuedRead& operator=(const QueuedRead&) = delete;
  ~QueuedRead()
  {
    if (Done)
    {
      cudaEventDestroy(Done);
      cudaFreeHost(Words);
    }
  }
  void Queue(const std::uint64_t* data, std::size_t n, const char* what)
  {
    if (!Done)
    {
      CudaCheck(cudaMallocHost(&Words, kWords * sizeof(std::uint64_t)), "cudaMallocHost");
      CudaCheck(cudaEventCreateWithFlags(&Done, cudaEventDisableTiming), "cudaEventCreate");
    }
    CudaCheck(cudaMemcpyAsync(Words, data, n * sizeof(std::uint64_t), cudaMemcpyDeviceToHost, 0), what);
    CudaCheck(cudaEventRecord(Done, 0), what);
    Count = n;
  }
  void Wait(std::uint64_t* host, const char* what)
  {
    CudaCheck(cudaEventSynchronize(Done), what);
    std::copy_n(Words, Count, host);
  }

private:
  std::uint64_t* Words = nullptr;
  cudaEvent_t Done = nullptr;
  std::size_t Count = 0;
};

// Reads the partial results of ReduceRangeKernel for the final reduction.
template <typename R>
struct PartialResult
{
  const R* partial;
  __host__ __device__ R operator()(std::size_t i) const { return partial[i]; }
};
}

class CudaDevice
{
public:
  template <typename T>
  using Buffer = DeviceBuffer<T>;
  template <typename T>
  using Staged = DeviceBuffer<T>;

  // Marks points in the order of the default stream, where every loop
  // runs: the time between two is the device's, however the host's calls
  // interleave with its work.
  class Clock
  {
  public:
    Clock() = default;
    Clock(const Clock&) = delete;
    Clock& operator=(const Clock&) = delete;
    ~Clock()
    {
      for (cudaEvent_t e : Events)
      {
        cudaEventDestroy(e);
      }
    }
    int Mark()
    {
      cudaEvent_t e = nullptr;
      CudaCheck(cudaEventCreate(&e), "cudaEventCreate");
      Events.push_back(e);
      CudaCheck(cudaEventRecord(e, 0), "cudaEventRecord");
      return static_cast<int>(Events.size()) - 1;
    }
    // Once the host has waited for the device past `to`.
    double Seconds(int from, int to) const
    {
      float ms = 0.0f;
      CudaCheck(cudaEventElapsedTime(&ms, Events[from], Events[to]), "cudaEventElapsedTime");
      return 1e-3 * ms;
    }

  private:
    std::vector<cudaEvent_t> Events;
  };

  // Running out of device memory is an expected failure (a full GPU, the
  // engine's budget): a build fills a new state aside and replaces the
  // current one only once complete, so that a failed build leaves the
  // previous octree as it was.
  static constexpr bool kBuildsAside = true;

  // Works on `device` (-1: the caller's current device).
  explicit CudaDevice(int device)
  {
    if (device < 0)
    {
      CudaCheck(cudaGetDevice(&device), "cudaGetDevice");
    }
    Device = device;
  }

  int Index() const { return Device; }
  DeviceMemoryPool& Pool() { return Memory; }

  // Makes this device current until the scope ends (every public call).
  ScopedDevice Scope() const { return ScopedDevice(Device); }
  // From the start of the owner's destructor on: its buffers are freed on
  // this device, and the caller's device is current again once this device
  // (the owner's first member) is destroyed.
  void ScopeUntilDestroyed() { DestructionScope = std::make_unique<ScopedDevice>(Device); }

  template <typename T>
  void Reserve(Buffer<T>& buffer, std::size_t n, const char* what)
  {
    buffer.Reserve(Memory, n, what);
  }
  template <typename T>
  void Release(Buffer<T>& buffer)
  {
    buffer.Release();
  }
  // Copies that Prepare adds for a StageReduced to make in the same pass of
  // the staging threads as its own.
  using Fills = std::vector<cuda::CopyPart>;
  // A copy of `source` (host memory, or device memory: a caller's CUDA arrays,
  // copied on the device) with the reduction of its items of `stride`
  // elements, one loop over the whole array once it has landed. Before, the
  // staging threads queued a loop on each piece as it landed, on their own
  // streams. With one loop, eight rounds each in turn on an H200, the whole
  // call at 1 M points took 2.61-3.25 times the pinned copy against 2.78-3.46
  // (medians 2.80 and 2.94), at 10 M 1.29-1.39 against 1.34-1.51 (medians
  // 1.335 and 1.355), at 100 M 1.15-1.27 against 1.16-1.25 (1.18 and 1.20)
  // (Benchmarks/gpu/variants-whole-bounds.txt). In ncu the one loop took
  // 55 us at 10 M points where the 65 loops a piece took 696, and 0.45 ms at
  // 100 M where 321 took 3.64 (Benchmarks/gpu/profile-build*.txt, the
  // reports' runs at 1c3ac4a and c9c93d4): each small loop ran at 0.2-0.3
  // TB/s. Whether they held up the staging, and how, was not established.
  // prepareAlong adds copies that go in the same pass. It runs once this
  // array's memory is taken, so theirs comes after it in the pool, as before
  // the one pass: taken first, it left the build's level phase at 10 M points
  // 0.15 ms slower in two calls, though not with other piece sizes
  // (Benchmarks/gpu/variants-one-pass.txt; the pool's layout, not explained).
  // Where this array is staged with those copies, whenReduced(result, staged),
  // if given, runs on the host once it has landed and been reduced, while they
  // are still on their way (HostStaging::Copy's afterFirst): the reduction and
  // the loops it queues over the array overlap their copies. Elsewhere
  // (nothing left on its way) it does not run, and the caller queues them
  // after the copy.
  template <typename T, typename R, typename Map, typename Combine>
  Staged<T> StageReduced(const T* source, std::size_t n, int stride, const char* what, R identity, Map map,
    Combine combine, R& result, const std::function<void(Fills&)>& prepareAlong = nullptr,
    const std::function<void(const R&, const T*)>& whenReduced = nullptr)
  {
    Fills along;
    Staged<T> staged;
    result = identity;
    if (source)
    {
      Reserve(staged, n, what);
    }
    if (prepareAlong)
    {
      prepareAlong(along);
    }
    if (!source)
    {
      Staging.Copy(along);
      return staged;
    }
    along.insert(along.begin(), cuda::CopyPart{ staged.Get(), source, n * sizeof(T), what });
    const T* data = staged.Get();
    const auto reduce = [&] { result = ReduceItems(data, n / stride, identity, map, combine); };
    std::function<void()> afterArray;
    if (whenReduced)
    {
      afterArray = [&] {
        reduce();
        whenReduced(result, data);
      };
    }
    if (!Staging.Copy(along, afterArray))
    {
      reduce();
    }
    return staged;
  }
  // Room for a caller's array where loops read it, whose copy a
  // StageReduced makes from `fills` (on the CPU, the array itself): arrays
  // staged together share the staging's ramps (StagingPieces.h).
  template <typename T>
  Staged<T> Prepare(const T* source, std::size_t n, const char* what, Fills& fills)
  {
    Staged<T> staged;
    if (source)
    {
      Reserve(staged, n, what);
      fills.push_back(cuda::CopyPart{ staged.Get(), source, n * sizeof(T), what });
    }
    return staged;
  }
  // The Scalar16 codes of a caller's unit values (Attributes.h's UnitInput):
  // made by the staging threads as they copy pageable memory, so that half
  // the bytes cross the bus; made by a loop where the device reads the
  // values itself (a caller's device or page-locked arrays).
  Staged<std::uint16_t> PrepareUnitCodes(const float* source, std::size_t n, const char* what, Fills& fills)
  {
    Staged<std::uint16_t> codes;
    if (!source)
    {
      return codes;
    }
    Reserve(codes, n, what);
    std::uint16_t* to = codes.Get();
    if (const float* values = static_cast<const float*>(cuda::DeviceReadable(source)))
    {
      ForEach("UnitCodesKernel", n, OCTORAY_LAMBDA(std::size_t i) { to[i] = EncodeUnitScalar(values[i]).code; });
      return codes;
    }
    cuda::CopyPart part{ to, source, n * sizeof(std::uint16_t), what };
    part.unitCodes = true;
    fills.push_back(std::move(part));
    return codes;
  }
  template <typename T>
  void Adopt(Staged<T>&& staged, Buffer<T>& buffer, std::size_t)
  {
    buffer = std::move(staged);
  }
  template <typename T>
  void Upload(Buffer<T>& buffer, const T* source, std::size_t n, const char* what)
  {
    Reserve(buffer, n, what);
    Staging.Copy(buffer.Get(), source, n * sizeof(T), what);
  }
  template <typename T>
  void Download(const Buffer<T>& buffer, std::vector<T>& host)
  {
    host.resize(buffer.Count());
    ToHost(buffer.Get(), host.size(), host.data(), "copy to the host");
  }
  template <typename T>
  void ToHost(const T* data, std::size_t n, T* host, const char* what)
  {
    if (n)
    {
      CudaCheck(cudaMemcpy(host, data, n * sizeof(T), cudaMemcpyDeviceToHost), what);
    }
  }
  // A copy to the host that waits for the device only in
  // WaitToHost: the host can queue more work meanwhile.
  void QueueToHost(const std::uint64_t* data, std::size_t n, const char* what)
  {
    if (n > cuda::QueuedRead::kWords)
    {
      throw Error(std::string("octoray: ") + what + ": more words than a queued read holds");
    }
    Read.Queue(data, n, what);
  }
  void WaitToHost(std::uint64_t* host, const char* what) { Read.Wait(host, what); }
  template <typename T>
  void FillBytes(T* data, std::size_t n, unsigned char byte)
  {
    CudaCheck(cudaMemset(data, byte, n * sizeof(T)), "cudaMemset");
  }
  void Synchronize(const char* what) { CudaCheck(cudaDeviceSynchronize(), what); }
  std::size_t ScratchBytes() const { return CubScratch.Bytes() + ReduceResult.Bytes(); }
  void ReleaseScratch()
  {
    CubScratch.Release();
    ReduceResult.Release();
  }
  std::size_t CachedBytes() const { return Memory.CachedBytes(); }
  void TrimCache() { Memory.Trim(); }

  template <typename Fn>
  void ForEach(const char* name, std::size_t n, Fn fn)
  {
    ForEach(name, n, Occupying<kLoopBlocks, Fn>{ fn });
  }
  template <int Blocks, typename Fn>
  void ForEach(const char* name, std::size_t n, Occupying<Blocks, Fn> loop)
  {
    if (n)
    {
      Launch(name, cuda::ForEachKernel<Blocks, Fn>, cuda::Blocks(n), cuda::kBlock, n, loop.body);
    }
  }

  // As CpuDevice::ReduceSmallLevels: levels of at most 16 children a
  // thread of one block, all in that block (SmallLevelsKernel).
  static constexpr std::size_t kSmallLevelItems = 16 * std::size_t(cuda::kSmallLevelThreads);
  template <typename Levels>
  void ReduceSmallLevels(const char* name, int top, const Levels& levels, const NestedLists& lists)
  {
    Launch(name, cuda::SmallLevelsKernel<Levels>, 1, cuda::kSmallLevelThreads, top, levels, lists);
  }

  // As CpuDevice's: `tally` holds the warp tiles' counts and their scan,
  // lists * tiles + 1 entries each.
  template <typename FirstList, typename Side = NoSideHistogram>
  void CountNested(const char* name, std::size_t n, int lists, FirstList firstList, Buffer<std::uint32_t>& tally,
    std::uint64_t* counts, Side side = {})
  {
    static_assert(sizeof(std::uint64_t) == sizeof(unsigned long long), "64-bit counts");
    const std::size_t tiles = cuda::NestedWarpTiles(n);
    const std::size_t entries = static_cast<std::size_t>(lists) * tiles + 1;
    std::uint32_t* none = nullptr;
    std::size_t scanBytes = 0;
    CudaCheck(cub::DeviceScan::ExclusiveSum(nullptr, scanBytes, none, none, entries), "cub::DeviceScan");
    Reserve(tally, 2 * entries, "nested lists");
    std::uint32_t* tileCounts = tally.Get();
    Launch(name, cuda::NestedCountKernel<FirstList, Side>, cuda::Blocks(32 * tiles), cuda::kBlock, n, lists, tiles,
      firstList, side, tileCounts, reinterpret_cast<unsigned long long*>(counts));
    CudaCheck(cub::DeviceScan::ExclusiveSum(Temporary(scanBytes), scanBytes, tileCounts, tileCounts + entries, entries),
      "cub::DeviceScan");
  }

  template <typename FirstList>
  void PlaceNested(const char* name, std::size_t n, FirstList firstList, const Buffer<std::uint32_t>& tally,
    int counted, const NestedLists& out)
  {
    const std::size_t tiles = cuda::NestedWarpTiles(n);
    // The scan follows the counts of every list counted; the places of the
    // first out.count lists are where they would be had those alone been.
    const std::size_t entries = static_cast<std::size_t>(counted) * tiles + 1;
    Launch(name, cuda::NestedPlaceKernel<FirstList>, cuda::Blocks(32 * tiles), cuda::kBlock, n, tiles, firstList,
      out, tally.Get() + entries);
  }

  // combine over map(i, data) for every item i < items of `data`: a grid
  // of at most kMaxRangeBlocks, then their results.
  template <typename T, typename R, typename Map, typename Combine>
  R ReduceItems(const T* data, std::size_t items, R identity, Map map, Combine combine)
  {
    const unsigned blocks = cuda::RangeBlocks(items);
    Buffer<R> partial;
    Reserve(partial, blocks, "partial reductions");
    Launch("ReduceRangeKernel", cuda::ReduceRangeKernel<T, R, Map, Combine>, blocks, cuda::kBlock, data, items,
      identity, map, combine, partial.Get());
    return Reduce(blocks, identity, cuda::PartialResult<R>{ partial.Get() }, combine);
  }

  template <typename T, typename Map, typename Combine>
  T Reduce(std::size_t n, T identity, Map map, Combine combine)
  {
    auto in = thrust::make_transform_iterator(thrust::counting_iterator<std::size_t>(0), map);
    Reserve(ReduceResult, sizeof(T), "reduction");
    T* out = reinterpret_cast<T*>(ReduceResult.Get());
    std::size_t bytes = 0;
    CudaCheck(cub::DeviceReduce::Reduce(nullptr, bytes, in, out, n, combine, identity), "cub::DeviceReduce");
    CudaCheck(cub::DeviceReduce::Reduce(Temporary(bytes), bytes, in, out, n, combine, identity), "cub::DeviceReduce");
    T result;
    ToHost(out, 1, &result, "cub::DeviceReduce");
    return result;
  }

  template <typename Predicate>
  void Select(std::size_t n, Predicate selected, std::uint32_t* out, std::uint64_t* count)
  {
    auto in = thrust::counting_iterator<std::uint32_t>(0);
    std::size_t bytes = 0;
    CudaCheck(cub::DeviceSelect::If(nullptr, bytes, in, out, count, n, selected), "cub::DeviceSelect");
    CudaCheck(cub::DeviceSelect::If(Temporary(bytes), bytes, in, out, count, n, selected), "cub::DeviceSelect");
  }

  template <typename Key, typename Value>
  int SortPairs(Key* const keys[2], Value* const values[2], std::size_t n, int bits, const char* what)
  {
    cub::DoubleBuffer<Key> k(keys[0], keys[1]);
    cub::DoubleBuffer<Value> v(values[0], values[1]);
    const std::string name = std::string("cub::DeviceRadixSort (") + what + ")";
    std::size_t bytes = 0;
    CudaCheck(cub::DeviceRadixSort::SortPairs(nullptr, bytes, k, v, n, 0, bits), name.c_str());
    CudaCheck(cub::DeviceRadixSort::SortPairs(Temporary(bytes), bytes, k, v, n, 0, bits), name.c_str());
    return k.selector;
  }

  // SortPairs with the values read from valuesIn, which stays as it is,
  // and written in sorted order to valuesOut: CUB's form that leaves its
  // input alone, its second buffers in the temporary storage. The keys end
  // in keys[1].
  template <typename Key, typename Value>
  int SortPairsFrom(Key* const keys[2], const Value* valuesIn, Value* valuesOut, std::size_t n, int bits,
    const char* what)
  {
    const std::string name = std::string("cub::DeviceRadixSort (") + what + ")";
    std::size_t bytes = 0;
    CudaCheck(cub::DeviceRadixSort::SortPairs(nullptr, bytes, keys[0], keys[1], valuesIn, valuesOut, n, 0, bits),
      name.c_str());
    CudaCheck(cub::DeviceRadixSort::SortPairs(Temporary(bytes), bytes, keys[0], keys[1], valuesIn, valuesOut, n, 0,
                bits),
      name.c_str());
    return 1;
  }

  template <typename Key>
  int SortKeys(Key* const keys[2], std::size_t n, int bits, const char* what)
  {
    cub::DoubleBuffer<Key> k(keys[0], keys[1]);
    const std::string name = std::string("cub::DeviceRadixSort (") + what + ")";
    std::size_t bytes = 0;
    CudaCheck(cub::DeviceRadixSort::SortKeys(nullptr, bytes, k, n, 0, bits), name.c_str());
    CudaCheck(cub::DeviceRadixSort::SortKeys(Temporary(bytes), bytes, k, n, 0, bits), name.c_str());
    return k.selector;
  }

private:
  // CUB's temporary storage; its allocation is kept while later calls fit.
  void* Temporary(std::size_t bytes)
  {
    Reserve(CubScratch, bytes, "CUB temporary storage");
    return CubScratch.Get();
  }

  // Declared first so that it is destroyed last (ScopeUntilDestroyed).
  std::unique_ptr<ScopedDevice> DestructionScope;
  int Device = 0;
  // Declared before the buffers so that it outlives them.
  DeviceMemoryPool Memory;
  DeviceBuffer<unsigned char> CubScratch;
  DeviceBuffer<unsigned char> ReduceResult;
  // Page-locked host buffers through which large pageable arrays go
  // (CudaUpload.h); not in the memory report, which counts device bytes.
  cuda::HostStaging Staging;
  cuda::QueuedRead Read;
};
}
