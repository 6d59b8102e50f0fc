// What a host-to-device copy from page-locked memory costs per piece: the
// same bytes copied whole and as back-to-back cudaMemcpyAsync calls of one
// piece size, on one stream and spread over 16 streams in turn, with no
// host copy beside them (the engine's staged copy, CudaUpload.h, adds the
// staging threads' copies into the pieces). The time beyond the whole copy
// divided by the pieces beyond one is what each piece costs the copy itself.
//
//   nvcc -O2 -arch=sm_90 -o /tmp/pinned-pieces scripts/gpu/pinned-pieces.cu && /tmp/pinned-pieces [MB...]
#include "probe-support.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace
{
// Median milliseconds of `rounds` copies of `bytes` in pieces of `piece`
// bytes, queued in turn on the first `streamCount` streams.
float CopyMilliseconds(char* device, const char* host, std::size_t bytes, std::size_t piece,
  const std::vector<cudaStream_t>& streams, int streamCount, int rounds)
{
  cudaEvent_t start, stop;
  Check(cudaEventCreate(&start), "cudaEventCreate");
  Check(cudaEventCreate(&stop), "cudaEventCreate");
  std::vector<float> times;
  for (int r = 0; r < rounds; ++r)
  {
    Check(cudaDeviceSynchronize(), "cudaDeviceSynchronize");
    Check(cudaEventRecord(start, streams[0]), "cudaEventRecord");
    for (int s = 1; s < streamCount; ++s)
    {
      Check(cudaStreamWaitEvent(streams[s], start, 0), "cudaStreamWaitEvent");
    }
    int s = 0;
    for (std::size_t offset = 0; offset < bytes; offset += piece, s = (s + 1) % streamCount)
    {
      const std::size_t n = std::min(piece, bytes - offset);
      Check(cudaMemcpyAsync(device + offset, host + offset, n, cudaMemcpyHostToDevice, streams[s]), "copy");
    }
    for (int t = 1; t < streamCount; ++t)
    {
      cudaEvent_t joined;
      Check(cudaEventCreateWithFlags(&joined, cudaEventDisableTiming), "cudaEventCreate");
      Check(cudaEventRecord(joined, streams[t]), "cudaEventRecord");
      Check(cudaStreamWaitEvent(streams[0], joined, 0), "cudaStreamWaitEvent");
      Check(cudaEventDestroy(joined), "cudaEventDestroy");
    }
    Check(cudaEventRecord(stop, streams[0]), "cudaEventRecord");
    Check(cudaEventSynchronize(stop), "cudaEventSynchronize");
    float ms = 0.0f;
    Check(cudaEventElapsedTime(&ms, start, stop), "cudaEventElapsedTime");
    times.push_back(ms);
  }
  Check(cudaEventDestroy(start), "cudaEventDestroy");
  Check(cudaEventDestroy(stop), "cudaEventDestroy");
  return Median(times);
}
}

int main(int argc, char** argv)
{
  std::vector<std::size_t> sizes;
  for (int a = 1; a < argc; ++a)
  {
    sizes.push_back(std::strtoull(argv[a], nullptr, 10) << 20);
  }
  if (sizes.empty())
  {
    sizes = { std::size_t(190) << 20, std::size_t(1900) << 20 }; // the benchmark's 10 M and 100 M points
  }
  const std::size_t most = *std::max_element(sizes.begin(), sizes.end());
  char* host = nullptr;
  char* device = nullptr;
  Check(cudaMallocHost(&host, most), "cudaMallocHost");
  Check(cudaMalloc(&device, most), "cudaMalloc");
  for (std::size_t i = 0; i < most; i += 4096)
  {
    host[i] = static_cast<char>(i >> 12);
  }
  std::vector<cudaStream_t> streams(16);
  for (cudaStream_t& s : streams)
  {
    Check(cudaStreamCreateWithFlags(&s, cudaStreamNonBlocking), "cudaStreamCreate");
  }
  const int rounds = 7;
  for (std::size_t bytes : sizes)
  {
    const float whole = CopyMilliseconds(device, host, bytes, bytes, streams, 1, rounds);
    std::printf("pinned copy of %zu MB: whole %.3f ms (%.1f GB/s)\n", bytes >> 20, whole, bytes / whole / 1e6);
    for (std::size_t kb : { 8192, 4096, 2048, 1024, 512, 256 })
    {
      const std::size_t piece = kb << 10;
      const std::size_t pieces = (bytes + piece - 1) / piece;
      for (int streamCount : { 1, 16 })
      {
        const float ms = CopyMilliseconds(device, host, bytes, piece, streams, streamCount, rounds);
        std::printf("  pieces of %5zu kB on %2d stream(s): %5zu pieces, %.3f ms, %.2f us a piece beyond the whole\n", kb,
          streamCount, pieces, ms, pieces > 1 ? 1e3 * (ms - whole) / (pieces - 1) : 0.0);
      }
    }
  }
  return 0;
}
