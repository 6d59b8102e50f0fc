// Whether the automatic depth, where its provisional sort (32-bit keys of 10
// levels) does not settle the depth rule, could order the points within
// that sort's runs instead of sorting every key again: the points of one
// level-10 cell are already together, so full-depth order is each run
// sorted by its full keys. Timed here on the build benchmark's clouds
// (octoray_bench_build's GaussianClusters, sets "clustered" and "narrow"),
// device arrays, CUDA events, median of the rounds:
//   global D     the engine's way: keys of D levels made in the points' order,
//                sorted with the points' indices (cub::DeviceRadixSort, 3D bits)
//   runs         the provisional sort's run starts (flags, cub::DeviceSelect)
//   gather       each sorted point's full-depth key, read through its index
//   segmented    cub::DeviceSegmentedSort::StableSortPairs of those keys with
//                the indices, a segment a run
// and the check that segmented order equals global 21's.
//
//   nvcc -O3 -std=c++17 -arch=sm_90 --expt-relaxed-constexpr -I Rendering/Engine -o /tmp/segmented-resort \
//     scripts/gpu/segmented-resort.cu && /tmp/segmented-resort [POINTS...]
#include "probe-support.h"

#include "../../Benchmarks/Engine/BenchUtil.h"

#include <octoray/Morton.h>

#include <cub/cub.cuh>
#include <thrust/iterator/counting_iterator.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace
{
using octoray::EncodeMortonAt;

struct Cube
{
  float lo[3];
  float scale; // cells of full depth per unit
};

__device__ std::uint64_t KeyOf(const float* xyz, std::uint32_t i, const Cube& c, int depth)
{
  std::uint32_t cell[3];
  for (int a = 0; a < 3; ++a)
  {
    const float v = (xyz[3 * i + a] - c.lo[a]) * c.scale;
    cell[a] = min(static_cast<std::uint32_t>(max(v, 0.0f)), (1u << octoray::kMaxLevel) - 1);
  }
  return EncodeMortonAt(cell[0], cell[1], cell[2], depth);
}

template <typename Key>
__global__ void KeysKernel(const float* xyz, std::uint32_t n, Cube c, int depth, Key* keys, std::uint32_t* index)
{
  const std::uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n)
  {
    keys[i] = static_cast<Key>(KeyOf(xyz, i, c, depth));
    index[i] = i;
  }
}

__global__ void RunFlagsKernel(const std::uint32_t* keys, std::uint32_t n, char* flags)
{
  const std::uint32_t s = blockIdx.x * blockDim.x + threadIdx.x;
  if (s < n)
  {
    flags[s] = s == 0 || keys[s] != keys[s - 1];
  }
}

__global__ void GatherKeysKernel(
  const float* xyz, const std::uint32_t* index, std::uint32_t n, Cube c, std::uint64_t* keys)
{
  const std::uint32_t s = blockIdx.x * blockDim.x + threadIdx.x;
  if (s < n)
  {
    keys[s] = KeyOf(xyz, index[s], c, octoray::kMaxLevel);
  }
}

unsigned Blocks(std::size_t n)
{
  return static_cast<unsigned>((n + 255) / 256);
}

// Milliseconds of `work` on the default stream.
float Time(const std::function<void()>& work)
{
  cudaEvent_t begin, end;
  Check(cudaEventCreate(&begin), "cudaEventCreate");
  Check(cudaEventCreate(&end), "cudaEventCreate");
  Check(cudaEventRecord(begin), "cudaEventRecord");
  work();
  Check(cudaEventRecord(end), "cudaEventRecord");
  Check(cudaEventSynchronize(end), "cudaEventSynchronize");
  float ms = 0;
  Check(cudaEventElapsedTime(&ms, begin, end), "cudaEventElapsedTime");
  cudaEventDestroy(begin);
  cudaEventDestroy(end);
  return ms;
}

