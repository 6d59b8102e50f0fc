// What the mapper tests share: the backend a test runs on (--backend cpu or
// cuda; cuda returns VTK's skip code where no device is usable), scenes,
// windows, cameras, and pictures read back with their depth.
#ifndef octorayMapperTesting_h
#define octorayMapperTesting_h

#include "octorayTestCheck.h" // CHECK, octoray_test::Result

#include "vtkCamera.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkOctreeVolumeMapper.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkRenderWindow.h"
#include "vtkSmartPointer.h"
#include "vtkTesting.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace octoray_test
{
// ---- The backend under test.
struct Backend
{
  int Requested = vtkOctreeVolumeMapper::BACKEND_CPU;
  bool Interop = true; // CUDA: the picture to OpenGL device to device (else through the host)
  const char* Name() const { return Requested == vtkOctreeVolumeMapper::BACKEND_CUDA ? "CUDA" : "CPU"; }
  bool Cuda() const { return Requested == vtkOctreeVolumeMapper::BACKEND_CUDA; }
};

// `--backend cpu|cuda` among the arguments (default cpu), and for CUDA
// `--transfer device|host` (default device). False when CUDA is asked for
// and no device is usable: the test then skips.
inline bool ParseBackend(int argc, char* argv[], Backend& backend)
{
  for (int i = 1; i + 1 < argc; ++i)
  {
    if (std::strcmp(argv[i], "--backend") == 0 && std::strcmp(argv[i + 1], "cuda") == 0)
    {
      backend.Requested = vtkOctreeVolumeMapper::BACKEND_CUDA;
    }
    if (std::strcmp(argv[i], "--transfer") == 0 && std::strcmp(argv[i + 1], "host") == 0)
    {
      backend.Interop = false;
    }
  }
  if (backend.Cuda() && !vtkOctreeVolumeMapper::IsCudaAvailable())
  {
    std::cout << "CUDA backend not usable here: skipped" << std::endl;
    return false;
  }
  std::cout << "backend: " << backend.Name()
            << (backend.Cuda() ? (backend.Interop ? ", picture device to device" : ", picture through the host") : "")
            << std::endl;
  return true;
}
#define OCTORAY_TEST_BACKEND(backend)                                                              \
  octoray_test::Backend backend;                                                                   \
  if (!octoray_test::ParseBackend(argc, argv, backend))                                            \
  {                                                                                                \
    return VTK_SKIP_RETURN_CODE;                                                                   \
  }

// The value after `flag` among the arguments, or `otherwise`.
inline std::string Argument(int argc, char* argv[], const char* flag, const std::string& otherwise)
{
  for (int i = 1; i + 1 < argc; ++i)
  {
    if (std::strcmp(argv[i], flag) == 0)
    {
      return argv[i + 1];
    }
  }
  return otherwise;
}

inline vtkSmartPointer<vtkOctreeVolumeMapper> NewMapper(const Backend& backend)
{
  auto mapper = vtkSmartPointer<vtkOctreeVolumeMapper>::New();
  mapper->SetRequestedBackend(backend.Requested);
  mapper->SetUseCudaGLInterop(backend.Interop);
  return mapper;
}

// After a render: the backend under test drew it, and the picture took the
// way asked for (CUDA with interop: device to device; the GPU machine's EGL
// runs on the GPU that CUDA uses).
inline bool DrewWith(vtkOctreeVolumeMapper* mapper, const Backend& backend)
{
  const bool backendOk = std::string(mapper->GetLastUsedBackendName()) == backend.Name();
  const int transfer = backend.Cuda() && backend.Interop ? vtkOctreeVolumeMapper::TRANSFER_DEVICE
                                                         : vtkOctreeVolumeMapper::TRANSFER_HOST;
  const bool transferOk = mapper->GetLastPictureTransfer() == transfer;
  if (!backendOk || !transferOk)
  {
    std::cerr << "drawn by " << mapper->GetLastUsedBackendName() << " through "
              << mapper->GetLastPictureTransferName() << ", expected " << backend.Name() << std::endl;
  }
  return backendOk && transferOk;
}

// ---- Scenes.
// A cloud of `n` points in a ball of radius 1 with random 8-bit RGB colours
// (the active scalars), or with a "Density" scalar (1 at the centre, 0 at
// the rim) active and the colours as a named array.
inline vtkSmartPointer<vtkPolyData> Cloud(int n, unsigned seed, bool withScalars = false)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> c(40, 255);
  vtkNew<vtkPoints> points;
  vtkNew<vtkUnsignedCharArray> colors;
  colors->SetName("Colors");
  colors->SetNumberOfComponents(3);
  vtkNew<vtkFloatArray> scalars;
  scalars->SetName("Density");
  while (points->GetNumberOfPoints() < n)
  {
    const double p[3] = { u(rng), u(rng), u(rng) };
    const double r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    if (r2 > 1.0)
    {
      continue;
    }
    points->InsertNextPoint(p);
    const unsigned char rgb[3] = { static_cast<unsigned char>(c(rng)), static_cast<unsigned char>(c(rng)),
      static_cast<unsigned char>(c(rng)) };
    colors->InsertNextTypedTuple(rgb);
    scalars->InsertNextValue(static_cast<float>(1.0 - std::sqrt(r2)));
  }
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  cloud->SetPoints(points);
  if (withScalars)
  {
    cloud->GetPointData()->SetScalars(scalars);
    cloud->GetPointData()->AddArray(colors);
  }
  else
  {
    cloud->GetPointData()->SetScalars(colors);
  }
  return cloud;
}

