// One picture per rendering mode against its baseline image (vtkTesting,
// threshold 0.05 of vtkImageDifference's thresholded error; the same
// baselines and threshold for both backends). Each test also checks that the
// comparison can fail: another mode's picture must fail against the same
// baseline. Arguments: --mode NAME, --backend cpu|cuda, and VTK's -V BASELINE
// -T TEMPORARY (this mode's picture there; the other mode's in
// TEMPORARY/other-mode).
#include "octorayMapperTesting.h"

#include "vtkColorTransferFunction.h"
#include "vtkLight.h"
#include "vtkPiecewiseFunction.h"
#include "vtkRenderer.h"
#include "vtkTrivialProducer.h"

#include <filesystem>
#include <sstream>
#include <string>

using namespace octoray_test;

namespace
{
struct Mode
{
  const char* Name;
  int Blend;
  bool Shade;
  bool Scalars; // transfer function on "Density" (else the RGB colours)
  double DepthCue;
};

const Mode Modes[] = {
  { "surface", vtkOctreeVolumeMapper::SURFACE_BLEND, false, false, 0.0 },
  { "phong", vtkOctreeVolumeMapper::SURFACE_BLEND, true, false, 0.0 },
  { "depthcue", vtkOctreeVolumeMapper::SURFACE_BLEND, false, false, 0.8 },
  { "surface_tf", vtkOctreeVolumeMapper::SURFACE_BLEND, true, true, 0.0 },
  { "composite", vtkVolumeMapper::COMPOSITE_BLEND, false, true, 0.0 },
  { "mip", vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND, false, true, 0.0 },
  { "minip", vtkVolumeMapper::MINIMUM_INTENSITY_BLEND, false, true, 0.0 },
  { "average", vtkVolumeMapper::AVERAGE_INTENSITY_BLEND, false, true, 0.0 },
  { "additive", vtkVolumeMapper::ADDITIVE_BLEND, false, true, 0.0 },
};

// The scene of `mode` in a 200x200 window, rendered.
vtkSmartPointer<vtkRenderWindow> Scene(const Mode& m, const Backend& backend, bool& drewWithBackend)
{
  vtkSmartPointer<vtkPolyData> cloud = Cloud(3000, 5, true);
  vtkSmartPointer<vtkOctreeVolumeMapper> mapper = NewMapper(backend);
  mapper->SetInputData(cloud);
  mapper->SetLeafDepth(6);
  mapper->SetBlendMode(m.Blend);
  mapper->SetDepthCue(m.DepthCue);
  if (!m.Scalars)
  {
    mapper->SelectScalarArray("Colors");
    mapper->SetScalarModeToUsePointFieldData();
  }
  vtkSmartPointer<vtkVolume> volume = Volume(mapper);
  vtkVolumeProperty* property = volume->GetProperty();
  property->SetShade(m.Shade);
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
  if (m.Shade)
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
  SetCamera(ren->GetActiveCamera());
  vtkSmartPointer<vtkRenderWindow> window = Window(200, 200);
  window->AddRenderer(ren);
  window->Render();
  drewWithBackend = DrewWith(mapper, backend);
  return window;
}
}

int TestOctreeVolumeMapperModes(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  const std::string name = Argument(argc, argv, "--mode", "surface");
  const Mode* mode = std::find_if(std::begin(Modes), std::end(Modes), [&](const Mode& m) { return name == m.Name; });
  if (mode == std::end(Modes))
  {
    std::cerr << "no mode '" << name << "'\n";
    return EXIT_FAILURE;
  }
  bool drew = false;
  vtkSmartPointer<vtkRenderWindow> window = Scene(*mode, backend, drew);
  CHECK(drew);
  const int result = vtkTesting::Test(argc, argv, window, 0.05);
  std::cout << mode->Name << ": " << (result == vtkTesting::PASSED ? "passed" : "FAILED") << "\n";
  CHECK(result == vtkTesting::PASSED);

  // The comparison can fail: another mode's picture against this baseline.
  const Mode& other = Modes[mode == &Modes[0] ? 4 : 0];
  vtkSmartPointer<vtkRenderWindow> otherWindow = Scene(other, backend, drew);
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(otherWindow);
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkNew<vtkImageData> picture;
  picture->DeepCopy(grab->GetOutput());
  vtkNew<vtkTrivialProducer> producer;
  producer->SetOutput(picture);
  // Its failed picture goes to a folder of its own under -T: in -T itself
  // it took the place of this mode's picture, from which a baseline is
  // redrawn.
  vtkNew<vtkTesting> testing;
  for (int i = 0; i < argc; ++i)
  {
    std::string argument = argv[i];
    if (i > 0 && std::string(argv[i - 1]) == "-T")
    {
      argument += "/other-mode";
      std::filesystem::create_directories(argument);
    }
    testing->AddArgument(argument.c_str());
  }
  testing->SetRenderWindow(otherWindow);
  std::ostringstream quiet;
  CHECK(testing->RegressionTest(producer, 0.05, quiet) == vtkTesting::FAILED);
  return Result();
}
