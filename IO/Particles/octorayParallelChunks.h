// Work split into chunks and run on worker threads while the calling thread
// reports progress, for the module's readers. VTK-free. Private to the
// module; not wrapped.
//
// Why not vtkSMPTools::For: VTK's progress events (and the abort flag that a
// progress observer sets) belong to the thread that called Update(), so that
// thread must stay free to report while the workers parse; vtkSMPTools::For
// returns only when all the work is done, and may do it on the calling
// thread. The chunks are handed out in order, one at a time, so that a
// chunk that fails can stop the chunks after it (the particle reader's
// strict mode reports the lowest bad line).
//
// vtkParticleTextReader uses it for both passes over a file. vtkPCDReader
// does not: LZF inflates serially, its ascii lines are parsed in one pass
// into a buffer, and the conversion of the values is a copy bound by memory.
// The engine's ParallelChunks (Rendering/Engine/octoray/Parallel.h) splits
// a range over threads without progress; a later step may merge the two.
#ifndef octorayParallelChunks_h
#define octorayParallelChunks_h

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace octoray
{
// Runs work(i) for i in [0, n) on `threads` threads; the calling thread waits
// and calls progress(chunks done) as chunks finish, at least every 50 ms.
// With one thread (or one chunk) the calling thread works itself, reporting
// after each chunk.
template <typename Work, typename Progress>
void ParallelChunks(int n, int threads, Work&& work, Progress&& progress)
{
  std::atomic<int> next{ 0 };
  std::atomic<int> done{ 0 };
  std::mutex m;
  std::condition_variable cv;
  auto worker = [&]() {
    for (int i = next++; i < n; i = next++)
    {
      work(i);
      {
        std::lock_guard<std::mutex> lock(m);
        ++done;
      }
      cv.notify_one();
    }
  };
  // The calling thread only waits and reports, so `threads` workers parse;
  // with one thread (or one chunk) it parses itself.
  std::vector<std::thread> pool;
  const int workers = std::min(threads, n);
  for (int t = 0; workers > 1 && t < workers; ++t)
  {
    pool.emplace_back(worker);
  }
  if (pool.empty())
  {
    for (int i = next++; i < n; i = next++)
    {
      work(i);
      ++done;
      progress(done.load());
    }
  }
  else
  {
    std::unique_lock<std::mutex> lock(m);
    while (done.load() < n)
    {
      cv.wait_for(lock, std::chrono::milliseconds(50));
      lock.unlock();
      progress(done.load());
      lock.lock();
    }
  }
  for (auto& t : pool)
  {
    t.join();
  }
}
} // namespace octoray

#endif
