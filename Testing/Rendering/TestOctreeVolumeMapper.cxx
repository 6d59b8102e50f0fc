// Tests of vtkOctreeVolumeMapper in VTK render windows (CPU backend, the
// reference). One executable, one sub-test per first argument:
//   glyphs <perspective|parallel>  the surface picture and depth against the
//                                  same leaf voxels drawn as cubes by VTK
//   mixed                          a sphere half inside the cloud: occluded
//                                  and occluding
//   modes <baseline dir> <tmp dir> a regression image per mode (vtkTesting)
//   work                           backend choice, CUDA fallback, rebuild /
//                                  update / re-trace only when needed
//   animation <frames>             moved points == built from scratch, two
//                                  renderers side by side
//   large                          a 4096x4096 offscreen window
#include "octorayTestCheck.h"

#include "vtkActor.h"
#include "vtkCPUOctreeVolumeMapper.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkCubeSource.h"
#include "vtkCudaOctreeVolumeMapper.h"
#include "vtkFloatArray.h"
#include "vtkGlyph3D.h"
#include "vtkImageData.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkOctreeVolumeMapper.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSphereSource.h"
#include "vtkTesting.h"
#include "vtkTrivialProducer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWindowToImageFilter.h"

#include <cmath>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace
{
// A cloud of `n` points in a ball of radius 1 with random 8-bit RGB colours.
vtkSmartPointer<vtkPolyData> Cloud(int n, unsigned seed, bool withScalars = false)
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
    const unsigned char rgb[3] = { static_cast<unsigned char>(c(rng)),
      static_cast<unsigned char>(c(rng)), static_cast<unsigned char>(c(rng)) };
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

vtkSmartPointer<vtkRenderWindow> Window(int w, int h)
{
  auto window = vtkSmartPointer<vtkRenderWindow>::New();
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0); // pixel-exact comparisons
  window->SetSize(w, h);
  return window;
}

void SetCamera(vtkCamera* camera, bool parallel)
{
  camera->SetPosition(2.2, 1.6, 3.1);
  camera->SetFocalPoint(0.05, -0.05, 0.0);
  camera->SetViewUp(0, 1, 0);
  camera->SetViewAngle(35);
  camera->SetParallelProjection(parallel);
  camera->SetParallelScale(1.25);
  camera->SetClippingRange(1.5, 7.0);
}

struct Picture
{
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
  std::vector<float> depth;
  const unsigned char* At(int x, int y) const { return &rgb[3 * (static_cast<size_t>(y) * w + x)]; }
  float Depth(int x, int y) const { return depth[static_cast<size_t>(y) * w + x]; }
};

Picture Capture(vtkRenderWindow* window)
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

