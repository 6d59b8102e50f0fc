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
    bool Mapped = false;
  };
  Registration Color, Depth, Buffer;

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
    if (r.Mapped)
    {
      cudaGraphicsUnmapResources(1, &r.Resource);
    }
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

  // Registers `texture` unless it already is, at this size on this device.
  static bool Register(Registration& r, unsigned int texture, const octoray::DeviceImage& image, std::string& error)
  {
    if (r.Resource && r.Name == texture && r.Width == image.width && r.Height == image.height &&
      r.Device == image.device)
    {
      return true;
    }
    Unregister(r);
    if (!Check(cudaGraphicsGLRegisterImage(
                 &r.Resource, texture, GL_TEXTURE_2D, cudaGraphicsRegisterFlagsWriteDiscard),
          "cudaGraphicsGLRegisterImage", error))
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
  vtkInternals::Unregister(this->Internals->Buffer);
}

const void* vtkOctreeCudaInterop::MapBuffer(unsigned int buffer, std::size_t bytes, int device, std::string& error)
{
  vtkInternals::DeviceScope scope(device, error);
  vtkInternals::Registration& r = this->Internals->Buffer;
  if (!scope.Ok)
  {
    return nullptr;
  }
  if (!(r.Resource && r.Name == buffer && r.Width == static_cast<int>(bytes) && r.Device == device))
  {
    vtkInternals::Unregister(r);
    if (!vtkInternals::Check(cudaGraphicsGLRegisterBuffer(&r.Resource, buffer, cudaGraphicsRegisterFlagsReadOnly),
          "cudaGraphicsGLRegisterBuffer", error))
    {
      r = vtkInternals::Registration{};
      return nullptr;
    }
    r.Name = buffer;
    r.Width = static_cast<int>(bytes); // a buffer's size: its bytes, one row
    r.Device = device;
  }
  void* address = nullptr;
  std::size_t size = 0;
  if (!vtkInternals::Check(cudaGraphicsMapResources(1, &r.Resource), "cudaGraphicsMapResources", error))
  {
    return nullptr;
  }
  r.Mapped = true;
  if (!vtkInternals::Check(cudaGraphicsResourceGetMappedPointer(&address, &size, r.Resource),
        "cudaGraphicsResourceGetMappedPointer", error) ||
    size < bytes)
  {
    this->UnmapBuffer();
    return nullptr;
  }
  return address;
}

void vtkOctreeCudaInterop::UnmapBuffer()
{
  vtkInternals::Registration& r = this->Internals->Buffer;
  if (r.Mapped)
  {
    int previous = 0;
    cudaGetDevice(&previous);
    cudaSetDevice(r.Device);
    cudaGraphicsUnmapResources(1, &r.Resource);
    cudaGetLastError();
    cudaSetDevice(previous);
    r.Mapped = false;
  }
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

const void* vtkOctreeCudaInterop::MapBuffer(unsigned int, std::size_t, int, std::string& error)
{
  error = "octoray was built without CUDA";
  return nullptr;
}

void vtkOctreeCudaInterop::UnmapBuffer() {}

bool vtkOctreeCudaInterop::Copy(unsigned int, unsigned int, const octoray::DeviceImage&, std::string& error)
{
  error = "octoray was built without CUDA";
  return false;
}

#endif
