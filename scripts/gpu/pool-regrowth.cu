// What a build without the points (BuildOptions::keepPoints off) pays for
// giving its memory back: the engine's allocator is a CUDA memory pool that
// keeps what it frees (CudaSupport.h's DeviceMemoryPool), and such a build
// trims it to nothing afterwards (Device::TrimCache), so the next build maps
// new memory. Here a pool made as the engine makes it hands out GB in
// arrays of 100 MB (about a 10 M-point build's array), each written once
// (a memset), three ways: the pool empty (new memory mapped), the pool
// holding the memory from before (reused), and the trim that gives it back.
// Host wall time, with the stream synchronised, median of the rounds.
//
//   nvcc -O2 -arch=sm_90 -o /tmp/pool-regrowth scripts/gpu/pool-regrowth.cu && /tmp/pool-regrowth [GB...]
#include "probe-support.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <vector>

namespace
{
constexpr std::size_t kArrayBytes = std::size_t(100) << 20;

double Milliseconds(const std::function<void()>& work)
{
  const auto start = std::chrono::steady_clock::now();
  work();
  Check(cudaStreamSynchronize(0), "cudaStreamSynchronize");
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Arrays of kArrayBytes taking `bytes` from the pool, each written once.
std::vector<void*> TakeAndWrite(cudaMemPool_t pool, std::size_t bytes)
{
  std::vector<void*> arrays(bytes / kArrayBytes);
  for (void*& p : arrays)
  {
    Check(cudaMallocFromPoolAsync(&p, kArrayBytes, pool, 0), "cudaMallocFromPoolAsync");
    Check(cudaMemsetAsync(p, 0, kArrayBytes, 0), "cudaMemsetAsync");
  }
  return arrays;
}

void GiveBack(const std::vector<void*>& arrays)
{
  for (void* p : arrays)
  {
    Check(cudaFreeAsync(p, 0), "cudaFreeAsync");
  }
}
}

int main(int argc, char** argv)
{
  std::vector<double> sizes;
  for (int a = 1; a < argc; ++a)
  {
    sizes.push_back(std::atof(argv[a]));
  }
  if (sizes.empty())
  {
    sizes = { 0.8, 1.6, 6.4 };
  }
  int device = 0;
  Check(cudaGetDevice(&device), "cudaGetDevice");
  cudaMemPoolProps props = {};
  props.allocType = cudaMemAllocationTypePinned;
  props.location.type = cudaMemLocationTypeDevice;
  props.location.id = device;
  cudaMemPool_t pool;
  Check(cudaMemPoolCreate(&pool, &props), "cudaMemPoolCreate");
  std::uint64_t keepAll = ~std::uint64_t(0);
  Check(cudaMemPoolSetAttribute(pool, cudaMemPoolAttrReleaseThreshold, &keepAll), "cudaMemPoolSetAttribute");
  const int rounds = 7;
  for (double gb : sizes)
  {
    const std::size_t bytes = static_cast<std::size_t>(gb * 1e9) / kArrayBytes * kArrayBytes;
    std::vector<double> mapped, reused, trimmed;
    for (int r = 0; r < rounds; ++r)
    {
      std::vector<void*> arrays;
      mapped.push_back(Milliseconds([&] { arrays = TakeAndWrite(pool, bytes); }));
      GiveBack(arrays);
      reused.push_back(Milliseconds([&] { arrays = TakeAndWrite(pool, bytes); }));
      GiveBack(arrays);
      trimmed.push_back(Milliseconds([&] { // as the engine's DeviceMemoryPool::Trim: the frees first
        Check(cudaStreamSynchronize(0), "cudaStreamSynchronize");
        Check(cudaMemPoolTrimTo(pool, 0), "cudaMemPoolTrimTo");
      }));
    }
    const double mb = bytes / 1e6;
    std::printf("%.0f MB in arrays of %zu MB, each written once (median of %d): new memory %.3f ms, reused %.3f ms, "
                "so mapping costs %.3f ms a GB; the trim that gives it back %.3f ms (%.3f ms a GB)\n",
      mb, kArrayBytes >> 20, rounds, Median(mapped), Median(reused), (Median(mapped) - Median(reused)) / (mb / 1e3),
      Median(trimmed), Median(trimmed) / (mb / 1e3));
  }
  return 0;
}
