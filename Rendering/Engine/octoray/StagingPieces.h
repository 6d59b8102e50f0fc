// How the CUDA backend's staged copy (CudaUpload.h) cuts a caller's arrays:
// laid end to end in one run, cut into pieces in order, which the staging
// threads take in turn as each becomes free, each piece passing through the
// taking thread's two page-locked buffers in turn. Plain C++, so that the
// CPU's tests check the cuts and octoray_bench_cuda's host-side peer makes
// the same ones.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <utility>
#include <vector>

namespace octoray
{
namespace cuda
{
// Pieces start at multiples of this (3 x 256 bytes) into their arrays: on
// 256-byte boundaries and whole points of three floats or doubles, and a
// piece of codes (half as long) on whole values.
constexpr std::size_t kPieceAlignment = 768;
// Each pinned buffer (about 4 MB, a multiple of kPieceAlignment): large
// enough that what a piece costs beyond its bytes (about 4.5 us, PieceBytes)
// is small beside its transfer (about 75 us); 1, 2 and 8 MB were slower.
constexpr std::size_t kStagingPiece = (std::size_t(4) << 20) / kPieceAlignment * kPieceAlignment;
// The smallest pieces, at the run's start (about 512 kB): see PieceBytes.
constexpr std::size_t kEdgePiece = (std::size_t(512) << 10) / kPieceAlignment * kPieceAlignment;
// One host thread copies from pageable memory at a fraction of the bus's
// speed, and several share the host's memory bandwidth: on the 16-core
// host of an H100 the host's half of the staging took 3.0-3.1 ms for
// 190 MB on 16 threads against 3.9-6.1 on 8, in one run (octoray_bench_cuda,
// Benchmarks/gpu/variants-staging.txt, call 3). Each thread keeps 2 x 4 MB of
// page-locked memory: 128 MB at most.
constexpr int kMaxStagingThreads = 16;

// The bytes of the piece at `offset` of a run that `threads` threads copy, a
// multiple of kPieceAlignment, before CutPieces cuts it at its array's end.
// The threads start together: while they fill their first buffers the copy
// engine has nothing to do, so the first pieces are small, and grow with the
// bytes behind them. They do not shrink toward the run's end: each piece
// costs the copy time beyond its bytes, and the threads mostly wait for the
// copy engine, not it for them, so it still has pieces queued when they take
// their last ones. On an H200's host, with 1 MB buffers (1848 pieces at
// 100 M points where 4 MB cut 554) the staged copy took 42.4-43.2 ms against
// 36.7-37.0, about 4.5 us a piece, of which the copy engine takes 2.2-3.6 us
// from page-locked memory alone (Benchmarks/gpu/pinned-pieces.txt); 8 MB
// buffers were slower too. Without the shrinking (81 pieces at 10 M points
// where it cut 147) the whole call at 10 M points took 1.56-1.68 times the
// pinned copy against 1.63-1.80, each round beside the engine before
// (Benchmarks/gpu/variants-staging-pieces.txt).
inline std::size_t PieceBytes(std::size_t offset, int threads)
{
  const std::size_t grown = std::max(offset / threads, kEdgePiece);
  return std::min(kStagingPiece, grown) / kPieceAlignment * kPieceAlignment;
}

// `bytes` rounded up to whole multiples of kPieceAlignment.
inline std::size_t AlignedBytes(std::size_t bytes)
{
  return (bytes + kPieceAlignment - 1) / kPieceAlignment * kPieceAlignment;
}

// The arrays of one staged copy laid end to end in a run, each from a
// multiple of kPieceAlignment (so that the pieces of every array start on
// whole points), which the threads copy in one pass: each pass pays the
// ramps at its ends once, whatever the number of arrays
// (Benchmarks/gpu/variants-one-pass.txt).
//
// An array the threads make from twice as many bytes of the caller's (the
// codes of unit values: CudaUpload.h's CopyPart) is cut into pieces half as
// long, so that a thread's piece reads no more of the caller's memory than
// any other, and the run's last pieces, which hold up its end, take no
// longer. (Its effect was not told apart from that of the coding in AVX2,
// which came with it: Benchmarks/gpu/variants-unit-codes.txt, call 5.)
struct StagingRun
{
  std::vector<std::size_t> start; // each array's first byte in the run
  std::vector<std::size_t> bytes; // each array's length
  std::vector<bool> halfPieces;   // each array's pieces half as long

  explicit StagingRun(std::vector<std::size_t> arrayBytes, std::vector<bool> halved = {})
    : bytes(std::move(arrayBytes))
    , halfPieces(std::move(halved))
  {
    halfPieces.resize(bytes.size(), false);
    std::size_t at = 0;
    for (std::size_t b : bytes)
    {
      start.push_back(at);
      at += AlignedBytes(b);
    }
  }
  std::size_t Length() const { return bytes.empty() ? 0 : start.back() + bytes.back(); }
  std::size_t End(std::size_t array) const { return start[array] + bytes[array]; }
};

// Bytes [offset, offset + bytes) of array `array` of a run.
struct Piece
{
  std::size_t array;
  std::size_t offset;
  std::size_t bytes;
};

// The run cut into pieces for `threads` threads, in order (PieceBytes). A
// piece ends where its array does; the gaps between arrays are nobody's.
inline std::vector<Piece> CutPieces(const StagingRun& run, int threads)
{
  std::vector<Piece> pieces;
  std::size_t array = 0;
  for (std::size_t offset = 0; offset < run.Length();)
  {
    while (offset >= run.End(array)) // stops at the last array at the latest: it ends the run
    {
      ++array;
    }
    if (offset < run.start[array])
    {
      offset = run.start[array]; // past a gap
      continue;
    }
    const std::size_t most = PieceBytes(offset, threads) / (run.halfPieces[array] ? 2 : 1);
    const std::size_t n = std::min(most / kPieceAlignment * kPieceAlignment, run.End(array) - offset);
    pieces.push_back(Piece{ array, offset - run.start[array], n });
    offset += n;
  }
  return pieces;
}

// Deals a run's pieces to the threads that copy them: each takes the next
// piece as it becomes free, so a thread that runs slower, sharing its core
// with another, takes fewer. With one stripe of the run a thread, the
// threads' copies ended up to 3 ms apart in a 4.9-6.5 ms copy of 190 MB,
// some of them copying at half the others' speed
// (Benchmarks/gpu/variants-staging-timeline.txt). Dealt, the host's half
// of a 1.9 GB copy took 22-25 ms against 33-34; the whole copy, which waits
// for the copy engine, took as long as before
// (Benchmarks/gpu/variants-staging-dealt.txt).
class PieceDealer
{
public:
  explicit PieceDealer(std::vector<Piece> pieces)
    : Pieces(std::move(pieces))
  {
  }

  // fn(piece, buffer) for each piece this thread takes, in the order it
  // takes them; `buffer` (0 or 1) is the thread's page-locked buffer it
  // passes through, in turn.
  template <typename Fn>
  void Take(Fn&& fn)
  {
    int buffer = 0;
    for (std::size_t i = Next++; i < Pieces.size(); i = Next++, buffer ^= 1)
    {
      fn(Pieces[i], buffer);
    }
  }

private:
  std::vector<Piece> Pieces;
  std::atomic<std::size_t> Next{ 0 };
};
}
}