// An offscreen window; no multisampling unless asked, for pixel-exact
// comparisons.
inline vtkSmartPointer<vtkRenderWindow> Window(int w, int h, int samples = 0)
{
  auto window = vtkSmartPointer<vtkRenderWindow>::New();
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(samples);
  window->SetSize(w, h);
  return window;
}

inline void SetCamera(vtkCamera* camera, bool parallel = false)
{
  camera->SetPosition(2.2, 1.6, 3.1);
  camera->SetFocalPoint(0.05, -0.05, 0.0);
  camera->SetViewUp(0, 1, 0);
  camera->SetViewAngle(35);
  camera->SetParallelProjection(parallel);
  camera->SetParallelScale(1.25);
  camera->SetClippingRange(1.5, 7.0);
}

// A volume with unshaded first hits of the RGB point colours.
inline vtkSmartPointer<vtkVolume> Volume(vtkOctreeVolumeMapper* mapper)
{
  auto volume = vtkSmartPointer<vtkVolume>::New();
  volume->SetMapper(mapper);
  vtkNew<vtkVolumeProperty> property;
  property->ShadeOff();
  property->IndependentComponentsOff(); // RGB scalars are colours
  volume->SetProperty(property);
  return volume;
}

// ---- Pictures: RGB and window depth read back after a render.
struct Picture
{
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
  std::vector<float> depth;
  const unsigned char* At(int x, int y) const { return &rgb[3 * (static_cast<size_t>(y) * w + x)]; }
  float Depth(int x, int y) const { return depth[static_cast<size_t>(y) * w + x]; }
};

inline Picture Capture(vtkRenderWindow* window)
{
  window->Render();
  Picture p;
  vtkNew<vtkWindowToImageFilter> colour;
  colour->SetInput(window);
  colour->SetInputBufferTypeToRGB();
  colour->ReadFrontBufferOff();
  colour->Update();
  int* dims = colour->GetOutput()->GetDimensions();
  p.w = dims[0];
  p.h = dims[1];
  auto* c = vtkUnsignedCharArray::SafeDownCast(colour->GetOutput()->GetPointData()->GetScalars());
  p.rgb.assign(c->GetPointer(0), c->GetPointer(0) + 3 * p.w * p.h);
  vtkNew<vtkWindowToImageFilter> z;
  z->SetInput(window);
  z->SetInputBufferTypeToZBuffer();
  z->ReadFrontBufferOff();
  z->Update();
  auto* d = vtkFloatArray::SafeDownCast(z->GetOutput()->GetPointData()->GetScalars());
  p.depth.assign(d->GetPointer(0), d->GetPointer(0) + p.w * p.h);
  return p;
}

inline bool Same(const unsigned char* a, const unsigned char* b)
{
  return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

// Pixels next to a change of colour in `ref` (voxel edges, silhouettes): the
// one-pixel band where rasterisation, multisampling and ray casting may
// round differently.
inline std::vector<char> Band(const Picture& ref)
{
  std::vector<char> band(static_cast<size_t>(ref.w) * ref.h, 0);
  for (int y = 0; y < ref.h; ++y)
  {
    for (int x = 0; x < ref.w; ++x)
    {
      for (int dy = -1; dy <= 1; ++dy)
      {
        for (int dx = -1; dx <= 1; ++dx)
        {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= ref.w || ny >= ref.h || !Same(ref.At(x, y), ref.At(nx, ny)))
          {
            band[static_cast<size_t>(y) * ref.w + x] = 1;
          }
        }
      }
    }
  }
  return band;
}

// Pixels whose colour or depth differ between two pictures of one size.
inline int Differing(const Picture& a, const Picture& b)
{
  int n = 0;
  for (int y = 0; y < a.h; ++y)
  {
    for (int x = 0; x < a.w; ++x)
    {
      n += !Same(a.At(x, y), b.At(x, y)) || a.Depth(x, y) != b.Depth(x, y);
    }
  }
  return n;
}

inline int Covered(const Picture& p)
{
  return static_cast<int>(std::count_if(p.depth.begin(), p.depth.end(), [](float z) { return z < 1.0f; }));
}
}

#endif
