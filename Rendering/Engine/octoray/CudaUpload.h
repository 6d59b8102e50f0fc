// Copies of a caller's arrays to the device at the speed of page-locked
// memory. A VTK array lives in ordinary (pageable) host memory, from which
// cudaMemcpy goes through the driver's own small bounce buffer at a
// fraction of what the bus carries (octoray_bench_cuda measures both
// beside the engine's own upload). Large arrays are cut into stripes,
// one per host thread; each thread copies its stripe through two pinned
// buffers of its own, filling one while the copy engine reads the other,
// so the host copies and the DMA overlap and several host threads keep
// the bus busy; the threads and buffers are made at the first such copy
// and kept. Arrays already in device memory (a CUDA simulation's) and
// page-locked host arrays are copied directly. A caller may queue work on
// each piece as it lands (Landed), which then runs while the rest of the
// array is still on its way. Only compiled by nvcc.
#pragma once

#include "CudaSupport.h"
#include "Parallel.h"
#include "StagingPieces.h"

#include <algorithm>
#include <cstring>
#include <functional>
#include <memory>
#include <vector>

namespace octoray
{
namespace cuda
{
// Below this many bytes cudaMemcpy from pageable memory (through the
// driver's own bounce buffer, a fraction of the bus's speed) takes about as
// long as waking the staging threads and queueing their pieces.
constexpr std::size_t kStagingThreshold = std::size_t(1) << 20;
// Work queued on a piece of a copy, bytes [begin, end) of the destination,
// once it has landed: on `stream`, in whose order the piece's copy ran.
using Landed = std::function<void(std::size_t begin, std::size_t end, cudaStream_t stream)>;

// Whether CUDA can copy from `p` without staging: device, managed or
// page-locked host memory.
inline bool DirectlyCopyable(const void* p)
{
  cudaPointerAttributes attributes;
  if (cudaPointerGetAttributes(&attributes, p) != cudaSuccess)
  {
    cudaGetLastError();
    return false;
  }
  return attributes.type != cudaMemoryTypeUnregistered;
}

// Whether a copy must first wait for the loops queued on the default
// stream: it must where its destination may be memory that one of them
// still reads (freed and taken again in the stream's order).
enum class QueuedLoops
{
  WaitFor,
  MayRun
};

class HostStaging
{
public:
  HostStaging() = default;
  HostStaging(const HostStaging&) = delete;
  HostStaging& operator=(const HostStaging&) = delete;
  ~HostStaging() { Free(); }

  // Copies `bytes` from `source` (host or device memory) to `device` on the
  // current device; returns once the copy, and the work `landed` queued on
  // its pieces, is complete.
  void Copy(void* device, const void* source, std::size_t bytes, const char* what,
    QueuedLoops queued = QueuedLoops::WaitFor, const Landed& landed = nullptr)
  {
    if (bytes < kStagingThreshold || DirectlyCopyable(source) || !Allocate())
    {
      CudaCheck(cudaMemcpy(device, source, bytes, cudaMemcpyDefault), what);
      if (landed)
      {
        landed(0, bytes, 0);
        CudaCheck(cudaStreamSynchronize(0), what);
      }
      return;
    }
    int current = 0;
    CudaCheck(cudaGetDevice(&current), "cudaGetDevice");
    // The staging streams do not wait for the default stream by themselves.
    if (queued == QueuedLoops::WaitFor)
    {
      CudaCheck(cudaStreamSynchronize(0), what);
    }
    Workers->Run(StripeUnits(bytes), [&](std::size_t first, std::size_t last, int stripe) {
      CudaCheck(cudaSetDevice(current), "cudaSetDevice"); // the current device is per thread
      CopyStripe(Lanes[stripe], static_cast<char*>(device), static_cast<const char*>(source),
        StripeBytes(first, last, bytes), what, landed);
    });
  }

private:
  // One staging thread's stream, pinned buffers and their events.
  struct Lane
  {
    cudaStream_t stream = nullptr;
    void* pinned[2] = { nullptr, nullptr };
    cudaEvent_t copied[2] = { nullptr, nullptr };
  };

  // A stripe of the copy, through the lane's two pinned buffers in turn.
  // Returns, or throws, once the lane has finished what it queued: the
  // destination may be freed right after.
  static void CopyStripe(Lane& lane, char* device, const char* source, Stripe stripe, const char* what,
    const Landed& landed)
  {
    struct Drain
    {
      cudaStream_t stream;
      ~Drain() { cudaStreamSynchronize(stream); }
    } drain{ lane.stream };
    ForEachPiece(stripe, [&](std::size_t offset, std::size_t n, int b) {
      CudaCheck(cudaEventSynchronize(lane.copied[b]), what); // the DMA from this buffer is done
      std::memcpy(lane.pinned[b], source + offset, n);
      CudaCheck(cudaMemcpyAsync(device + offset, lane.pinned[b], n, cudaMemcpyHostToDevice, lane.stream), what);
      CudaCheck(cudaEventRecord(lane.copied[b], lane.stream), what);
      if (landed)
      {
        landed(offset, offset + n, lane.stream);
      }
    });
    CudaCheck(cudaStreamSynchronize(lane.stream), what);
  }

  // The lanes and their threads, made at the first large copy and kept;
  // false (and the plain copy taken) where page-locked memory cannot be had.
  bool Allocate()
  {
    if (!Lanes.empty())
    {
      return true;
    }
    const int threads = std::min(kMaxStagingThreads, DefaultThreadCount());
    Lanes.resize(threads);
    for (Lane& lane : Lanes)
    {
      bool made = cudaStreamCreateWithFlags(&lane.stream, cudaStreamNonBlocking) == cudaSuccess;
      for (int b = 0; b < 2; ++b)
      {
        made = made && cudaMallocHost(&lane.pinned[b], kStagingPiece) == cudaSuccess &&
          cudaEventCreateWithFlags(&lane.copied[b], cudaEventDisableTiming) == cudaSuccess &&
          cudaEventRecord(lane.copied[b], lane.stream) == cudaSuccess;
      }
      if (!made)
      {
        cudaGetLastError();
        Free();
        return false;
      }
    }
    Workers = std::make_unique<ChunkWorkers>(threads);
    return true;
  }

  void Free()
  {
    Workers.reset();
    for (Lane& lane : Lanes)
    {
      for (int b = 0; b < 2; ++b)
      {
        if (lane.copied[b])
        {
          cudaEventDestroy(lane.copied[b]);
        }
        if (lane.pinned[b])
        {
          cudaFreeHost(lane.pinned[b]);
        }
      }
      if (lane.stream)
      {
        cudaStreamDestroy(lane.stream);
      }
    }
    Lanes.clear();
  }

  std::vector<Lane> Lanes;
  std::unique_ptr<ChunkWorkers> Workers; // one stripe each
};
}
}