bool Same(const unsigned char* a, const unsigned char* b)
{
  return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

// Pixels next to a change of colour in `ref` (voxel edges, silhouettes): the
// one-pixel band where rasterisation and ray casting may round differently.
std::vector<char> Band(const Picture& ref)
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

vtkSmartPointer<vtkVolume> Volume(vtkOctreeVolumeMapper* mapper)
{
  auto volume = vtkSmartPointer<vtkVolume>::New();
  volume->SetMapper(mapper);
  vtkNew<vtkVolumeProperty> property;
  property->ShadeOff();
  property->IndependentComponentsOff(); // RGB scalars are colours
  volume->SetProperty(property);
  return volume;
}

// ---- The surface picture against VTK's own cubes at the leaf centres.
int Glyphs(bool parallel)
{
  const int size = 300;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(250, 7);
  vtkNew<vtkCPUOctreeVolumeMapper> mapper;
  mapper->SetInputData(cloud);
  mapper->SetLeafDepth(4);
  vtkSmartPointer<vtkVolume> volume = Volume(mapper);
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(volume);
  SetCamera(ren->GetActiveCamera(), parallel);
  vtkSmartPointer<vtkRenderWindow> window = Window(size, size);
  window->AddRenderer(ren);
  const Picture octree = Capture(window);

  // The reference: the mapper's own leaves, drawn by VTK's OpenGL pipeline
  // as flat, unlit cubes of the leaf size.
  vtkNew<vtkPolyData> leaves;
  mapper->GetLeafVoxels(leaves);
  CHECK(leaves->GetNumberOfPoints() > 50);
  vtkNew<vtkCubeSource> cube;
  const double side = mapper->GetLeafSize();
  cube->SetXLength(side);
  cube->SetYLength(side);
  cube->SetZLength(side);
  vtkNew<vtkGlyph3D> glyphs;
  glyphs->SetInputData(leaves);
  glyphs->SetSourceConnection(cube->GetOutputPort());
  glyphs->ScalingOff();
  glyphs->OrientOff();
  glyphs->SetColorModeToColorByScalar();
  vtkNew<vtkPolyDataMapper> glyphMapper;
  glyphMapper->SetInputConnection(glyphs->GetOutputPort());
  glyphMapper->SetColorModeToDirectScalars();
  vtkNew<vtkActor> actor;
  actor->SetMapper(glyphMapper);
  actor->GetProperty()->LightingOff();
  vtkNew<vtkRenderer> refRen;
  refRen->AddActor(actor);
  SetCamera(refRen->GetActiveCamera(), parallel);
  vtkSmartPointer<vtkRenderWindow> refWindow = Window(size, size);
  refWindow->AddRenderer(refRen);
  const Picture reference = Capture(refWindow);

  const std::vector<char> band = Band(reference);
  int compared = 0, coveredCompared = 0, covered = 0, colourMismatch = 0, depthMismatch = 0;
  double worstDepth = 0.0;
  for (int y = 0; y < size; ++y)
  {
    for (int x = 0; x < size; ++x)
    {
      if (reference.Depth(x, y) < 1.0f)
      {
        ++covered;
      }
      if (band[static_cast<size_t>(y) * size + x])
      {
        continue;
      }
      ++compared;
      coveredCompared += reference.Depth(x, y) < 1.0f;
      if (!Same(octree.At(x, y), reference.At(x, y)))
      {
        if (colourMismatch++ < 5)
        {
          const unsigned char *a = octree.At(x, y), *b = reference.At(x, y);
          std::cerr << "pixel " << x << "," << y << ": octree " << int(a[0]) << " " << int(a[1]) << " "
                    << int(a[2]) << ", cubes " << int(b[0]) << " " << int(b[1]) << " " << int(b[2])
                    << "\n";
        }
      }
      const double dz = std::fabs(double(octree.Depth(x, y)) - reference.Depth(x, y));
      worstDepth = std::max(worstDepth, dz);
      if (dz > 1e-4)
      {
        ++depthMismatch;
      }
    }
  }
  std::cout << (parallel ? "parallel" : "perspective") << ": " << covered << " covered pixels, "
            << compared << " compared outside the band (" << coveredCompared << " of them covered), " << colourMismatch << " colour and "
            << depthMismatch << " depth mismatches, worst depth difference " << worstDepth << "\n";
  // Enough of the picture is compared for the test to mean something.
  CHECK(covered > size * size / 8);
  CHECK(compared > size * size / 2);
  CHECK(coveredCompared > covered / 2);
  CHECK(colourMismatch == 0);
  CHECK(depthMismatch == 0);
  return 0;
}

// ---- A sphere half inside the cloud hides it and is hidden by it.
int Mixed()
{
  const int size = 300;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(1500, 11);
  auto render = [&](bool withCloud, bool withSphere) {
    vtkNew<vtkCPUOctreeVolumeMapper> mapper;
    mapper->SetInputData(cloud);
    mapper->SetLeafDepth(5);
    vtkNew<vtkRenderer> ren;
    if (withCloud)
    {
      ren->AddVolume(Volume(mapper));
    }
    vtkNew<vtkSphereSource> sphere;
    sphere->SetCenter(0.6, 0.2, 0.3);
    sphere->SetRadius(0.6);
    sphere->SetThetaResolution(48);
    sphere->SetPhiResolution(48);
    vtkNew<vtkPolyDataMapper> sm;
    sm->SetInputConnection(sphere->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(sm);
    actor->GetProperty()->SetColor(0.2, 0.4, 1.0);
    if (withSphere)
    {
      ren->AddActor(actor);
    }
    SetCamera(ren->GetActiveCamera(), false);
    vtkSmartPointer<vtkRenderWindow> window = Window(size, size);
    window->AddRenderer(ren);
    return Capture(window);
  };
  const Picture cloudOnly = render(true, false);
  const Picture sphereOnly = render(false, true);
  const Picture both = render(true, true);
  const std::vector<char> bandC = Band(cloudOnly);
  int sphereFront = 0, cloudFront = 0, wrong = 0, depthWrong = 0;
  for (int y = 0; y < size; ++y)
  {
    for (int x = 0; x < size; ++x)
    {
      const size_t i = static_cast<size_t>(y) * size + x;
      const float zc = cloudOnly.Depth(x, y), zs = sphereOnly.Depth(x, y);
      if (bandC[i] || std::fabs(zc - zs) < 1e-3 || (zc >= 1.0f && zs >= 1.0f))
      {
        continue;
      }
      const bool sphereWins = zs < zc;
      const Picture& expected = sphereWins ? sphereOnly : cloudOnly;
      if (sphereWins && zc < 1.0f)
      {
        ++sphereFront;
      }
      if (!sphereWins && zs < 1.0f)
      {
        ++cloudFront;
      }
      if (!Same(both.At(x, y), expected.At(x, y)))
      {
        ++wrong;
      }
      if (std::fabs(both.Depth(x, y) - std::min(zc, zs)) > 1e-5)
      {
        ++depthWrong;
      }
    }
  }
  std::cout << "mixed: sphere in front of the cloud at " << sphereFront << " pixels, cloud in front of the sphere at "
            << cloudFront << ", wrong colour " << wrong << ", wrong depth " << depthWrong << "\n";
  CHECK(sphereFront > 300); // the sphere occludes part of the cloud
  CHECK(cloudFront > 300);  // and the cloud part of the sphere
  CHECK(wrong == 0);
  CHECK(depthWrong == 0);
  return 0;
}

// ---- A regression image per mode, compared by vtkTesting.
int Modes(const std::string& baselineDir, const std::string& tmpDir)
{
  const int size = 200;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(3000, 5, true);
  struct Mode
  {
    const char* name;
    int blend;
    bool shade;
    bool scalars; // transfer function on "Density" (else the RGB colours)
  };
  const Mode modes[] = {
    { "surface", vtkOctreeVolumeMapper::SURFACE_BLEND, false, false },
    { "phong", vtkOctreeVolumeMapper::SURFACE_BLEND, true, false },
    { "depthcue", vtkOctreeVolumeMapper::SURFACE_BLEND, false, false },
    { "surface_tf", vtkOctreeVolumeMapper::SURFACE_BLEND, true, true },
    { "composite", vtkVolumeMapper::COMPOSITE_BLEND, false, true },
    { "mip", vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND, false, true },
    { "minip", vtkVolumeMapper::MINIMUM_INTENSITY_BLEND, false, true },
    { "average", vtkVolumeMapper::AVERAGE_INTENSITY_BLEND, false, true },
    { "additive", vtkVolumeMapper::ADDITIVE_BLEND, false, true },
  };
  std::vector<vtkSmartPointer<vtkImageData>> pictures;
  vtkSmartPointer<vtkRenderWindow> lastWindow;
  for (const Mode& m : modes)
  {
    vtkNew<vtkCPUOctreeVolumeMapper> mapper;
    mapper->SetInputData(cloud);
    mapper->SetLeafDepth(6);
    mapper->SetBlendMode(m.blend);
    if (std::string(m.name) == "depthcue")
    {
      mapper->SetDepthCue(0.8);
    }
    if (!m.scalars)
    {
      mapper->SelectScalarArray("Colors");
      mapper->SetScalarModeToUsePointFieldData();
    }
    vtkSmartPointer<vtkVolume> volume = Volume(mapper);
    vtkVolumeProperty* property = volume->GetProperty();
    property->SetShade(m.shade);
    property->SetAmbient(0.15);
    property->SetDiffuse(0.7);
    property->SetSpecular(0.4);
    property->SetSpecularPower(20);
    vtkNew<vtkColorTransferFunction> ctf;
    ctf->AddRGBPoint(0.0, 0.1, 0.1, 0.8);
    ctf->AddRGBPoint(0.5, 0.9, 0.9, 0.2);
    ctf->AddRGBPoint(1.0, 1.0, 0.2, 0.1);
    vtkNew<vtkPiecewiseFunction> opacity;
    opacity->AddPoint(0.0, 0.05);
    opacity->AddPoint(1.0, 0.8);
    property->SetColor(ctf);
    property->SetScalarOpacity(opacity);
    property->SetScalarOpacityUnitDistance(0.1);
    vtkNew<vtkRenderer> ren;
    ren->AddVolume(volume);
    ren->SetBackground(0.1, 0.1, 0.1);
    if (m.shade)
    {
      // A coloured scene light beside the headlight.
      vtkNew<vtkLight> light;
      light->SetLightTypeToSceneLight();
      light->SetPosition(-3, 4, 2);
      light->SetFocalPoint(0, 0, 0);
      light->SetDiffuseColor(1.0, 0.8, 0.6);
      light->SetIntensity(0.7);
      ren->CreateLight();
      ren->AddLight(light);
    }
    SetCamera(ren->GetActiveCamera(), false);
    vtkSmartPointer<vtkRenderWindow> window = Window(size, size);
    window->AddRenderer(ren);
    window->Render();
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(window);
    grab->ReadFrontBufferOff();
    grab->Update();
    auto picture = vtkSmartPointer<vtkImageData>::New();
    picture->DeepCopy(grab->GetOutput());
    pictures.push_back(picture);

    const std::string baseline = baselineDir + "/TestOctreeVolumeMapper_" + m.name + ".png";
    vtkNew<vtkTesting> testing;
    testing->AddArgument("-V");
    testing->AddArgument(baseline.c_str());
    testing->AddArgument("-T");
    testing->AddArgument(tmpDir.c_str());
    testing->SetRenderWindow(window);
    lastWindow = window;
    // Threshold 0.05: vtkImageDifference's thresholded error; an image of the
    // CPU reference differs from its baseline only by driver rounding.
    const int result = testing->RegressionTest(grab, 0.05, std::cout);
    std::cout << m.name << ": " << (result == vtkTesting::PASSED ? "passed" : "FAILED") << "\n";
    CHECK(result == vtkTesting::PASSED);
  }
  // The comparison can fail: every mode differs from every other one by far
  // more than the threshold.
  {
    vtkNew<vtkTesting> testing;
    const std::string baseline = baselineDir + "/TestOctreeVolumeMapper_surface.png";
    testing->AddArgument("-V");
    testing->AddArgument(baseline.c_str());
    testing->AddArgument("-T");
    testing->AddArgument(tmpDir.c_str());
    testing->SetRenderWindow(lastWindow);
    std::ostringstream quiet;
    vtkNew<vtkImageData> composite;
    composite->DeepCopy(pictures[4]);
    vtkNew<vtkTrivialProducer> producer;
    producer->SetOutput(composite);
    CHECK(testing->RegressionTest(producer, 0.05, quiet) == vtkTesting::FAILED);
  }
  return 0;
}
// Counts warnings and errors, and keeps VTK from printing them.
struct Messages
{
  int warnings = 0, errors = 0;
  std::string last;
  vtkNew<vtkCallbackCommand> callback;
  explicit Messages(vtkObject* o)
  {
    callback->SetClientData(this);
    callback->SetCallback([](vtkObject*, unsigned long event, void* self, void* text) {
      auto* m = static_cast<Messages*>(self);
      (event == vtkCommand::WarningEvent ? m->warnings : m->errors)++;
      m->last = text ? static_cast<const char*>(text) : "";
    });
    o->AddObserver(vtkCommand::WarningEvent, callback);
    o->AddObserver(vtkCommand::ErrorEvent, callback);
  }
};

// ---- Backend choice, CUDA fallback, and work only when needed.
int Work()
{
  vtkSmartPointer<vtkPolyData> cloud = Cloud(2000, 3);
  // New() picks CUDA when a device is usable, the CPU otherwise.
  {
    vtkNew<vtkOctreeVolumeMapper> automatic;
    CHECK(vtkOctreeVolumeMapper::IsCudaAvailable() ? automatic->IsA("vtkCudaOctreeVolumeMapper")
                                                   : automatic->IsA("vtkCPUOctreeVolumeMapper"));
  }
  // The CUDA mapper without a usable device, or with a device whose memory
  // is exhausted: a warning, and the CPU draws the picture.
  {
    vtkNew<vtkCudaOctreeVolumeMapper> cuda;
    Messages messages(cuda);
    cuda->SetInputData(cloud);
    cuda->SetCudaMemoryBudget(1024); // far too little for any octree
    vtkNew<vtkRenderer> ren;
    ren->AddVolume(Volume(cuda));
    SetCamera(ren->GetActiveCamera(), false);
    vtkSmartPointer<vtkRenderWindow> window = Window(120, 120);
    window->AddRenderer(ren);
    window->Render();
    std::cout << "CUDA mapper: " << cuda->GetLastUsedBackendName() << " (" << cuda->GetBackendDescription()
              << "), warning: " << messages.last << "\n";
    CHECK(cuda->GetLastUsedBackend() == vtkOctreeVolumeMapper::BACKEND_CPU);
    CHECK(messages.warnings == 1);
    CHECK(messages.errors == 0);
    CHECK(cuda->GetNumberOfTraces() == 1);
  }

  vtkNew<vtkCPUOctreeVolumeMapper> mapper;
  mapper->SetInputData(cloud);
  vtkNew<vtkRenderer> ren;
  vtkSmartPointer<vtkVolume> volume = Volume(mapper);
  ren->AddVolume(volume);
  SetCamera(ren->GetActiveCamera(), false);
  vtkSmartPointer<vtkRenderWindow> window = Window(160, 120);
  window->AddRenderer(ren);
  window->Render();
  CHECK(mapper->GetNumberOfBuilds() == 1 && mapper->GetNumberOfTraces() == 1);
  CHECK(std::string(mapper->GetLastUsedBackendName()) == "CPU");
  CHECK(mapper->GetNumberOfOctreePoints() == 2000);
  // Nothing changed: no build, no trace.
  window->Render();
  CHECK(mapper->GetNumberOfBuilds() == 1 && mapper->GetNumberOfTraces() == 1);
  // The camera moved: trace, no build.
  ren->GetActiveCamera()->Azimuth(10);
  window->Render();
  CHECK(mapper->GetNumberOfBuilds() == 1 && mapper->GetNumberOfTraces() == 2);
  // A light changed: trace.
  ren->GetLights()->GetItemAsObject(0);
  vtkNew<vtkLight> light;
  light->SetPosition(1, 2, 3);
  ren->AddLight(light);
  window->Render();
  CHECK(mapper->GetNumberOfBuilds() == 1 && mapper->GetNumberOfTraces() == 3);
  light->SetIntensity(0.5);
  window->Render();
  CHECK(mapper->GetNumberOfTraces() == 4);
  // The property changed: trace.
  volume->GetProperty()->SetAmbient(0.3);
  window->Render();
  CHECK(mapper->GetNumberOfBuilds() == 1 && mapper->GetNumberOfTraces() == 5);
  // Only the positions changed (same array, modified in place): update.
  double p[3];
  cloud->GetPoints()->GetPoint(0, p);
  p[0] += 0.01;
  cloud->GetPoints()->SetPoint(0, p);
  cloud->GetPoints()->Modified();
  window->Render();
  CHECK(mapper->GetNumberOfBuilds() == 1 && mapper->GetNumberOfUpdates() == 1);
  CHECK(mapper->GetNumberOfTraces() == 6);
  // The colours changed: rebuild.
  cloud->GetPointData()->GetScalars()->Modified();
  window->Render();
  CHECK(mapper->GetNumberOfBuilds() == 2 && mapper->GetNumberOfUpdates() == 1);
  // A mapper setting that shapes the octree: rebuild.
  mapper->SetLeafDepth(3);
  window->Render();
  CHECK(mapper->GetNumberOfBuilds() == 3);
  // Depth 3: a leaf is an eighth of the root cube, which is about 2 wide.
  CHECK(mapper->GetLeafSize() * 8 > 1.8 && mapper->GetLeafSize() * 8 < 2.01);
  // A setting of the picture only: trace, no build.
  mapper->SetBlendModeToMaximumIntensity();
  window->Render();
  CHECK(mapper->GetNumberOfBuilds() == 3 && mapper->GetNumberOfTraces() == 9);

  // vtkImageData: voxels above the background become points.
  {
    vtkNew<vtkImageData> image;
    image->SetDimensions(10, 10, 10);
    image->AllocateScalars(VTK_FLOAT, 1);
    auto* v = vtkFloatArray::SafeDownCast(image->GetPointData()->GetScalars());
    for (vtkIdType i = 0; i < 1000; ++i)
    {
      v->SetValue(i, i % 4 == 0 ? 5.0f : 0.0f);
    }
    vtkNew<vtkCPUOctreeVolumeMapper> imageMapper;
    imageMapper->SetInputData(image);
    imageMapper->SetImageBackground(1.0);
    vtkNew<vtkRenderer> r2;
    r2->AddVolume(Volume(imageMapper));
    r2->ResetCamera();
    vtkSmartPointer<vtkRenderWindow> w2 = Window(100, 100);
    w2->AddRenderer(r2);
    w2->Render();
    CHECK(imageMapper->GetNumberOfOctreePoints() == 250);
  }
  return 0;
}

// ---- Moving points for `frames` frames gives the pictures of building
// from scratch at each frame. Left renderer: one mapper, updated in place;
// right renderer: a new mapper per frame. Eight fixed corner points keep
// the bounds, and so the root cube, the same for both.
int Animation(int frames)
{
  const int w = 160, h = 160;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(600, 21);
  vtkPoints* points = cloud->GetPoints();
  vtkUnsignedCharArray* colors = vtkUnsignedCharArray::SafeDownCast(cloud->GetPointData()->GetScalars());
  const unsigned char white[3] = { 255, 255, 255 };
  for (int corner = 0; corner < 8; ++corner)
  {
    points->InsertNextPoint(corner & 1 ? 1.2 : -1.2, corner & 2 ? 1.2 : -1.2, corner & 4 ? 1.2 : -1.2);
    colors->InsertNextTypedTuple(white);
  }
  std::vector<double> base(3 * 600);
  for (vtkIdType i = 0; i < 600; ++i)
  {
    points->GetPoint(i, &base[3 * i]);
  }
  vtkNew<vtkCPUOctreeVolumeMapper> animated;
  animated->SetInputData(cloud);
  animated->SetLeafDepth(5);
  vtkNew<vtkRenderer> left;
  left->SetViewport(0, 0, 0.5, 1);
  left->AddVolume(Volume(animated));
  SetCamera(left->GetActiveCamera(), false);
  vtkNew<vtkRenderer> right;
  right->SetViewport(0.5, 0, 1, 1);
  SetCamera(right->GetActiveCamera(), false);
  vtkSmartPointer<vtkRenderWindow> window = Window(2 * w, h);
  window->AddRenderer(left);
  window->AddRenderer(right);
  int differing = 0, emptyFrames = 0;
  for (int frame = 0; frame < frames; ++frame)
  {
    const double t = 0.05 * frame;
    for (vtkIdType i = 0; i < 600; ++i)
    {
      const double* b = &base[3 * i];
      points->SetPoint(i, b[0] * 0.9 + 0.08 * std::sin(t + i), b[1] * 0.9 + 0.08 * std::cos(1.3 * t + i),
        b[2] * 0.9);
    }
    points->Modified();
    // A fresh copy, so that the right mapper builds from scratch.
    vtkNew<vtkPolyData> copy;
    copy->DeepCopy(cloud);
    vtkNew<vtkCPUOctreeVolumeMapper> fresh;
    fresh->SetInputData(copy);
    fresh->SetLeafDepth(5);
    right->RemoveAllViewProps();
    right->AddVolume(Volume(fresh));
    const Picture p = Capture(window);
    int covered = 0;
    for (int y = 0; y < h; ++y)
    {
      for (int x = 0; x < w; ++x)
      {
        differing += !Same(p.At(x, y), p.At(x + w, y));
        covered += p.Depth(x, y) < 1.0f;
      }
    }
    emptyFrames += covered < 1000;
  }
  std::cout << "animation: " << frames << " frames, " << animated->GetNumberOfBuilds() << " build(s), "
            << animated->GetNumberOfUpdates() << " updates, " << differing << " differing pixels\n";
  CHECK(animated->GetNumberOfBuilds() == 1);
  CHECK(animated->GetNumberOfUpdates() == frames - 1);
  CHECK(differing == 0);
  CHECK(emptyFrames == 0);
  return 0;
}

// ---- Two render windows with their own mappers on the same input,
// rendering in turn (issue 8): each round both show the same picture, and
// a camera seen before gives the picture it gave then.
int TwoWindows()
{
  const int w = 120, h = 120;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(3000, 33);
  vtkNew<vtkCPUOctreeVolumeMapper> mapperA, mapperB;
  vtkSmartPointer<vtkRenderWindow> windows[2] = { Window(w, h), Window(w, h) };
  vtkNew<vtkRenderer> renderers[2];
  vtkOctreeVolumeMapper* mappers[2] = { mapperA, mapperB };
  for (int k = 0; k < 2; ++k)
  {
    mappers[k]->SetInputData(cloud);
    mappers[k]->SetLeafDepth(6);
    renderers[k]->AddVolume(Volume(mappers[k]));
    SetCamera(renderers[k]->GetActiveCamera(), false);
    windows[k]->AddRenderer(renderers[k]);
  }
  std::vector<Picture> firstLap;
  int differing = 0, changedOnRevisit = 0, empty = 0;
  for (int round = 0; round < 8; ++round)
  {
    // Four camera positions, visited twice.
    Picture p[2];
    for (int k = 0; k < 2; ++k)
    {
      renderers[k]->GetActiveCamera()->Azimuth(90);
      p[k] = Capture(windows[k]);
    }
    int covered = 0;
    for (int y = 0; y < h; ++y)
    {
      for (int x = 0; x < w; ++x)
      {
        differing += !Same(p[0].At(x, y), p[1].At(x, y)) || p[0].Depth(x, y) != p[1].Depth(x, y);
        covered += p[0].Depth(x, y) < 1.0f;
        if (round >= 4)
        {
          changedOnRevisit += !Same(p[0].At(x, y), firstLap[round - 4].At(x, y));
        }
      }
    }
    empty += covered < 500;
    if (round < 4)
    {
      firstLap.push_back(p[0]);
    }
  }
  std::cout << "two windows: " << differing << " pixels differ between the windows, " << changedOnRevisit
            << " changed on revisiting a camera; builds " << mapperA->GetNumberOfBuilds() << " and "
            << mapperB->GetNumberOfBuilds() << "\n";
  CHECK(differing == 0);
  CHECK(changedOnRevisit == 0);
  CHECK(empty == 0);
  CHECK(mapperA->GetNumberOfBuilds() == 1 && mapperB->GetNumberOfBuilds() == 1);
  return 0;
}

// ---- A 4096x4096 offscreen window.
int Large()
{
  const int size = 4096;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(5000, 9);
  vtkNew<vtkCPUOctreeVolumeMapper> mapper;
  mapper->SetInputData(cloud);
  mapper->SetLeafDepth(6);
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(Volume(mapper));
  SetCamera(ren->GetActiveCamera(), false);
  vtkSmartPointer<vtkRenderWindow> window = Window(size, size);
  window->AddRenderer(ren);
  const Picture p = Capture(window);
  CHECK(p.w == size && p.h == size);
  // The cloud fills the middle of the window, not only a corner.
  int covered = 0, quadrants[4] = { 0, 0, 0, 0 };
  for (int y = 0; y < size; y += 4)
  {
    for (int x = 0; x < size; x += 4)
    {
      if (p.Depth(x, y) < 1.0f)
      {
        ++covered;
        ++quadrants[(x >= size / 2) + 2 * (y >= size / 2)];
      }
    }
  }
  std::cout << "4096x4096: " << covered << " of " << (size / 4) * (size / 4) << " sampled pixels covered, trace "
            << mapper->GetLastTraceSeconds() << " s, depth read " << mapper->GetLastDepthReadSeconds()
            << " s, upload " << mapper->GetLastUploadSeconds() << " s\n";
  CHECK(covered > (size / 4) * (size / 4) / 8);
  for (int q : quadrants)
  {
    CHECK(q > covered / 8);
  }
  return 0;
}
} // namespace

int main(int argc, char* argv[])
{
  const std::string what = argc > 1 ? argv[1] : "";
  if (what == "glyphs")
  {
    Glyphs(argc > 2 && std::string(argv[2]) == "parallel");
  }
  else if (what == "mixed")
  {
    Mixed();
  }
  else if (what == "modes" && argc > 3)
  {
    Modes(argv[2], argv[3]);
  }
  else if (what == "work")
  {
    Work();
  }
  else if (what == "animation")
  {
    Animation(argc > 2 ? std::atoi(argv[2]) : 100);
  }
  else if (what == "large")
  {
    Large();
  }
  else if (what == "twowindows")
  {
    TwoWindows();
  }
  else
  {
    std::cerr << "usage: " << argv[0] << " glyphs [parallel] | mixed | modes BASELINES TMP\n";
    return 2;
  }
  return octorayTestFailures == 0 ? 0 : 1;
}
