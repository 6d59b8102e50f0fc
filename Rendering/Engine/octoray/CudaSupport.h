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
void LaunchOn(cudaStream_t stream, const char* name, void (*kernel)(Parameters...), dim3 grid, dim3 block,
  Arguments&&... arguments)
{
  kernel<<<LaunchGrid(name, grid), block, 0, stream>>>(std::forward<Arguments>(arguments)...);
  CudaCheckLaunch(name);
}

// The same on the default stream, where the engine's loops run.
template <typename... Parameters, typename... Arguments>
void Launch(const char* name, void (*kernel)(Parameters...), dim3 grid, dim3 block, Arguments&&... arguments)
{
  LaunchOn(0, name, kernel, grid, block, std::forward<Arguments>(arguments)...);
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
// engine holds. Allocations come from a stream-ordered memory pool of the
// engine's own that keeps freed memory for the next allocations: a rebuild
// fills a new state while the old one lives (kBuildsAside), and mapping
// fresh gigabytes with cudaMalloc and unmapping them with cudaFree (which
// also waits for the whole device) at every rebuild cost more than the
// build's own kernels. What the pool keeps is reported (CachedBytes), given
// back by Trim, and given back before an allocation fails.
class DeviceMemoryPool
{
public:
  std::size_t budget = ~std::size_t(0);
  std::size_t held = 0;

  DeviceMemoryPool() = default;
  DeviceMemoryPool(const DeviceMemoryPool&) = delete;
  DeviceMemoryPool& operator=(const DeviceMemoryPool&) = delete;
  ~DeviceMemoryPool()
  {
    if (Pool)
    {
      cudaMemPoolDestroy(Pool); // memory still being freed goes once its frees complete
    }
  }

  void* Allocate(std::size_t bytes, const char* what)
  {
    if (!bytes)
    {
      return nullptr;
    }
    if (held + bytes > budget)
    {
      throw Error(OutOfMemoryMessage(what, bytes, budget > held ? budget - held : 0) + " within the engine's budget");
    }
    Create();
    void* p = nullptr;
    if (Get(&p, bytes) != cudaSuccess)
    {
      cudaGetLastError();
      Trim();
      if (Get(&p, bytes) != cudaSuccess)
      {
        cudaGetLastError();
        std::size_t freeBytes = 0, totalBytes = 0;
        cudaMemGetInfo(&freeBytes, &totalBytes);
        throw Error(OutOfMemoryMessage(what, bytes, freeBytes) + " on the GPU");
      }
    }
    held += bytes;
    return p;
  }
  void Free(void* p, std::size_t bytes)
  {
    if (p)
    {
      if (Pool)
      {
        cudaFreeAsync(p, 0);
      }
      else
      {
        cudaFree(p);
      }
      held -= bytes;
    }
  }

  // Device memory the pool keeps for later allocations, beyond what is held.
  std::size_t CachedBytes() const
  {
    std::uint64_t reserved = 0, used = 0;
    if (Pool)
    {
      cudaMemPoolGetAttribute(Pool, cudaMemPoolAttrReservedMemCurrent, &reserved);
      cudaMemPoolGetAttribute(Pool, cudaMemPoolAttrUsedMemCurrent, &used);
    }
    return reserved > used ? static_cast<std::size_t>(reserved - used) : 0;
  }
  // Gives what the pool keeps back to the device, once the frees queued so
  // far have run.
  void Trim()
  {
    if (Pool)
    {
      cudaStreamSynchronize(0);
      cudaMemPoolTrimTo(Pool, 0);
    }
  }

private:
  cudaError_t Get(void** p, std::size_t bytes)
  {
    return Pool ? cudaMallocFromPoolAsync(p, bytes, Pool, 0) : cudaMalloc(p, bytes);
  }

  // The pool, on the current device (the engine's), made before the first
  // allocation; it keeps all it frees until trimmed. Where the device has
  // no memory pools, allocations are plain cudaMalloc.
  void Create()
  {
    if (Tried)
    {
      return;
    }
    Tried = true;
    int device = 0;
    cudaGetDevice(&device);
    cudaMemPoolProps props = {};
    props.allocType = cudaMemAllocationTypePinned;
    props.location.type = cudaMemLocationTypeDevice;
    props.location.id = device;
    if (cudaMemPoolCreate(&Pool, &props) != cudaSuccess)
    {
      cudaGetLastError();
      Pool = nullptr;
      return;
    }
    std::uint64_t keepAll = ~std::uint64_t(0);
    cudaMemPoolSetAttribute(Pool, cudaMemPoolAttrReleaseThreshold, &keepAll);
  }

  bool Tried = false;
  cudaMemPool_t Pool = nullptr;
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
