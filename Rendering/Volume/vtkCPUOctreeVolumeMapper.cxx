#include "vtkCPUOctreeVolumeMapper.h"

#include "vtkObjectFactory.h"

vtkStandardNewMacro(vtkCPUOctreeVolumeMapper);

vtkCPUOctreeVolumeMapper::vtkCPUOctreeVolumeMapper()
{
  this->RequestedBackend = BACKEND_CPU;
}
