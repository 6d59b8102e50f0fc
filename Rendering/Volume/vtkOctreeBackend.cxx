#include "vtkOctreeBackend.h"

#include "vtkMultiProcessController.h"
#include "vtkOctreeVolumeMapper.h"

#include <octoray/DeviceChoice.h>
#include <octoray/Engine.h>

#include <exception>

namespace
{
// The process's rank on its host: from the MPI launcher, else the rank VTK's
// controller gives (the same thing when every rank runs on one host).
int LocalRank()
{
  const int rank = octoray::LocalRankFromEnvironment();
  if (rank >= 0)
  {
    return rank;
  }
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  return controller ? controller->GetLocalProcessId() : -1;
}
}

vtkOctreeBackend::vtkOctreeBackend() = default;
vtkOctreeBackend::~vtkOctreeBackend() = default;

//------------------------------------------------------------------------------
vtkOctreeBackend::Status vtkOctreeBackend::Acquire(int requested, int cudaDevice)
{
  this->LastMessage.clear();
  const bool cudaWanted = !this->CudaFailed &&
    (requested == vtkOctreeVolumeMapper::BACKEND_CUDA ||
      (requested == vtkOctreeVolumeMapper::BACKEND_AUTO && octoray::CudaAvailable()));
  const int wanted = cudaWanted ? vtkOctreeVolumeMapper::BACKEND_CUDA : vtkOctreeVolumeMapper::BACKEND_CPU;
  const int device = cudaWanted
    ? octoray::ChooseCudaDevice(cudaDevice, LocalRank(), octoray::CudaDeviceCount())
    : -1;
  if (this->Current && this->Backend == wanted && this->Device == device)
  {
    return Status::Ready;
  }
  std::string why;
  try
  {
    this->Make(wanted, device);
    return Status::Ready;
  }
  catch (const std::exception& e)
  {
    why = e.what();
  }
  if (wanted == vtkOctreeVolumeMapper::BACKEND_CUDA)
  {
    return this->ToCPU(why + "; using the CPU backend");
  }
  this->LastMessage = "cannot create the octree engine: " + why;
  return Status::Failed;
}

//------------------------------------------------------------------------------
vtkOctreeBackend::Status vtkOctreeBackend::Failed(const char* what, const std::string& error)
{
  if (this->Backend != vtkOctreeVolumeMapper::BACKEND_CUDA)
  {
    this->LastMessage = std::string("octree ") + what + " failed: " + error;
    return Status::Failed;
  }
  return this->ToCPU(std::string("CUDA ") + what + " failed (" + error + "); falling back to the CPU backend");
}

//------------------------------------------------------------------------------
vtkOctreeBackend::Status vtkOctreeBackend::ToCPU(const std::string& why)
{
  this->CudaFailed = true;
  this->LastMessage = why;
  if (this->Current && this->Backend == vtkOctreeVolumeMapper::BACKEND_CPU)
  {
    return Status::KeptCPU; // a CUDA request on a machine without CUDA: nothing to rebuild
  }
  try
  {
    this->Make(vtkOctreeVolumeMapper::BACKEND_CPU, -1);
  }
  catch (const std::exception& e)
  {
    this->LastMessage = why + "; cannot create the CPU engine either: " + e.what();
    return Status::Failed;
  }
  return Status::SwitchedToCPU;
}

//------------------------------------------------------------------------------
void vtkOctreeBackend::Make(int backend, int cudaDevice)
{
  // Made before the engine it replaces goes: an engine that cannot be had
  // leaves the current one, and its octree, as they were.
  const bool cuda = backend == vtkOctreeVolumeMapper::BACKEND_CUDA;
  std::unique_ptr<octoray::Engine> made =
    octoray::CreateEngine(cuda ? octoray::Backend::CUDA : octoray::Backend::CPU, cudaDevice);
  ++this->Replacements;
  this->Current = std::move(made);
  this->Backend = backend;
  this->Device = cudaDevice;
  this->EngineDescription = this->Current->Description();
}
