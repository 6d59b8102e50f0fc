// The CPU backend's loop launcher: splits [0, n) into one contiguous chunk
// per thread. Chunks are contiguous so that per-thread partial results (radix
// histograms, run counts) combine in order and results are deterministic.
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace octoray
{
// A loop of fewer items runs on the calling thread: starting a thread costs
// about 20 us, more than such a loop.
constexpr std::size_t kParallelForMinItems = 4096;
// A pass that keeps a partial result per thread (a radix histogram, a count
// of selected items) splits only above this: each thread's partial result
// costs its own setup and merge.
constexpr std::size_t kParallelPassMinItems = 65536;

inline int DefaultThreadCount()
{
  const unsigned n = std::thread::hardware_concurrency();
  return n ? static_cast<int>(n) : 1;
}

// Calls fn(begin, end, chunk) for `chunks` contiguous pieces of [0, n), each
// on its own thread (the first on the calling thread). Exceptions thrown by
// fn reach the caller, the first chunk's first.
template <typename Fn>
void ParallelChunks(std::size_t n, int chunks, Fn&& fn)
{
  chunks = std::max(1, std::min<int>(chunks, static_cast<int>(std::max<std::size_t>(n, 1))));
  if (chunks == 1)
  {
    fn(std::size_t(0), n, 0);
    return;
  }
  std::vector<std::exception_ptr> errors(chunks);
  std::vector<std::thread> workers;
  workers.reserve(chunks - 1);
  auto run = [&](int c) {
    const std::size_t begin = n * c / chunks;
    const std::size_t end = n * (c + 1) / chunks;
    try
    {
      fn(begin, end, c);
    }
    catch (...)
    {
      errors[c] = std::current_exception();
    }
  };
  for (int c = 1; c < chunks; ++c)
  {
    workers.emplace_back(run, c);
  }
  run(0);
  for (auto& w : workers)
  {
    w.join();
  }
  for (auto& e : errors)
  {
    if (e)
    {
      std::rethrow_exception(e);
    }
  }
}

// Calls fn(i) for every i in [0, n) on `threads` threads.
template <typename Fn>
void ParallelFor(std::size_t n, int threads, Fn&& fn)
{
  if (n < kParallelForMinItems)
  {
    threads = 1;
  }
  ParallelChunks(n, threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i)
    {
      fn(i);
    }
  });
}
}
