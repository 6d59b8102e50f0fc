// Copies of a caller's arrays to the device at the speed of page-locked
// memory. A VTK array lives in ordinary (pageable) host memory, from which
// cudaMemcpy goes through the driver's own small bounce buffer at a
// fraction of what the bus carries (octoray_bench_cuda measures both
// beside the engine's own upload). The arrays of one copy are laid end
// to end and cut into pieces (StagingPieces.h), which a team of host
// threads take in turn, so that one pass of the threads serves them all;
// each thread copies its pieces through two pinned buffers of its own,
// filling one while the copy engine reads the other, so the host copies and
// the DMA overlap and several host threads keep the bus busy; the threads
// and buffers are made at the first such copy and kept. Arrays already in
// device memory (a CUDA simulation's) and page-locked host arrays are
// copied directly. A caller may queue work on the whole first array once
// it has landed, while the others are still on their way (Copy's
// afterFirst). Only compiled by nvcc.
#pragma once

#include "CudaSupport.h"
#include "Parallel.h"
#include "Scalar16.h"
#include "StagingPieces.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace octoray
{
namespace cuda
{
// Below this many bytes (a copy's pageable arrays together) cudaMemcpy
// from pageable memory (through the driver's own bounce buffer, a fraction
// of the bus's speed) takes about as long as waking the staging threads
// and queueing their pieces.
constexpr std::size_t kStagingThreshold = std::size_t(1) << 20;

// Where the device reads `p` if CUDA can copy from it without staging
// (device, managed or page-locked host memory); else null.
inline const void* DeviceReadable(const void* p)
{
  cudaPointerAttributes attributes;
  if (cudaPointerGetAttributes(&attributes, p) != cudaSuccess)
  {
    cudaGetLastError();
    return nullptr;
  }
  return attributes.type != cudaMemoryTypeUnregistered ? attributes.devicePointer : nullptr;
}

inline bool DirectlyCopyable(const void* p)
{
  return DeviceReadable(p) != nullptr;
}

// One array of a copy: `bytes` from `source` (host or device memory) to
// `device`. A part of unit codes takes floats from pageable host memory and
// lands their Scalar16 codes (EncodeUnitScalars, made as each piece is
// staged; `bytes` counts the codes): half the bytes over the bus.
struct CopyPart
{
  void* device;
  const void* source;
  std::size_t bytes;
  std::string what; // names the array in an error
  bool unitCodes = false;
};

// The bytes [offset, offset + bytes) of a part as they land, written to
// `to` on the host: the source's, or the codes of its floats.
inline void FillPiece(const CopyPart& part, std::size_t offset, std::size_t bytes, void* to)
{
  if (part.unitCodes)
  {
    EncodeUnitScalars(static_cast<const float*>(part.source) + offset / sizeof(std::uint16_t),
      bytes / sizeof(std::uint16_t), static_cast<std::uint16_t*>(to));
    return;
  }
  std::memcpy(to, static_cast<const char*>(part.source) + offset, bytes);
}

// The staged parts laid end to end (StagingPieces.h), the pieces of unit
// codes half as long.
inline StagingRun RunOf(const std::vector<CopyPart>& parts)
{
  std::vector<std::size_t> bytes;
  std::vector<bool> halved;
  for (const CopyPart& part : parts)
  {
    bytes.push_back(part.bytes);
    halved.push_back(part.unitCodes);
  }
  return StagingRun(bytes, halved);
}

class HostStaging
{
public:
  HostStaging() = default;
  HostStaging(const HostStaging&) = delete;
  HostStaging& operator=(const HostStaging&) = delete;
  ~HostStaging() { Free(); }

  // Copies `bytes` from `source` (host or device memory) to `device` on the
  // current device; returns once the copy is complete.
  void Copy(void* device, const void* source, std::size_t bytes, const char* what)
  {
    Copy({ CopyPart{ device, source, bytes, what } });
  }

  // Copies every part, after the loops queued on the default stream (the
  // staging streams do not wait for them by themselves); returns once the
  // copies are complete. Parts CUDA copies directly go so; the others are
  // staged in one pass.
  // Where the first part is staged with others, afterFirst(), if given,
  // runs on the host as soon as that part's pieces are queued, with the
  // default stream waiting for them, while the others are still on their
  // way: it can queue loops over the first part that overlap the rest of
  // the copy. It may run on a staging thread; what it throws reaches the
  // caller once every part is copied. Returns whether it ran: where nothing
  // is left on its way, there is nothing to overlap.
  bool Copy(const std::vector<CopyPart>& parts, const std::function<void()>& afterFirst = nullptr)
  {
    std::vector<CopyPart> staged;
    bool firstStaged = false;
    for (const CopyPart& part : parts)
    {
      if (DirectlyCopyable(part.source))
      {
        if (part.unitCodes)
        {
          // CudaDevice::PrepareUnitCodes makes those by a loop on the device.
          throw Error("octoray: internal: the staging asked for the codes of " + part.what + " in device memory");
        }
        CopyDirectly(part);
      }
      else
      {
        firstStaged = firstStaged || &part == &parts.front();
        staged.push_back(part);
      }
    }
    const StagingRun run = RunOf(staged);
    if (run.Length() < kStagingThreshold || !Allocate())
    {
      std::for_each(staged.begin(), staged.end(), CopyDirectly);
      return false;
    }
    const bool overlap = afterFirst && firstStaged && staged.size() > 1;
    int current = 0;
    CudaCheck(cudaGetDevice(&current), "cudaGetDevice");
    CudaCheck(cudaStreamSynchronize(0), staged.front().what.c_str());
    std::vector<Piece> pieces = CutPieces(run, Workers->Chunks());
    FirstPartWatch watch(Lanes, pieces, overlap ? afterFirst : nullptr);
    PieceDealer dealer(std::move(pieces));
    Workers->Run(Lanes.size(), [&](std::size_t lane, std::size_t, int) {
      CudaCheck(cudaSetDevice(current), "cudaSetDevice"); // the current device is per thread
      CopyPieces(Lanes[lane], staged, dealer, watch);
    });
    return overlap;
  }

private:
  // One staging thread's stream, pinned buffers and their events.
  struct Lane
  {
    cudaStream_t stream = nullptr;
    void* pinned[2] = { nullptr, nullptr };
    cudaEvent_t copied[2] = { nullptr, nullptr };
    cudaEvent_t firstQueued = nullptr; // after this lane's last piece of a copy's first part
  };

  // Runs a copy's afterFirst once the lanes have queued every piece of
  // its first part: each lane marks its stream after each such piece, and
  // the lane that queues the last one makes the default stream wait for
  // every lane's mark. A lane that took none in this copy holds a mark
  // long passed, or none, which the default stream does not wait for.
  class FirstPartWatch
  {
  public:
    FirstPartWatch(const std::vector<Lane>& lanes, const std::vector<Piece>& pieces, std::function<void()> then)
      : Lanes(lanes)
      , Then(std::move(then))
      , Left(std::count_if(pieces.begin(), pieces.end(), [](const Piece& p) { return p.array == 0; }))
    {
      if (Then && Left == 0)
      {
        Then();
      }
    }
    // After `lane` queued a piece of array `array`.
    void Queued(const Lane& lane, std::size_t array, const char* what)
    {
      if (!Then || array != 0)
      {
        return;
      }
      CudaCheck(cudaEventRecord(lane.firstQueued, lane.stream), what);
      if (Left.fetch_sub(1) == 1)
      {
        for (const Lane& other : Lanes)
        {
          CudaCheck(cudaStreamWaitEvent(0, other.firstQueued, 0), what);
        }
        Then();
      }
    }

  private:
    const std::vector<Lane>& Lanes;
    const std::function<void()> Then;
    std::atomic<std::ptrdiff_t> Left;
  };

  // cudaMemcpy, which goes from pageable memory through the driver's own
  // bounce buffer.
  static void CopyDirectly(const CopyPart& part)
  {
    std::vector<std::uint16_t> codes;
    const void* source = part.source;
    if (part.unitCodes)
    {
      codes.resize(part.bytes / sizeof(std::uint16_t));
      FillPiece(part, 0, part.bytes, codes.data());
      source = codes.data();
    }
    CudaCheck(cudaMemcpy(part.device, source, part.bytes, cudaMemcpyDefault), part.what.c_str());
  }

  // The pieces this lane's thread takes, through the lane's two pinned
  // buffers in turn. Returns, or throws, once the lane has finished what it
  // queued: the destinations may be freed right after.
  static void CopyPieces(Lane& lane, const std::vector<CopyPart>& parts, PieceDealer& dealer, FirstPartWatch& watch)
  {
    struct Drain
    {
      cudaStream_t stream;
      ~Drain() { cudaStreamSynchronize(stream); }
    } drain{ lane.stream };
    const char* what = parts.front().what.c_str();
    dealer.Take([&](const Piece& piece, int b) {
      const CopyPart& part = parts[piece.array];
      const std::size_t offset = piece.offset, n = piece.bytes;
      what = part.what.c_str();
      CudaCheck(cudaEventSynchronize(lane.copied[b]), what); // the DMA from this buffer is done
      FillPiece(part, offset, n, lane.pinned[b]);
      CudaCheck(cudaMemcpyAsync(static_cast<char*>(part.device) + offset, lane.pinned[b], n,
                  cudaMemcpyHostToDevice, lane.stream),
        what);
      CudaCheck(cudaEventRecord(lane.copied[b], lane.stream), what);
      watch.Queued(lane, piece.array, what);
    });
    CudaCheck(cudaStreamSynchronize(lane.stream), what);
  }

  // The lanes and their threads, made at the first large copy and kept;
  // false (and the plain copy taken) where page-locked memory cannot be had.
  // Each buffer is an allocation of its own, in the host's 4 kB pages: all
  // of them in one region of 2 MB pages staged no faster, in nine rounds on
  // H200s (Benchmarks/gpu/variants-hugepages.txt).
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
      made = made && cudaEventCreateWithFlags(&lane.firstQueued, cudaEventDisableTiming) == cudaSuccess;
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
      if (lane.firstQueued)
      {
        cudaEventDestroy(lane.firstQueued);
      }
      if (lane.stream)
      {
        cudaStreamDestroy(lane.stream);
      }
    }
    Lanes.clear();
  }

  std::vector<Lane> Lanes;
  std::unique_ptr<ChunkWorkers> Workers; // one a lane
};
}
}
