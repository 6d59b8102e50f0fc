#include "vtkOctreeCudaInterop.h"

#include <octoray/Render.h>

#if OCTORAY_HAVE_CUDA
// VTK's GLEW first: it defines the OpenGL types that cuda_gl_interop.h
// needs and keeps <GL/gl.h> from being included again.
#include "vtk_glew.h"

#include <cuda_gl_interop.h>
#include <cuda_runtime.h>

class vtkOctreeCudaInterop::vtkInternals
{
public:
  // One registered texture or buffer: which OpenGL name, at which size, on
  // which device.
  struct Registration
  {
    cudaGraphicsResource_t Resource = nullptr;
    unsigned int Name = 0; // the OpenGL texture or buffer
    int Width = 0, Height = 0, Device = -1;
  };
  Registration Color, Depth, Source;
  // The window depth in linear device memory, for the engine to read.
  void* Linear = nullptr;
  std::size_t LinearBytes = 0;
  int LinearDevice = -1;

  void FreeLinear()
  {
    if (this->Linear)
    {
      int previous = 0;
      cudaGetDevice(&previous);
      cudaSetDevice(this->LinearDevice);
      cudaFree(this->Linear);
      cudaSetDevice(previous);
    }
    this->Linear = nullptr;
    this->LinearBytes = 0;
    this->LinearDevice = -1;
  }

  static bool Check(cudaError_t status, const char* what, std::string& error)
  {
    if (status == cudaSuccess)
    {
      return true;
    }
    cudaGetLastError();
    error = std::string(what) + ": " + cudaGetErrorString(status);
    return false;
  }

  static void Unregister(Registration& r)
  {
    if (r.Resource)
    {
      cudaGraphicsUnregisterResource(r.Resource);
      cudaGetLastError();
    }
    r = Registration{};
  }

  // Makes `device` current for a scope, restoring the caller's.
  struct DeviceScope
  {
    int Previous = 0;
    bool Ok = false;
    DeviceScope(int device, std::string& error)
    {
      cudaGetDevice(&this->Previous);
      this->Ok = Check(cudaSetDevice(device), "cudaSetDevice", error);
    }
    ~DeviceScope() { cudaSetDevice(this->Previous); }
  };

  // Registers `texture` unless it already is, at this size on this device:
  // write-discard for the picture's textures, read-only for the depth.
  static bool Register(Registration& r, unsigned int texture, const octoray::DeviceImage& image, std::string& error,
    unsigned int flags = cudaGraphicsRegisterFlagsWriteDiscard)
  {
    if (r.Resource && r.Name == texture && r.Width == image.width && r.Height == image.height &&
      r.Device == image.device)
    {
      return true;
    }
    Unregister(r);
    if (!Check(cudaGraphicsGLRegisterImage(&r.Resource, texture, GL_TEXTURE_2D, flags), "cudaGraphicsGLRegisterImage",
          error))
    {
      r.Resource = nullptr;
      return false;
    }
    r.Name = texture;
    r.Width = image.width;
    r.Height = image.height;
    r.Device = image.device;
    return true;
  }
};

vtkOctreeCudaInterop::vtkOctreeCudaInterop()
  : Internals(new vtkInternals)
{
}

vtkOctreeCudaInterop::~vtkOctreeCudaInterop()
{
  this->Release();
  delete this->Internals;
}

void vtkOctreeCudaInterop::Release()
{
  vtkInternals::Unregister(this->Internals->Color);
  vtkInternals::Unregister(this->Internals->Depth);
  vtkInternals::Unregister(this->Internals->Source);
  this->Internals->FreeLinear();
}

