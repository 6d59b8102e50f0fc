// How the CUDA backend's staged copy (CudaUpload.h) cuts a caller's arrays:
// laid end to end in one run, into one stripe a staging thread, and each
// stripe into pieces that pass through the thread's two page-locked buffers
// in turn. Plain C++, so that the CPU's tests check the cuts and
// octoray_bench_cuda's host-side peer makes the same ones.
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace octoray
{
namespace cuda
{
// Stripes and pieces start at multiples of this (3 x 256 bytes), so that no
// piece splits a point of three floats or doubles.
constexpr std::size_t kStripeAlignment = 768;
// Each pinned buffer (about 4 MB, a multiple of kStripeAlignment): large
// enough that a DMA's setup and the calls that queue it are small beside
// its transfer.
constexpr std::size_t kStagingPiece = (std::size_t(4) << 20) / kStripeAlignment * kStripeAlignment;
// A stripe's first and last pieces (about 512 kB): see PieceBytes.
constexpr std::size_t kEdgePiece = (std::size_t(512) << 10) / kStripeAlignment * kStripeAlignment;
// How many pieces smaller than kStagingPiece PieceBytes cuts at each end of
// a stripe, at most: kEdgePiece twice, then doublings toward kStagingPiece
// at its start; halvings at its end. MaxPieces counts on it (the
// StagingPieces test checks it).
constexpr std::size_t kEdgePieces = 6;
static_assert(kStagingPiece / kEdgePiece <= 16, "kEdgePieces counts at most four doublings");
// One host thread copies from pageable memory at a fraction of the bus's
// speed, and several share the host's memory bandwidth: on the 16-core
// host of an H100 the host's half of the staging took 3.0-3.1 ms for
// 190 MB on 16 threads against 3.9-6.1 on 8, in one run (octoray_bench_cuda,
// Benchmarks/gpu/variants-staging.txt, call 3). Each thread keeps 2 x 4 MB of
// page-locked memory: 128 MB at most.
constexpr int kMaxStagingThreads = 16;


// The bytes of a stripe's piece at `offset`, of the stripe [begin, end):
// a multiple of kStripeAlignment but the stripe's last. The staging
// threads start together and end together: while they fill their first
// buffers the copy engine has nothing to do, and while it copies their last
// ones the host waits. Pieces that grow from kEdgePiece at a stripe's start
// and shrink toward its end keep both short.
inline std::size_t PieceBytes(std::size_t offset, std::size_t begin, std::size_t end)
{
  const std::size_t left = end - offset;
  const std::size_t grown = std::max(offset - begin, kEdgePiece);
  const std::size_t shrunk = std::max(left / 2, kEdgePiece);
  const std::size_t n = std::min({ kStagingPiece, grown, shrunk }) / kStripeAlignment * kStripeAlignment;
  return std::min(n, left);
}

// A copy of `bytes` in units of kStripeAlignment: the staging threads split
// these (ChunkWorkers), so that stripes start on whole points.
inline std::size_t StripeUnits(std::size_t bytes)
{
  return (bytes + kStripeAlignment - 1) / kStripeAlignment;
}

// A stripe's bytes [begin, end) of a copy.
struct Stripe
{
  std::size_t begin;
  std::size_t end;
};

// The stripe of units [first, last) of a copy of `bytes`.
inline Stripe StripeBytes(std::size_t first, std::size_t last, std::size_t bytes)
{
  return Stripe{ std::min(first * kStripeAlignment, bytes), std::min(last * kStripeAlignment, bytes) };
}

// The arrays of one staged copy laid end to end in a run, each from a
// multiple of kStripeAlignment (so that the pieces of every array start on
// whole points), which the threads cut into stripes and pieces in one pass:
// each pass pays the ramps at its stripes' ends once, whatever the number of
// arrays (Benchmarks/gpu/variants-one-pass.txt).
struct StagingRun
{
  std::vector<std::size_t> start; // each array's first byte in the run
  std::vector<std::size_t> bytes; // each array's length

  explicit StagingRun(std::vector<std::size_t> arrayBytes)
    : bytes(std::move(arrayBytes))
  {
    std::size_t at = 0;
    for (std::size_t b : bytes)
    {
      start.push_back(at);
      at += StripeUnits(b) * kStripeAlignment;
    }
  }
  std::size_t Length() const { return bytes.empty() ? 0 : start.back() + bytes.back(); }
  std::size_t End(std::size_t array) const { return start[array] + bytes[array]; }
};

// The most pieces of a run that fall in one of its arrays, of `bytes`: its
// full pieces, and in each stripe those PieceBytes cuts smaller at either
// end, the stripe's last and the one the array's end cuts.
inline std::size_t MaxPieces(std::size_t bytes)
{
  return bytes / kStagingPiece + kMaxStagingThreads * (2 * kEdgePieces + 2);
}

// fn(array, offset, bytes, buffer) for each piece of the run's stripe, in
// order: bytes [offset, offset + bytes) of that array; `buffer` (0 or 1) is
// the page-locked buffer it passes through. A piece ends where its array
// does; the gaps between arrays are nobody's.
template <typename Fn>
void ForEachPiece(const StagingRun& run, Stripe stripe, Fn&& fn)
{
  int piece = 0;
  std::size_t array = 0;
  for (std::size_t offset = stripe.begin; offset < stripe.end;)
  {
    while (array < run.bytes.size() && offset >= run.End(array))
    {
      ++array;
    }
    if (array == run.bytes.size())
    {
      return;
    }
    if (offset < run.start[array])
    {
      offset = run.start[array]; // past a gap
      continue;
    }
    const std::size_t n = std::min(PieceBytes(offset, stripe.begin, stripe.end), run.End(array) - offset);
    fn(array, offset - run.start[array], n, piece++ & 1);
    offset += n;
  }
}
}
}
