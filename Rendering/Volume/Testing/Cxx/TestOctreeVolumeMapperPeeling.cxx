// Dual depth peeling of volumes (vtkRenderer::UseDepthPeelingForVolumes,
// on in ParaView's views) with a translucent plate half over the cloud. The
// pass calls volume mappers inside its own framebuffer, once or more a
// frame; the octree's picture drawn there came out garbled. It is drawn
// once a frame into the framebuffer the pass composites onto: behind the
// plate. The cloud is translucent (composite), so that a picture drawn
// twice in a frame would show. Each pixel must be the plate alone over the
// cloud alone (the plate picture, plus what the plate lets through of the
// cloud where it covers it), within 2/255, in two frames running, and the
// mapper says so once. --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkActor.h"
#include "vtkCallbackCommand.h"
#include "vtkColorTransferFunction.h"
#include "vtkCommand.h"
#include "vtkCubeSource.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"

#include <cstdlib>

using namespace octoray_test;

namespace
{
constexpr double kPlateOpacity = 0.4;
// The plate is a thin box: its front and back faces each let 1 - opacity
// through.
constexpr double kThroughPlate = (1.0 - kPlateOpacity) * (1.0 - kPlateOpacity);

vtkSmartPointer<vtkActor> Plate()
{
  vtkNew<vtkCubeSource> plate;
  plate->SetBounds(-0.2, 1.2, -1.2, 0.3, 0.9, 0.95);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(plate->GetOutputPort());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(0.1, 1.0, 0.2);
  actor->GetProperty()->SetOpacity(kPlateOpacity);
  return actor;
}

Picture Draw(vtkOctreeVolumeMapper* mapper, bool withPlate, int size, int frames = 1)
{
  vtkNew<vtkRenderer> ren;
  ren->SetUseDepthPeeling(1);
  ren->SetUseDepthPeelingForVolumes(1);
  ren->SetMaximumNumberOfPeels(8);
  ren->SetOcclusionRatio(0.0);
  if (mapper)
  {
    vtkSmartPointer<vtkVolume> volume = Volume(mapper);
    vtkNew<vtkColorTransferFunction> colour;
    colour->AddRGBPoint(0.0, 1.0, 0.3, 0.1);
    colour->AddRGBPoint(1.0, 1.0, 1.0, 0.6);
    vtkNew<vtkPiecewiseFunction> opacity;
    opacity->AddPoint(0.0, 0.2);
    opacity->AddPoint(1.0, 0.6);
    volume->GetProperty()->IndependentComponentsOn();
    volume->GetProperty()->SetColor(colour);
    volume->GetProperty()->SetScalarOpacity(opacity);
    ren->AddVolume(volume);
  }
  if (withPlate)
  {
    ren->AddActor(Plate());
  }
  SetCamera(ren->GetActiveCamera());
  vtkSmartPointer<vtkRenderWindow> window = Window(size, size);
  window->SetAlphaBitPlanes(1);
  window->AddRenderer(ren);
  Picture p;
  for (int frame = 0; frame < frames; ++frame)
  {
    p = Capture(window);
  }
  return p;
}

// Pixels more than 2/255 off the plate over the cloud.
int OffTheComposite(const Picture& both, const Picture& cloud, const Picture& plate, const Picture& none)
{
  int off = 0;
  for (int y = 0; y < both.h; ++y)
  {
    for (int x = 0; x < both.w; ++x)
    {
      const bool covered = !Same(plate.At(x, y), none.At(x, y));
      for (int c = 0; c < 3; ++c)
      {
        const double expected = covered
          ? plate.At(x, y)[c] + kThroughPlate * (cloud.At(x, y)[c] - none.At(x, y)[c])
          : cloud.At(x, y)[c];
        if (std::abs(both.At(x, y)[c] - expected) > 2.0)
        {
          ++off;
          break;
        }
      }
    }
  }
  return off;
}
}

int TestOctreeVolumeMapperPeeling(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  const int size = 200;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(1500, 11, true);
  auto mapper = [&] {
    vtkSmartPointer<vtkOctreeVolumeMapper> m = NewMapper(backend);
    m->SetInputData(cloud);
    m->SetLeafDepth(5);
    m->SetBlendModeToComposite();
    return m;
  };
  vtkSmartPointer<vtkOctreeVolumeMapper> peeled = mapper();
  int said = 0;
  vtkNew<vtkCallbackCommand> count;
  count->SetClientData(&said);
  count->SetCallback([](vtkObject*, unsigned long, void* n, void*) { ++*static_cast<int*>(n); });
  peeled->AddObserver(vtkCommand::WarningEvent, count);
  const Picture both = Draw(peeled, true, size, 2);
  const Picture cloudOnly = Draw(mapper(), false, size);
  const Picture plateOnly = Draw(nullptr, true, size);
  const Picture none = Draw(nullptr, false, size);
  const int off = OffTheComposite(both, cloudOnly, plateOnly, none);
  int overlap = 0;
  for (int y = 0; y < size; ++y)
  {
    for (int x = 0; x < size; ++x)
    {
      overlap += !Same(plateOnly.At(x, y), none.At(x, y)) && !Same(cloudOnly.At(x, y), none.At(x, y));
    }
  }
  std::cout << "peeling: " << off << " pixels off the plate over the cloud, " << overlap
            << " where the plate covers the cloud; warnings " << said << "\n";
  CHECK(DrewWith(peeled, backend));
  CHECK(overlap > 1000);
  CHECK(off == 0);
  CHECK(said == 1);
  return Result();
}
