// The CPU backend's loop launcher: splits [0, n) into one contiguous chunk
// per thread. Chunks are contiguous so that per-thread partial results (radix
// histograms, run counts) combine in order and results are deterministic.
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
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

// Calls fn(begin, end, c) for chunk c of `chunks` contiguous pieces of
// [0, n), keeping what it throws in errors[c].
template <typename Fn>
void RunChunk(std::size_t n, int chunks, int c, Fn& fn, std::vector<std::exception_ptr>& errors)
{
  try
  {
    fn(n * c / chunks, n * (c + 1) / chunks, c);
  }
  catch (...)
  {
    errors[c] = std::current_exception();
  }
}

// Rethrows the first chunk's exception of those the chunks threw.
inline void RethrowFirst(const std::vector<std::exception_ptr>& errors)
{
  for (const auto& e : errors)
  {
    if (e)
    {
      std::rethrow_exception(e);
    }
  }
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
  for (int c = 1; c < chunks; ++c)
  {
    workers.emplace_back([&, c] { RunChunk(n, chunks, c, fn, errors); });
  }
  RunChunk(n, chunks, 0, fn, errors);
  for (auto& w : workers)
  {
    w.join();
  }
  RethrowFirst(errors);
}

// ParallelChunks with a fixed number of chunks on threads started once and
// kept, for a caller that splits many short passes: starting the threads
// each time costs tens of microseconds a thread (the CUDA backend's staged
// copies, several in each build, would pay it each copy). Every chunk is
// called, an empty one too. One pass at a time: Run is not reentrant.
class ChunkWorkers
{
public:
  explicit ChunkWorkers(int chunks)
    : ChunkCount(std::max(1, chunks))
  {
    for (int c = 1; c < ChunkCount; ++c)
    {
      Threads.emplace_back([this, c] { Serve(c); });
    }
  }
  ChunkWorkers(const ChunkWorkers&) = delete;
  ChunkWorkers& operator=(const ChunkWorkers&) = delete;
  ~ChunkWorkers()
  {
    {
      std::lock_guard<std::mutex> lock(Mutex);
      Stopping = true;
    }
    Wake.notify_all();
    for (auto& t : Threads)
    {
      t.join();
    }
  }

  int Chunks() const { return ChunkCount; }

  // ParallelChunks(n, Chunks(), fn) on the kept threads.
  template <typename Fn>
  void Run(std::size_t n, Fn&& fn)
  {
    std::vector<std::exception_ptr> errors(ChunkCount);
    std::function<void(int)> job = [&](int c) { RunChunk(n, ChunkCount, c, fn, errors); };
    {
      std::lock_guard<std::mutex> lock(Mutex);
      Job = &job;
      Pending = ChunkCount - 1;
      ++Pass;
    }
    Wake.notify_all();
    job(0);
    std::unique_lock<std::mutex> lock(Mutex);
    Done.wait(lock, [this] { return Pending == 0; });
    Job = nullptr;
    lock.unlock();
    RethrowFirst(errors);
  }

private:
  void Serve(int c)
  {
    std::uint64_t served = 0;
    std::unique_lock<std::mutex> lock(Mutex);
    for (;;)
    {
      Wake.wait(lock, [&] { return Stopping || Pass != served; });
      if (Stopping)
      {
        return;
      }
      served = Pass;
      const std::function<void(int)>* job = Job;
      lock.unlock();
      (*job)(c);
      lock.lock();
      if (--Pending == 0)
      {
        Done.notify_one();
      }
    }
  }

  const int ChunkCount;
  std::mutex Mutex;
  std::condition_variable Wake; // a pass to run, or stop
  std::condition_variable Done; // the pass's other chunks have run
  const std::function<void(int)>* Job = nullptr;
  std::uint64_t Pass = 0;
  int Pending = 0;
  bool Stopping = false;
  std::vector<std::thread> Threads;
};

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
