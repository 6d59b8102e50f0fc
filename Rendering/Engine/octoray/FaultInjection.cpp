#include "FaultInjection.h"

#include <atomic>
#include <mutex>

namespace octoray
{
namespace
{
std::mutex InjectionMutex;
std::string FailingKernel;
// Read without the lock by every launch: without an injection armed, a
// launch costs one relaxed load here.
std::atomic<bool> Armed{ false };
}

void InjectCudaLaunchFailure(const std::string& kernel)
{
  std::lock_guard<std::mutex> lock(InjectionMutex);
  FailingKernel = kernel;
  Armed.store(!kernel.empty());
}

bool TakeInjectedLaunchFailure(const char* kernel)
{
  if (!Armed.load(std::memory_order_relaxed))
  {
    return false;
  }
  std::lock_guard<std::mutex> lock(InjectionMutex);
  if (FailingKernel != kernel)
  {
    return false;
  }
  FailingKernel.clear();
  Armed.store(false);
  return true;
}
}
