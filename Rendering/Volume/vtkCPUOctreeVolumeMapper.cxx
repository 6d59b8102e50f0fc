#include "vtkCPUOctreeVolumeMapper.h"

#include "vtkObjectFactory.h"

vtkStandardNewMacro(vtkCPUOctreeVolumeMapper);

vtkCPUOctreeVolumeMapper::vtkCPUOctreeVolumeMapper()
{
  this->RequestedBackend = BACKEND_CPU;
}

void vtkCPUOctreeVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
