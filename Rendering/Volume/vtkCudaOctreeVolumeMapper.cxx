#include "vtkCudaOctreeVolumeMapper.h"

#include "vtkObjectFactory.h"

vtkStandardNewMacro(vtkCudaOctreeVolumeMapper);

vtkCudaOctreeVolumeMapper::vtkCudaOctreeVolumeMapper()
{
  this->RequestedBackend = BACKEND_CUDA;
}

void vtkCudaOctreeVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "CUDA available: " << (vtkOctreeVolumeMapper::IsCudaAvailable() ? "yes" : "no")
     << "\n";
}
