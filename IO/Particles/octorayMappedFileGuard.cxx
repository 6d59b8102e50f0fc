#include "octorayMappedFileGuard.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <mutex>

#include <sys/mman.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace
{
// The registry the handler reads: plain lock-free atomics, so a signal
// handler may read them on any thread at any time.
struct Mapping
{
  std::atomic<uintptr_t> Begin{ 0 };
  std::atomic<uintptr_t> End{ 0 };
  std::atomic<bool> Lost{ false }; // a page vanished
  std::atomic<bool> Taken{ false };
};
Mapping Mappings[octoray::MappedFileGuard::MaximumMappings];
uintptr_t PageSize = 4096;
struct sigaction Previous;
std::mutex InstallMutex;

void OnSigbus(int sig, siginfo_t* info, void* context)
{
  const int savedErrno = errno;
  const uintptr_t address = reinterpret_cast<uintptr_t>(info->si_addr);
  for (Mapping& m : Mappings)
  {
    const uintptr_t begin = m.Begin.load(std::memory_order_acquire);
    const uintptr_t end = m.End.load(std::memory_order_acquire);
    if (begin == 0 || address < begin || address >= end)
    {
      continue;
    }
    // Every page from the faulting one to the end of the mapping becomes
    // zeros: a truncated file is gone from some byte on, so one call covers
    // what the other threads will touch next. The raw system call, not
    // libc's (or a sanitizer's) mmap wrapper: nothing but the kernel runs
    // inside the handler.
    const uintptr_t page = address & ~(PageSize - 1);
    const uintptr_t stop = (end + PageSize - 1) & ~(PageSize - 1);
    const long r = ::syscall(SYS_mmap, page, stop - page, PROT_READ,
      MAP_PRIVATE | MAP_FIXED | MAP_ANONYMOUS, -1, 0);
    if (r != -1)
    {
      m.Lost.store(true);
      errno = savedErrno;
      return; // the load runs again and reads zeros
    }
    break;
  }
  errno = savedErrno;
  // Not a guarded mapping: what would have happened without this handler.
  if (Previous.sa_flags & SA_SIGINFO)
  {
    Previous.sa_sigaction(sig, info, context);
    return;
  }
  if (Previous.sa_handler != SIG_DFL && Previous.sa_handler != SIG_IGN)
  {
    Previous.sa_handler(sig);
    return;
  }
  // The default action: a fault re-raises when the instruction runs again;
  // a SIGBUS sent by a process is raised again here.
  struct sigaction dfl = {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  ::sigaction(SIGBUS, &dfl, nullptr);
  if (info->si_code <= 0)
  {
    ::raise(SIGBUS);
  }
}

// Installs the handler, again if someone replaced it since (chaining to
// the replacement).
void Install()
{
  std::lock_guard<std::mutex> lock(InstallMutex);
  struct sigaction current;
  if (::sigaction(SIGBUS, nullptr, &current) != 0)
  {
    return;
  }
  if ((current.sa_flags & SA_SIGINFO) && current.sa_sigaction == OnSigbus)
  {
    return;
  }
  PageSize = static_cast<uintptr_t>(::sysconf(_SC_PAGESIZE));
  struct sigaction ours = {};
  ours.sa_sigaction = OnSigbus;
  ours.sa_flags = SA_SIGINFO | SA_ONSTACK | SA_RESTART;
  sigemptyset(&ours.sa_mask);
  // Previous is read by the handler: written before the handler can run.
  Previous = current;
  ::sigaction(SIGBUS, &ours, nullptr);
}
} // namespace

namespace octoray
{
bool MappedFileGuard::Watch(const void* begin, size_t size)
{
  this->Release();
  if (!begin || size == 0)
  {
    return false;
  }
  Install();
  for (int i = 0; i < MaximumMappings; ++i)
  {
    bool expected = false;
    if (Mappings[i].Taken.compare_exchange_strong(expected, true))
    {
      Mapping& m = Mappings[i];
      m.Lost.store(false);
      m.End.store(reinterpret_cast<uintptr_t>(begin) + size, std::memory_order_release);
      m.Begin.store(reinterpret_cast<uintptr_t>(begin), std::memory_order_release);
      this->Slot = i;
      return true;
    }
  }
  return false;
}

void MappedFileGuard::Release()
{
  if (this->Slot < 0)
  {
    return;
  }
  Mapping& m = Mappings[this->Slot];
  m.Begin.store(0, std::memory_order_release);
  m.End.store(0, std::memory_order_release);
  m.Taken.store(false, std::memory_order_release);
  this->Slot = -1;
}

bool MappedFileGuard::Truncated() const
{
  return this->Slot >= 0 && Mappings[this->Slot].Lost.load();
}

} // namespace octoray
