// Run starts of sorted 32-bit keys, three ways, timed against each other on
// one GPU (a probe for the build's selects, not part of the engine):
//   if      = the engine's RunStarts: CUB's DeviceSelect::If over the
//             indices, the predicate reading key i and key i - 1;
//   unique  = CUB's DeviceSelect::UniqueByKey (keys compared >> shift, the
//             indices as values, the keys' output discarded), the end after;
//   tiles   = one kernel a tile of 256 threads x Items keys, loaded four at a
//             time, a block-wide scan of the run-start flags and CUB's
//             decoupled look-back for the tiles before (after a kernel that
//             readies the tiles' states).
// Keys: n random 30-bit keys sorted (the leaves of n points at depth 10,
// shift 0), and the unique ones of those as a level's children (shift 3),
// at an offset of one key, as a level's keys lie in the node array.
//   nvcc -O3 -std=c++17 -arch=sm_90 --extended-lambda run-starts-select.cu -o rs && ./rs
#include <cub/agent/single_pass_scan_operators.cuh>
#include <cub/block/block_scan.cuh>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_select.cuh>
#include <cuda/std/functional>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/discard_iterator.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#define CHECK(x)                                                                                                      \
  do                                                                                                                  \
  {                                                                                                                   \
    cudaError_t e = (x);                                                                                              \
    if (e != cudaSuccess)                                                                                             \
    {                                                                                                                 \
      std::printf("%s: %s\n", #x, cudaGetErrorString(e));                                                             \
      std::exit(1);                                                                                                   \
    }                                                                                                                 \
  } while (0)

using Tiles = cub::ScanTileState<unsigned>;
constexpr int kThreads = 256;

__global__ void InitTiles(Tiles tiles, int count) { tiles.InitializeStatus(count); }

template <int Items>
__global__ void __launch_bounds__(kThreads) RunStartsKernel(const std::uint32_t* keys, std::size_t n, int shift,
  std::uint32_t* starts, Tiles tiles)
{
  static_assert(Items % 4 == 0, "loads of four keys");
  using BlockScan = cub::BlockScan<unsigned, kThreads, cub::BLOCK_SCAN_WARP_SCANS>;
  using TilePrefix = cub::TilePrefixCallbackOp<unsigned, ::cuda::std::plus<unsigned>, Tiles>;
  __shared__ typename BlockScan::TempStorage scan;
  __shared__ typename TilePrefix::TempStorage lookBack;
  // Items over the keys' 16-byte aligned base: item g is key g - lead.
  const int lead = static_cast<int>((reinterpret_cast<std::uintptr_t>(keys) / 4) & 3u);
  const std::uint32_t* base = keys - lead;
  const std::size_t items = n + 1 + lead; // the end, n, is a run start too
  const std::size_t first = (std::size_t(blockIdx.x) * kThreads + threadIdx.x) * Items;
  std::uint32_t key[Items];
  const bool whole = first >= std::size_t(lead) && first + Items <= n + lead;
  if (whole)
  {
    for (int v = 0; v < Items / 4; ++v)
    {
      const uint4 q = __ldg(reinterpret_cast<const uint4*>(base + first) + v);
      key[4 * v] = q.x;
      key[4 * v + 1] = q.y;
      key[4 * v + 2] = q.z;
      key[4 * v + 3] = q.w;
    }
  }
  else
  {
    for (int j = 0; j < Items; ++j)
    {
      const std::size_t g = first + j;
      key[j] = g >= std::size_t(lead) && g < n + lead ? __ldg(base + g) : 0u;
    }
  }
  const std::size_t i0 = first - lead; // key index of item 0 (wraps where first < lead)
  std::uint32_t previous = first > std::size_t(lead) && first <= n + lead ? __ldg(base + first - 1) : 0u;
  unsigned flag[Items], rank[Items];
  for (int j = 0; j < Items; ++j)
  {
    const std::size_t g = first + j;
    const std::size_t i = i0 + j;
    flag[j] = g >= std::size_t(lead) && g < items && (i == 0 || i == n || (key[j] >> shift) != (previous >> shift));
    previous = key[j];
  }
  if (blockIdx.x == 0)
  {
    unsigned count;
    BlockScan(scan).ExclusiveSum(flag, rank, count);
    if (threadIdx.x == 0)
    {
      tiles.SetInclusive(0, count);
    }
  }
  else
  {
    TilePrefix before(tiles, lookBack, ::cuda::std::plus<unsigned>(), blockIdx.x);
    BlockScan(scan).ExclusiveSum(flag, rank, before);
  }
  for (int j = 0; j < Items; ++j)
  {
    if (flag[j])
    {
      starts[rank[j]] = static_cast<std::uint32_t>(i0 + j);
    }
  }
}

struct ShiftedEqual
{
  int shift;
  __host__ __device__ bool operator()(std::uint32_t a, std::uint32_t b) const { return (a >> shift) == (b >> shift); }
};

__global__ void WriteEnd(std::uint32_t* starts, const unsigned long long* count, std::uint32_t n)
{
  starts[*count] = n;
}

struct Buffers
{
  void* temp = nullptr;
  std::size_t tempBytes = 0;
  unsigned long long* count = nullptr;
  void* Temp(std::size_t bytes)
  {
    if (bytes > tempBytes)
    {
      CHECK(cudaFree(temp));
      CHECK(cudaMalloc(&temp, bytes));
      tempBytes = bytes;
    }
    return temp;
  }
};

void SelectIf(Buffers& b, const std::uint32_t* keys, std::size_t n, int shift, std::uint32_t* starts)
{
  auto pred = [=] __device__(std::uint32_t i) {
    return i == n || i == 0 || (keys[i] >> shift) != (keys[i - 1] >> shift);
  };
  thrust::counting_iterator<std::uint32_t> in(0);
  std::size_t bytes = 0;
  CHECK(cub::DeviceSelect::If(nullptr, bytes, in, starts, b.count, n + 1, pred));
  CHECK(cub::DeviceSelect::If(b.Temp(bytes), bytes, in, starts, b.count, n + 1, pred));
}

void SelectUnique(Buffers& b, const std::uint32_t* keys, std::size_t n, int shift, std::uint32_t* starts)
{
  thrust::counting_iterator<std::uint32_t> in(0);
  thrust::discard_iterator<> out;
  std::size_t bytes = 0;
  CHECK(cub::DeviceSelect::UniqueByKey(nullptr, bytes, keys, in, out, starts, b.count, n, ShiftedEqual{ shift }));
  CHECK(cub::DeviceSelect::UniqueByKey(b.Temp(bytes), bytes, keys, in, out, starts, b.count, n, ShiftedEqual{ shift }));
  WriteEnd<<<1, 1>>>(starts, b.count, static_cast<std::uint32_t>(n));
}

template <int Items>
void SelectTiles(Buffers& b, const std::uint32_t* keys, std::size_t n, int shift, std::uint32_t* starts)
{
  const std::size_t tile = std::size_t(kThreads) * Items;
  const int tileCount = static_cast<int>((n + 1 + 3 + tile - 1) / tile);
  std::size_t bytes = 0;
  CHECK(Tiles::AllocationSize(tileCount, bytes));
  Tiles tiles;
  CHECK(tiles.Init(tileCount, b.Temp(bytes), bytes));
  InitTiles<<<(tileCount + kThreads - 1) / kThreads, kThreads>>>(tiles, tileCount);
  RunStartsKernel<Items><<<tileCount, kThreads>>>(keys, n, shift, starts, tiles);
}

template <typename Fn>
float Median(Fn fn, int reps)
{
  cudaEvent_t a, z;
  CHECK(cudaEventCreate(&a));
  CHECK(cudaEventCreate(&z));
  std::vector<float> ms;
  for (int r = 0; r < reps + 2; ++r)
  {
    CHECK(cudaEventRecord(a));
    fn();
    CHECK(cudaEventRecord(z));
    CHECK(cudaEventSynchronize(z));
    float t;
    CHECK(cudaEventElapsedTime(&t, a, z));
    if (r >= 2)
    {
      ms.push_back(t);
    }
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

std::vector<std::uint32_t> HostStarts(const std::vector<std::uint32_t>& k, int shift)
{
  std::vector<std::uint32_t> s;
  for (std::size_t i = 0; i < k.size(); ++i)
  {
    if (i == 0 || (k[i] >> shift) != (k[i - 1] >> shift))
    {
      s.push_back(static_cast<std::uint32_t>(i));
    }
  }
  s.push_back(static_cast<std::uint32_t>(k.size()));
  return s;
}

void Case(Buffers& b, const char* what, const std::vector<std::uint32_t>& host, int shift)
{
  const std::size_t n = host.size();
  std::uint32_t *keys = nullptr, *starts = nullptr;
  CHECK(cudaMalloc(&keys, (n + 1) * 4));
  CHECK(cudaMalloc(&starts, (n + 1) * 4));
  CHECK(cudaMemcpy(keys + 1, host.data(), n * 4, cudaMemcpyHostToDevice)); // one key off the 16-byte alignment
  const std::vector<std::uint32_t> expect = HostStarts(host, shift);
  struct Way
  {
    const char* name;
    void (*fn)(Buffers&, const std::uint32_t*, std::size_t, int, std::uint32_t*);
  } ways[] = { { "if", SelectIf }, { "unique", SelectUnique }, { "tiles4", SelectTiles<4> },
    { "tiles8", SelectTiles<8> }, { "tiles16", SelectTiles<16> } };
  float baseline = 0;
  for (const Way& w : ways)
  {
    CHECK(cudaMemset(starts, 0xff, (n + 1) * 4));
    w.fn(b, keys + 1, n, shift, starts);
    CHECK(cudaDeviceSynchronize());
    std::vector<std::uint32_t> got(expect.size());
    CHECK(cudaMemcpy(got.data(), starts, got.size() * 4, cudaMemcpyDeviceToHost));
    const bool same = got == expect;
    const float ms = Median([&] { w.fn(b, keys + 1, n, shift, starts); }, 21);
    if (baseline == 0)
    {
      baseline = ms;
    }
    const double gb = (n * 4.0 + expect.size() * 4.0) / 1e9;
    std::printf("%-28s n=%9zu runs=%9zu %-8s %8.1f us  %.2f TB/s  %.2fx if  %s\n", what, n, expect.size() - 1, w.name,
      ms * 1e3, gb / (ms * 1e-3) / 1e3, ms / baseline, same ? "same starts" : "WRONG STARTS");
  }
  CHECK(cudaFree(keys));
  CHECK(cudaFree(starts));
}

int main()
{
  Buffers b;
  CHECK(cudaMalloc(&b.count, sizeof(unsigned long long)));
  cudaDeviceProp prop;
  CHECK(cudaGetDeviceProperties(&prop, 0));
  std::printf("%s\n", prop.name);
  for (std::size_t n : { std::size_t(10000000), std::size_t(100000000) })
  {
    std::mt19937_64 rng(12345);
    std::vector<std::uint32_t> keys(n);
    for (auto& k : keys)
    {
      k = static_cast<std::uint32_t>(rng() >> 34); // 30 bits: depth 10
    }
    std::sort(keys.begin(), keys.end());
    Case(b, "leaves (points, shift 0)", keys, 0);
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    Case(b, "level 9 (leaves, shift 3)", keys, 3);
    std::vector<std::uint32_t> up;
    for (auto k : keys)
    {
      if (up.empty() || up.back() != (k >> 3))
      {
        up.push_back(k >> 3);
      }
    }
    Case(b, "level 8 (shift 3)", up, 3);
  }
  return 0;
}
