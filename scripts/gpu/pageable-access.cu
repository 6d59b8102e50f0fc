// Ways to move a caller's pageable host array to the device other than the
// engine's staging through page-locked buffers (CudaUpload.h), each timed
// against a plain copy of the same bytes from page-locked memory:
//   register  cudaHostRegister of the array, the copy, cudaHostUnregister;
//   huge      the same on an array the kernel was asked to back with 2 MB
//             pages before it was first touched (madvise MADV_HUGEPAGE);
//   direct    where the device reads pageable memory itself
//             (cudaDevAttrPageableMemoryAccess: HMM or a coherent link), a
//             kernel copying the array straight from its host address: on
//             a fresh array, again on the same array, and then the host's
//             own read of it afterwards (pages the device moved come back);
//   advised   the same after cudaMemAdvise keeps the pages in host memory
//             and maps them for the device.
// Every array is fresh (allocated and filled) unless said otherwise.
//
//   nvcc -O2 -arch=sm_90 -o /tmp/pageable-access scripts/gpu/pageable-access.cu && /tmp/pageable-access [MB]
#include "probe-support.h"

#include <chrono>
#include <cstdint>
#include <cstring>
#include <sys/mman.h>

namespace
{
constexpr int kRounds = 5;
constexpr std::size_t kHugePage = std::size_t(2) << 20;

double Now()
{
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// A fresh array of `bytes` (a multiple of 16), filled, optionally asked for 2 MB pages first.
char* FreshArray(std::size_t bytes, bool huge)
{
  char* p = static_cast<char*>(std::aligned_alloc(kHugePage, (bytes + kHugePage - 1) / kHugePage * kHugePage));
  if (huge)
  {
    madvise(p, bytes, MADV_HUGEPAGE);
  }
  for (std::size_t i = 0; i < bytes; i += 4096)
  {
    p[i] = char(i / 4096);
  }
  return p;
}

__global__ void CopyKernel(const uint4* from, uint4* to, std::size_t n)
{
  for (std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x; i < n; i += std::size_t(gridDim.x) * blockDim.x)
  {
    to[i] = from[i];
  }
}

double KernelCopy(const char* host, char* device, std::size_t bytes)
{
  const double t0 = Now();
  CopyKernel<<<132 * 8, 256>>>(reinterpret_cast<const uint4*>(host), reinterpret_cast<uint4*>(device), bytes / 16);
  Check(cudaDeviceSynchronize(), "direct read kernel");
  return Now() - t0;
}

double HostRead(const char* p, std::size_t bytes)
{
  const double t0 = Now();
  volatile std::uint64_t sum = 0;
  std::uint64_t s = 0;
  for (std::size_t i = 0; i < bytes; i += 4096)
  {
    s += static_cast<unsigned char>(p[i]);
  }
  sum = s;
  (void)sum;
  return Now() - t0;
}

void Register(std::size_t bytes, char* device, bool huge)
{
  std::vector<double> reg, copy, unreg;
  for (int r = 0; r < kRounds; ++r)
  {
    char* p = FreshArray(bytes, huge);
    const double t0 = Now();
    Check(cudaHostRegister(p, bytes, cudaHostRegisterDefault), "cudaHostRegister");
    const double t1 = Now();
    Check(cudaMemcpy(device, p, bytes, cudaMemcpyHostToDevice), "copy");
    const double t2 = Now();
    Check(cudaHostUnregister(p), "cudaHostUnregister");
    const double t3 = Now();
    reg.push_back(t1 - t0), copy.push_back(t2 - t1), unreg.push_back(t3 - t2);
    std::free(p);
  }
  std::printf("%-9s register %.3f ms, copy %.3f ms, unregister %.3f ms (medians of %d fresh arrays)\n",
    huge ? "huge" : "register", Median(reg), Median(copy), Median(unreg), kRounds);
}

void Direct(std::size_t bytes, char* device, bool advised, int gpu)
{
  std::vector<double> advice, first, second, hostAfter;
  for (int r = 0; r < kRounds; ++r)
  {
    char* p = FreshArray(bytes, false);
    const double t0 = Now();
    if (advised)
    {
      cudaMemLocation cpu{cudaMemLocationTypeHost, 0};
      cudaMemLocation dev{cudaMemLocationTypeDevice, gpu};
      Check(cudaMemAdvise(p, bytes, cudaMemAdviseSetPreferredLocation, cpu), "advise preferred location");
      Check(cudaMemAdvise(p, bytes, cudaMemAdviseSetAccessedBy, dev), "advise accessed by");
    }
    advice.push_back(Now() - t0);
    first.push_back(KernelCopy(p, device, bytes));
    second.push_back(KernelCopy(p, device, bytes));
    hostAfter.push_back(HostRead(p, bytes));
    std::free(p);
  }
  std::printf("%-9s advice %.3f ms, kernel read %.3f ms fresh, %.3f ms again, host's read after %.3f ms\n",
    advised ? "advised" : "direct", Median(advice), Median(first), Median(second), Median(hostAfter));
}
}

int main(int argc, char** argv)
{
  const std::size_t bytes = std::size_t(argc > 1 ? std::atof(argv[1]) : 190.0) * 1000000 / 16 * 16;
  int gpu = 0, pageable = 0, hostTables = 0, managed = 0;
  Check(cudaGetDevice(&gpu), "cudaGetDevice");
  cudaDeviceGetAttribute(&pageable, cudaDevAttrPageableMemoryAccess, gpu);
  cudaDeviceGetAttribute(&hostTables, cudaDevAttrPageableMemoryAccessUsesHostPageTables, gpu);
  cudaDeviceGetAttribute(&managed, cudaDevAttrConcurrentManagedAccess, gpu);
  std::printf("pageable memory access %d, through the host's page tables %d, concurrent managed access %d\n", pageable,
    hostTables, managed);

  char* device = nullptr;
  char* pinned = nullptr;
  Check(cudaMalloc(&device, bytes), "cudaMalloc");
  Check(cudaMallocHost(&pinned, bytes), "cudaMallocHost");
  std::memset(pinned, 1, bytes);
  std::vector<double> copies;
  for (int r = 0; r < kRounds; ++r)
  {
    const double t0 = Now();
    Check(cudaMemcpy(device, pinned, bytes, cudaMemcpyHostToDevice), "pinned copy");
    copies.push_back(Now() - t0);
  }
  char* fresh = FreshArray(bytes, false);
  std::printf("pinned    copy %.3f ms of %.1f MB; host's read of a fresh array %.3f ms\n", Median(copies), bytes / 1e6,
    HostRead(fresh, bytes));
  std::free(fresh);
  Register(bytes, device, false);
  Register(bytes, device, true);
  if (pageable)
  {
    Direct(bytes, device, false, gpu);
    Direct(bytes, device, true, gpu);
  }
  return 0;
}
