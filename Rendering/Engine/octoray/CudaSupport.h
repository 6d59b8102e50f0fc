// Checked CUDA calls, named kernel launches, and device buffers that count
// against a memory budget. Only compiled by nvcc (CudaDevice.h, CudaEngine.cu).
#pragma once

#include "FaultInjection.h"
#include "Types.h"
#include "Validation.h"

#include <cuda_runtime.h>

#include <string>
#include <utility>

namespace octoray
{
// Throws Error naming the call (or kernel) that failed and CUDA's reason.
inline void CudaCheck(cudaError_t status, const char* what)
{
  if (status != cudaSuccess)
  {
    cudaGetLastError(); // clear a sticky launch error so later calls can proceed
    throw Error(std::string("octoray: CUDA ") + what + " failed: " + cudaGetErrorString(status));
  }
}

// After a kernel launch: configuration errors at once, faults at the next sync.
inline void CudaCheckLaunch(const char* kernel)
{
  CudaCheck(cudaGetLastError(), (std::string("launch of ") + kernel).c_str());
}

// The grid a launch of `kernel` uses: `grid`, or an empty one that the
// runtime refuses when a test has asked for this launch to fail
// (InjectCudaLaunchFailure).
inline dim3 LaunchGrid(const char* kernel, dim3 grid)
{
  return TakeInjectedLaunchFailure(kernel) ? dim3(0, 1, 1) : grid;
}

// Every kernel launch of the engine: under the name that its failure
// reports and that a test can refuse (the name of a __global__ function, or
// of the loop CudaDevice::ForEach runs), checked at once.
template <typename... Parameters, typename... Arguments>
void Launch(const char* name, void (*kernel)(Parameters...), dim3 grid, dim3 block, Arguments&&... arguments)
{
  kernel<<<LaunchGrid(name, grid), block>>>(std::forward<Arguments>(arguments)...);
  CudaCheckLaunch(name);
}

// Makes an engine's device current for the scope of one of its calls and
// restores the caller's afterwards, so that engines on different devices
// (one mapper per GPU) live in one process and never disturb a caller's own
// CUDA work.
class ScopedDevice
{
public:
  explicit ScopedDevice(int device)
  {
    cudaGetDevice(&Previous);
    if (device >= 0 && device != Previous)
    {
      CudaCheck(cudaSetDevice(device), "cudaSetDevice");
      Changed = true;
    }
  }
  ~ScopedDevice()
  {
    if (Changed)
    {
      cudaSetDevice(Previous);
    }
  }
  ScopedDevice(const ScopedDevice&) = delete;
  ScopedDevice& operator=(const ScopedDevice&) = delete;

private:
  int Previous = 0;
  bool Changed = false;
};

// Every device allocation of one engine goes through this: it enforces a
// budget (set to test and to live with out-of-memory) and reports what the
// engine holds.
struct DeviceMemoryPool
{
  std::size_t budget = ~std::size_t(0);
  std::size_t held = 0;

  void* Allocate(std::size_t bytes, const char* what)
  {
    if (!bytes)
    {
      return nullptr;
    }
    std::size_t freeBytes = 0, totalBytes = 0;
    cudaMemGetInfo(&freeBytes, &totalBytes);
    if (held + bytes > budget)
    {
      throw Error(OutOfMemoryMessage(what, bytes, budget > held ? budget - held : 0) + " within the engine's budget");
    }
    void* p = nullptr;
    if (cudaMalloc(&p, bytes) != cudaSuccess)
    {
      cudaGetLastError();
      throw Error(OutOfMemoryMessage(what, bytes, freeBytes) + " on the GPU");
    }
    held += bytes;
    return p;
  }
  void Free(void* p, std::size_t bytes)
  {
    if (p)
    {
      cudaFree(p);
      held -= bytes;
    }
  }
};

template <typename T>
class DeviceBuffer
{
public:
  DeviceBuffer() = default;
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& o) noexcept { Swap(o); }
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept
  {
    Swap(o);
    return *this;
  }
  ~DeviceBuffer() { Release(); }

  // Ensures room for n elements; keeps the allocation when it is big enough.
  void Reserve(DeviceMemoryPool& pool, std::size_t n, const char* what)
  {
    if (n <= Capacity && Pool == &pool)
    {
      Size = n;
      return;
    }
    Release();
    Data = static_cast<T*>(pool.Allocate(n * sizeof(T), what));
    Pool = &pool;
    Capacity = n;
    Size = n;
  }
  void Release()
  {
    if (Pool)
    {
      Pool->Free(Data, Capacity * sizeof(T));
    }
    Data = nullptr;
    Pool = nullptr;
    Capacity = Size = 0;
  }
  void Swap(DeviceBuffer& o) noexcept
  {
    std::swap(Data, o.Data);
    std::swap(Pool, o.Pool);
    std::swap(Capacity, o.Capacity);
    std::swap(Size, o.Size);
  }

  T* Get() const { return Data; }
  std::size_t Count() const { return Size; }
  std::size_t Bytes() const { return Capacity * sizeof(T); }
  bool Empty() const { return Size == 0; }

private:
  T* Data = nullptr;
  DeviceMemoryPool* Pool = nullptr;
  std::size_t Capacity = 0;
  std::size_t Size = 0;
};
}
