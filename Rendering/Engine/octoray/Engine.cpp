#include "Engine.h"

#include "CpuEngine.h"

namespace octoray
{
const char* ToString(Backend backend)
{
  return backend == Backend::CUDA ? "CUDA" : "CPU";
}

std::uint64_t Engine::DeviceDepthSignature(const float*, std::size_t)
{
  throw Error(std::string("octoray: the ") + ToString(Kind()) + " backend holds no device memory");
}

#if OCTORAY_HAVE_CUDA
std::unique_ptr<Engine> CreateCudaEngine(int device); // CudaEngine.cu
bool CudaDeviceUsable(std::string* why);
int CudaDevices();
#endif

int CudaDeviceCount()
{
#if OCTORAY_HAVE_CUDA
  return CudaDevices();
#else
  return 0;
#endif
}

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

std::unique_ptr<Engine> CreateEngine(Backend backend, int cudaDevice)
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
  if (cudaDevice >= CudaDeviceCount())
  {
    throw Error("octoray: CUDA device " + std::to_string(cudaDevice) + " does not exist (this process sees " +
      std::to_string(CudaDeviceCount()) + ")");
  }
#if OCTORAY_HAVE_CUDA
  return CreateCudaEngine(cudaDevice);
#else
  return nullptr;
#endif
}
}
