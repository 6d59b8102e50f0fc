/**
 * @class   vtkCudaOctreeVolumeMapper
 * @brief   vtkOctreeVolumeMapper with RequestedBackend preset to CUDA
 *
 * Builds, updates and traces the octree on the GPU, and copies the picture
 * into the compositing textures on the GPU (UseCudaGLInterop). When no
 * device is usable, or the device fails at run time (e.g. out of memory), it
 * warns and carries on with the CPU backend: GetLastUsedBackend() says which
 * one made the picture. The same as a vtkOctreeVolumeMapper with
 * SetRequestedBackendToCuda(); kept for its name.
 *
 * @sa vtkOctreeVolumeMapper vtkCPUOctreeVolumeMapper
 */
#ifndef vtkCudaOctreeVolumeMapper_h
#define vtkCudaOctreeVolumeMapper_h

#include "octorayRenderingVolumeModule.h" // for export macro
#include "vtkOctreeVolumeMapper.h"

class OCTORAYRENDERINGVOLUME_EXPORT vtkCudaOctreeVolumeMapper : public vtkOctreeVolumeMapper
{
public:
  static vtkCudaOctreeVolumeMapper* New();
  vtkTypeMacro(vtkCudaOctreeVolumeMapper, vtkOctreeVolumeMapper);

protected:
  vtkCudaOctreeVolumeMapper();
  ~vtkCudaOctreeVolumeMapper() override = default;

private:
  vtkCudaOctreeVolumeMapper(const vtkCudaOctreeVolumeMapper&) = delete;
  void operator=(const vtkCudaOctreeVolumeMapper&) = delete;
};

#endif
