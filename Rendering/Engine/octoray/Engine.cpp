#include "Engine.h"

#include "CpuEngine.h"

namespace octoray
{
const char* ToString(Backend backend)
{
  return backend == Backend::CUDA ? "CUDA" : "CPU";
}

#if OCTORAY_HAVE_CUDA
std::unique_ptr<Engine> CreateCudaEngine(); // CudaEngine.cu
bool CudaDeviceUsable(std::string* why);
#endif

bool CudaAvailable(std::string* why)
{
#if OCTORAY_HAVE_CUDA
  return CudaDeviceUsable(why);
#else
  if (why)
  {
    *why = "octoray was built without CUDA";
  }
  return false;
#endif
}

std::unique_ptr<Engine> CreateEngine(Backend backend)
{
  if (backend == Backend::CPU)
  {
    return std::make_unique<CpuEngine>();
  }
  std::string why;
  if (!CudaAvailable(&why))
  {
    throw Error("octoray: the CUDA backend is not available: " + why);
  }
#if OCTORAY_HAVE_CUDA
  return CreateCudaEngine();
#else
  return nullptr;
#endif
}
}
