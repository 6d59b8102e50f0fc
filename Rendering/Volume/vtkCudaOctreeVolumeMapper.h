/**
 * @class   vtkCudaOctreeVolumeMapper
 * @brief   vtkOctreeVolumeMapper on the engine's CUDA backend
 *
 * Builds, updates and traces the octree on the GPU. When no device is
 * usable, or the device fails at run time (e.g. out of memory), it warns and
 * carries on with the CPU backend: GetLastUsedBackend() says which one made
 * the picture.
 *
 * The picture is copied to the host and uploaded as a texture for the
 * composite draw; drawing straight from device memory through CUDA-OpenGL
 * interop is a later optimisation.
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
  void PrintSelf(ostream& os, vtkIndent indent) override;

protected:
  vtkCudaOctreeVolumeMapper();
  ~vtkCudaOctreeVolumeMapper() override = default;

private:
  vtkCudaOctreeVolumeMapper(const vtkCudaOctreeVolumeMapper&) = delete;
  void operator=(const vtkCudaOctreeVolumeMapper&) = delete;
};

#endif
