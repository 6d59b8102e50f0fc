/**
 * @class   vtkCPUOctreeVolumeMapper
 * @brief   vtkOctreeVolumeMapper with RequestedBackend preset to the CPU
 *
 * The fallback when no CUDA device is usable, and the reference in tests:
 * the CPU backend runs the same per-pixel functions as the CUDA one on all
 * cores. The same as a vtkOctreeVolumeMapper with
 * SetRequestedBackendToCPU(); kept for its name.
 *
 * @sa vtkOctreeVolumeMapper vtkCudaOctreeVolumeMapper
 */
#ifndef vtkCPUOctreeVolumeMapper_h
#define vtkCPUOctreeVolumeMapper_h

#include "octorayRenderingVolumeModule.h" // for export macro
#include "vtkOctreeVolumeMapper.h"

class OCTORAYRENDERINGVOLUME_EXPORT vtkCPUOctreeVolumeMapper : public vtkOctreeVolumeMapper
{
public:
  static vtkCPUOctreeVolumeMapper* New();
  vtkTypeMacro(vtkCPUOctreeVolumeMapper, vtkOctreeVolumeMapper);

protected:
  vtkCPUOctreeVolumeMapper();
  ~vtkCPUOctreeVolumeMapper() override = default;

private:
  vtkCPUOctreeVolumeMapper(const vtkCPUOctreeVolumeMapper&) = delete;
  void operator=(const vtkCPUOctreeVolumeMapper&) = delete;
};

#endif
