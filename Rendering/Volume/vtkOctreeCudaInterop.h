/**
 * @class   vtkOctreeCudaInterop
 * @brief   copies a picture the CUDA engine left in device memory into the
 *          compositor's OpenGL textures, device to device
 *
 * A private helper of vtkOctreeVolumeMapper (not wrapped, not installed).
 * The colour (RGBA32F) and depth (R32F) textures are registered with CUDA
 * (CUDA-OpenGL interop) once per texture and size; each frame maps them,
 * copies the engine's buffers into their arrays and unmaps them, so the
 * picture never crosses to the host. Copy() fails, saying why, where that
 * cannot work: CUDA not compiled in, an OpenGL context that no CUDA device
 * drives (Mesa, or another GPU than the engine's); the caller then takes the
 * host path.
 */
#ifndef vtkOctreeCudaInterop_h
#define vtkOctreeCudaInterop_h

#include <string> // for std::string

namespace octoray
{
struct DeviceImage;
}

class vtkOctreeCudaInterop
{
public:
  vtkOctreeCudaInterop();
  ~vtkOctreeCudaInterop();
  vtkOctreeCudaInterop(const vtkOctreeCudaInterop&) = delete;
  vtkOctreeCudaInterop& operator=(const vtkOctreeCudaInterop&) = delete;

  /**
   * Copies `image` (float colour) into the textures named `colorTexture`
   * and `depthTexture` (OpenGL names, their context current, allocated at
   * the image's size). False, with `error` set, when interop cannot be used.
   */
  bool Copy(unsigned int colorTexture, unsigned int depthTexture, const octoray::DeviceImage& image,
    std::string& error);

  /**
   * Copies the single-channel float texture named `texture` (width x height,
   * its context current) into linear device memory on `device`, which this
   * object keeps: its address (valid until the next call or Release()), or
   * null with `error` set.
   */
  const float* CopyToDevice(unsigned int texture, int width, int height, int device, std::string& error);

  /**
   * Forgets the registrations and frees the device memory (before the
   * textures are resized or deleted; their context current).
   */
  void Release();

private:
  class vtkInternals;
  vtkInternals* Internals;
};

#endif
// VTK-HeaderTest-Exclude: vtkOctreeCudaInterop.h