const float* vtkOctreeCudaInterop::CopyToDevice(
  unsigned int texture, int width, int height, int device, std::string& error)
{
  vtkInternals::DeviceScope scope(device, error);
  vtkInternals& in = *this->Internals;
  octoray::DeviceImage size; // the registration's key: name, size and device
  size.width = width;
  size.height = height;
  size.device = device;
  if (!scope.Ok || !vtkInternals::Register(in.Source, texture, size, error, cudaGraphicsRegisterFlagsReadOnly))
  {
    return nullptr;
  }
  const std::size_t bytes = sizeof(float) * static_cast<std::size_t>(width) * height;
  if (in.LinearBytes != bytes || in.LinearDevice != device)
  {
    in.FreeLinear();
    if (!vtkInternals::Check(cudaMalloc(&in.Linear, bytes), "cudaMalloc (window depth)", error))
    {
      in.Linear = nullptr;
      return nullptr;
    }
    in.LinearBytes = bytes;
    in.LinearDevice = device;
  }
  cudaArray_t array = nullptr;
  const std::size_t row = sizeof(float) * width;
  bool ok = vtkInternals::Check(cudaGraphicsMapResources(1, &in.Source.Resource), "cudaGraphicsMapResources", error);
  if (ok)
  {
    ok = vtkInternals::Check(cudaGraphicsSubResourceGetMappedArray(&array, in.Source.Resource, 0, 0),
           "cudaGraphicsSubResourceGetMappedArray", error) &&
      vtkInternals::Check(cudaMemcpy2DFromArray(in.Linear, row, array, 0, 0, row, height, cudaMemcpyDeviceToDevice),
        "cudaMemcpy2DFromArray", error);
    ok = vtkInternals::Check(cudaGraphicsUnmapResources(1, &in.Source.Resource), "cudaGraphicsUnmapResources", error) && ok;
  }
  return ok ? static_cast<const float*>(in.Linear) : nullptr;
}

bool vtkOctreeCudaInterop::Copy(unsigned int colorTexture, unsigned int depthTexture,
  const octoray::DeviceImage& image, std::string& error)
{
  if (!image.rgba || !image.depth)
  {
    error = "no float picture in device memory";
    return false;
  }
  vtkInternals::DeviceScope scope(image.device, error);
  if (!scope.Ok)
  {
    return false;
  }
  vtkInternals& in = *this->Internals;
  bool ok = vtkInternals::Register(in.Color, colorTexture, image, error) &&
    vtkInternals::Register(in.Depth, depthTexture, image, error);
  cudaGraphicsResource_t resources[2] = { in.Color.Resource, in.Depth.Resource };
  if (ok && (ok = vtkInternals::Check(cudaGraphicsMapResources(2, resources), "cudaGraphicsMapResources", error)))
  {
    // Colour: 4 floats a pixel; depth: 1 float. Both rows from the bottom,
    // as OpenGL stores textures.
    const struct
    {
      cudaGraphicsResource_t Resource;
      const void* Source;
      std::size_t RowBytes;
    } planes[2] = { { resources[0], image.rgba, 4 * sizeof(float) * image.width },
      { resources[1], image.depth, sizeof(float) * image.width } };
    for (const auto& plane : planes)
    {
      cudaArray_t array = nullptr;
      ok = ok &&
        vtkInternals::Check(cudaGraphicsSubResourceGetMappedArray(&array, plane.Resource, 0, 0),
          "cudaGraphicsSubResourceGetMappedArray", error) &&
        vtkInternals::Check(cudaMemcpy2DToArray(array, 0, 0, plane.Source, plane.RowBytes, plane.RowBytes,
                              image.height, cudaMemcpyDeviceToDevice),
          "cudaMemcpy2DToArray", error);
    }
    ok = vtkInternals::Check(cudaGraphicsUnmapResources(2, resources), "cudaGraphicsUnmapResources", error) && ok;
  }
  if (!ok)
  {
    this->Release();
  }
  return ok;
}

#else // !OCTORAY_HAVE_CUDA

class vtkOctreeCudaInterop::vtkInternals
{
};

vtkOctreeCudaInterop::vtkOctreeCudaInterop()
  : Internals(new vtkInternals)
{
}

vtkOctreeCudaInterop::~vtkOctreeCudaInterop()
{
  delete this->Internals;
}

void vtkOctreeCudaInterop::Release() {}

const float* vtkOctreeCudaInterop::CopyToDevice(unsigned int, int, int, int, std::string& error)
{
  error = "octoray was built without CUDA";
  return nullptr;
}

bool vtkOctreeCudaInterop::Copy(unsigned int, unsigned int, const octoray::DeviceImage&, std::string& error)
{
  error = "octoray was built without CUDA";
  return false;
}

#endif