template <typename T>
T* DeviceArray(std::size_t n)
{
  T* p = nullptr;
  Check(cudaMalloc(&p, n * sizeof(T)), "cudaMalloc");
  return p;
}

struct Temporary
{
  void* data = nullptr;
  std::size_t bytes = 0;
  void* Fit(std::size_t wanted)
  {
    if (wanted > bytes)
    {
      cudaFree(data);
      Check(cudaMalloc(&data, wanted), "cudaMalloc temporary");
      bytes = wanted;
    }
    return data;
  }
};

void Probe(std::size_t n, const char* set, double sigma, int rounds)
{
  const std::vector<float> host = octoray::bench::GaussianClusters(n, 32, sigma);
  Cube cube{ { host[0], host[1], host[2] }, 0 };
  float hi[3] = { host[0], host[1], host[2] };
  for (std::size_t i = 0; i < n; ++i)
  {
    for (int a = 0; a < 3; ++a)
    {
      cube.lo[a] = std::min(cube.lo[a], host[3 * i + a]);
      hi[a] = std::max(hi[a], host[3 * i + a]);
    }
  }
  const float size = std::max({ hi[0] - cube.lo[0], hi[1] - cube.lo[1], hi[2] - cube.lo[2] }) * 1.0001f;
  cube.scale = static_cast<float>(1u << octoray::kMaxLevel) / size;

  const std::uint32_t count = static_cast<std::uint32_t>(n);
  float* xyz = DeviceArray<float>(3 * n);
  Check(cudaMemcpy(xyz, host.data(), 3 * n * sizeof(float), cudaMemcpyHostToDevice), "upload");
  std::uint64_t* wide[2] = { DeviceArray<std::uint64_t>(n), DeviceArray<std::uint64_t>(n) };
  std::uint32_t* narrow[2] = { DeviceArray<std::uint32_t>(n), DeviceArray<std::uint32_t>(n) };
  std::uint32_t* index[2] = { DeviceArray<std::uint32_t>(n), DeviceArray<std::uint32_t>(n) };
  std::uint32_t* offsets = DeviceArray<std::uint32_t>(n + 1);
  std::uint32_t* segments = DeviceArray<std::uint32_t>(1);
  char* flags = DeviceArray<char>(n);
  Temporary temp;
  std::size_t bytes = 0;

  // The global sorts at 16 levels and at full depth.
  std::vector<std::vector<float>> global(2);
  std::vector<std::uint64_t> reference(n);
  for (int r = 0; r < rounds; ++r)
  {
    for (int g = 0; g < 2; ++g)
    {
      const int depth = g == 0 ? 16 : octoray::kMaxLevel;
      global[g].push_back(Time([&] {
        KeysKernel<<<Blocks(n), 256>>>(xyz, count, cube, depth, wide[0], index[0]);
        cub::DoubleBuffer<std::uint64_t> k(wide[0], wide[1]);
        cub::DoubleBuffer<std::uint32_t> v(index[0], index[1]);
        cub::DeviceRadixSort::SortPairs(nullptr, bytes, k, v, n, 0, 3 * depth);
        cub::DeviceRadixSort::SortPairs(temp.Fit(bytes), bytes, k, v, n, 0, 3 * depth);
        if (depth == octoray::kMaxLevel && r == 0)
        {
          Check(cudaMemcpy(reference.data(), k.Current(), n * 8, cudaMemcpyDeviceToHost), "reference");
        }
      }));
    }
  }

  // The provisional sort, untimed, then its runs, the gather, the segmented sort.
  std::vector<float> runs, gather, segmented;
  std::uint32_t segmentCount = 0, largest = 0;
  bool same = true;
  for (int r = 0; r < rounds; ++r)
  {
    KeysKernel<<<Blocks(n), 256>>>(xyz, count, cube, 10, narrow[0], index[0]);
    cub::DoubleBuffer<std::uint32_t> k(narrow[0], narrow[1]);
    cub::DoubleBuffer<std::uint32_t> v(index[0], index[1]);
    cub::DeviceRadixSort::SortPairs(nullptr, bytes, k, v, n, 0, 30);
    cub::DeviceRadixSort::SortPairs(temp.Fit(bytes), bytes, k, v, n, 0, 30);
    Check(cudaDeviceSynchronize(), "provisional sort");
    runs.push_back(Time([&] {
      RunFlagsKernel<<<Blocks(n), 256>>>(k.Current(), count, flags);
      thrust::counting_iterator<std::uint32_t> iota(0);
      cub::DeviceSelect::Flagged(nullptr, bytes, iota, flags, offsets, segments, n);
      cub::DeviceSelect::Flagged(temp.Fit(bytes), bytes, iota, flags, offsets, segments, n);
    }));
    Check(cudaMemcpy(&segmentCount, segments, 4, cudaMemcpyDeviceToHost), "segments");
    Check(cudaMemcpy(offsets + segmentCount, &count, 4, cudaMemcpyHostToDevice), "last offset");
    gather.push_back(Time([&] { GatherKeysKernel<<<Blocks(n), 256>>>(xyz, v.Current(), count, cube, wide[0]); }));
    std::uint32_t* sortedIndex = v.Current();
    std::uint32_t* otherIndex = v.Alternate();
    segmented.push_back(Time([&] {
      cub::DeviceSegmentedSort::StableSortPairs(nullptr, bytes, wide[0], wide[1], sortedIndex, otherIndex, n,
        segmentCount, offsets, offsets + 1);
      cub::DeviceSegmentedSort::StableSortPairs(temp.Fit(bytes), bytes, wide[0], wide[1], sortedIndex, otherIndex,
        n, segmentCount, offsets, offsets + 1);
    }));
    if (r == 0)
    {
      std::vector<std::uint32_t> o(segmentCount + 1);
      Check(cudaMemcpy(o.data(), offsets, 4 * o.size(), cudaMemcpyDeviceToHost), "offsets");
      for (std::uint32_t s = 0; s < segmentCount; ++s)
      {
        largest = std::max(largest, o[s + 1] - o[s]);
      }
      std::vector<std::uint64_t> keys(n);
      Check(cudaMemcpy(keys.data(), wide[1], n * 8, cudaMemcpyDeviceToHost), "keys");
      same = keys == reference;
    }
  }
  Check(cudaGetLastError(), "kernels");
  std::printf("%zu %s points (sigma %g): global 16 %.3f ms, global 21 %.3f ms; runs %.3f + gather %.3f + segmented "
              "%.3f = %.3f ms (%u runs, largest %u); order equal to global 21's: %s\n",
    n, set, sigma, Median(global[0]), Median(global[1]), Median(runs), Median(gather), Median(segmented),
    Median(runs) + Median(gather) + Median(segmented), segmentCount, largest, same ? "yes" : "NO");
  for (void* p : { (void*)xyz, (void*)wide[0], (void*)wide[1], (void*)narrow[0], (void*)narrow[1],
         (void*)index[0], (void*)index[1], (void*)offsets, (void*)segments, (void*)flags, temp.data })
  {
    cudaFree(p);
  }
}
}

int main(int argc, char** argv)
{
  std::vector<std::size_t> counts;
  for (int a = 1; a < argc; ++a)
  {
    counts.push_back(static_cast<std::size_t>(std::strtod(argv[a], nullptr)));
  }
  if (counts.empty())
  {
    counts = { 10000000, 100000000 };
  }
  for (std::size_t n : counts)
  {
    Probe(n, "clustered", 0.02, 5);
    Probe(n, "narrow", 1e-4, 5);
  }
  cudaDeviceProp p;
  Check(cudaGetDeviceProperties(&p, 0), "cudaGetDeviceProperties");
  std::printf("%s\n", p.name);
  return 0;
}
