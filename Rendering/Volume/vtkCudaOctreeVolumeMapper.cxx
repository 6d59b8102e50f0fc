#include "vtkCudaOctreeVolumeMapper.h"

#include "vtkObjectFactory.h"

vtkStandardNewMacro(vtkCudaOctreeVolumeMapper);

vtkCudaOctreeVolumeMapper::vtkCudaOctreeVolumeMapper()
{
  this->RequestedBackend = BACKEND_CUDA;
}
