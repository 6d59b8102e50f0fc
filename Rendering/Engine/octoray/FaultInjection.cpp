#include "FaultInjection.h"

#include <mutex>

namespace octoray
{
namespace
{
std::mutex InjectionMutex;
std::string FailingKernel;
}

void InjectCudaLaunchFailure(const std::string& kernel)
{
  std::lock_guard<std::mutex> lock(InjectionMutex);
  FailingKernel = kernel;
}

bool TakeInjectedLaunchFailure(const char* kernel)
{
  std::lock_guard<std::mutex> lock(InjectionMutex);
  if (FailingKernel.empty() || FailingKernel != kernel)
  {
    return false;
  }
  FailingKernel.clear();
  return true;
}
}
