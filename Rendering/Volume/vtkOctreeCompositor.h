/**
 * @class   vtkOctreeCompositor
 * @brief   the OpenGL half of vtkOctreeVolumeMapper: the depth of what VTK
 *          drew, and the traced picture drawn over it with depth
 *
 * A private helper of vtkOctreeVolumeMapper (not wrapped, not installed).
 * ReadDepth() reads the window depth of the viewport (resolving a
 * multisampled framebuffer first), so that rays stop at opaque geometry;
 * ReadDepthToDevice() gives the CUDA engine the same depth without leaving
 * the GPU.
 * The picture reaches two textures (premultiplied RGBA32F, R32F window
 * depth) either from the host (SetPictureFromHost, a texture upload) or
 * straight from CUDA device memory (SetPictureFromDevice,
 * vtkOctreeCudaInterop). Draw() draws them as a full-viewport quad that
 * blends the colour over the framebuffer and writes gl_FragDepth, so the
 * octree hides and is hidden by other actors. Every OpenGL state it
 * changes is restored on return.
 */
#ifndef vtkOctreeCompositor_h
#define vtkOctreeCompositor_h

#include "vtkSmartPointer.h" // for the textures

#include <memory> // for std::unique_ptr
#include <string> // for std::string
#include <vector> // for std::vector

class vtkOctreeCudaInterop;
class vtkOpenGLQuadHelper;
class vtkOpenGLRenderWindow;
class vtkOpenGLState;
class vtkTextureObject;
class vtkWindow;

namespace octoray
{
struct DeviceImage;
struct Image;
}

class vtkOctreeCompositor
{
public:
  vtkOctreeCompositor();
  ~vtkOctreeCompositor();
  vtkOctreeCompositor(const vtkOctreeCompositor&) = delete;
  vtkOctreeCompositor& operator=(const vtkOctreeCompositor&) = delete;

  /**
   * The window depth of the viewport's pixels, rows from the bottom. False
   * (depth all 1: nothing in front) when OpenGL could not read it.
   */
  bool ReadDepth(vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height, std::vector<float>& depth);

  /**
   * The same depth left on the GPU for the CUDA engine on `device`, in its
   * device memory (through CUDA-OpenGL interop), so it never crosses to the
   * host. Null, with `error`, where interop cannot serve this window. Valid
   * until the next call.
   */
  const float* ReadDepthToDevice(
    vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height, int device, std::string& error);

  /**
   * The picture, uploaded from host memory.
   */
  void SetPictureFromHost(vtkOpenGLRenderWindow* window, const octoray::Image& image);

  /**
   * The picture, copied from CUDA device memory into the textures. False,
   * with `error`, when CUDA-OpenGL interop cannot serve this window (the
   * caller then takes the host path).
   */
  bool SetPictureFromDevice(vtkOpenGLRenderWindow* window, const octoray::DeviceImage& image, std::string& error);

  /**
   * Whether the textures hold a picture (set by the two calls above;
   * cleared when resources are released or the window changes).
   */
  bool HasPicture() const { return this->PictureReady; }

  /**
   * Draws the picture over the current viewport. False when the shader did
   * not compile.
   */
  bool Draw(vtkOpenGLRenderWindow* window);

  void ReleaseGraphicsResources(vtkWindow* window);

private:
  void UseWindow(vtkOpenGLRenderWindow* window);
  void AllocateTextures(int width, int height);
  unsigned int CopyDepth(
    vtkOpenGLRenderWindow* window, unsigned int drawFramebuffer, int x0, int y0, int width, int height);

  vtkOpenGLRenderWindow* Window = nullptr;
  vtkSmartPointer<vtkTextureObject> ColorTexture;
  vtkSmartPointer<vtkTextureObject> DepthTexture;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  std::unique_ptr<vtkOctreeCudaInterop> Interop;
  bool PictureReady = false;
  // A depth texture of a window's depth format in a framebuffer of its own.
  struct DepthTarget
  {
    unsigned int Framebuffer = 0;
    unsigned int Texture = 0;
    int Size[2] = { 0, 0 };
    unsigned int Format = 0;
    void Fit(vtkOpenGLState* state, int width, int height, unsigned int format);
    void Release(bool withContext);
  };
  // A single-sampled copy of the viewport's depth at the origin: for
  // reading a multisampled window, and as the source of the float copy for
  // CUDA.
  DepthTarget Copy;
  // The window depth as a single-channel float texture, drawn from the copy,
  // which CUDA-OpenGL interop can read; WindowDepth wraps the copy's texture
  // for sampling.
  vtkSmartPointer<vtkTextureObject> FloatDepth;
  vtkSmartPointer<vtkTextureObject> WindowDepth;
  unsigned int FloatDepthFramebuffer = 0;
  std::unique_ptr<vtkOpenGLQuadHelper> DepthQuad;
};

#endif
// VTK-HeaderTest-Exclude: vtkOctreeCompositor.h
