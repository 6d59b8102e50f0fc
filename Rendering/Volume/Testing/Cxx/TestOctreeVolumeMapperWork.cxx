// Work only when needed: the octree is built when the input or the arrays it
// uses change, updated in place when only point positions move, and the
// picture is traced again only when the camera, lights, properties,
// settings or the opaque geometry's depth change. Also: the default backend choice, TimeToDraw and the
// render events, and image input. --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkActor.h"
#include "vtkLight.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderer.h"
#include "vtkSphereSource.h"

using namespace octoray_test;

namespace
{
// Counts the mapper's render events.
struct Events
{
  int starts = 0, ends = 0;
  vtkNew<vtkCallbackCommand> callback;
  explicit Events(vtkObject* o)
  {
    callback->SetClientData(this);
    callback->SetCallback([](vtkObject*, unsigned long event, void* self, void*) {
      auto* e = static_cast<Events*>(self);
      (event == vtkCommand::VolumeMapperRenderStartEvent ? e->starts : e->ends)++;
    });
    o->AddObserver(vtkCommand::VolumeMapperRenderStartEvent, callback);
    o->AddObserver(vtkCommand::VolumeMapperRenderEndEvent, callback);
  }
};

// The number of builds, updates and traces the mapper has made.
bool Made(vtkOctreeVolumeMapper* m, int builds, int updates, int traces)
{
  const bool ok =
    m->GetNumberOfBuilds() == builds && m->GetNumberOfUpdates() == updates && m->GetNumberOfTraces() == traces;
  if (!ok)
  {
    std::cerr << "builds " << m->GetNumberOfBuilds() << " updates " << m->GetNumberOfUpdates() << " traces "
              << m->GetNumberOfTraces() << ", expected " << builds << " " << updates << " " << traces << "\n";
  }
  return ok;
}
}

int TestOctreeVolumeMapperWork(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  // AUTO, the default, takes CUDA where a device is usable.
  {
    vtkNew<vtkOctreeVolumeMapper> automatic;
    CHECK(automatic->GetRequestedBackend() == vtkOctreeVolumeMapper::BACKEND_AUTO);
    automatic->SetInputData(Cloud(100, 1));
    vtkNew<vtkRenderer> ren;
    ren->AddVolume(Volume(automatic));
    vtkSmartPointer<vtkRenderWindow> window = Window(64, 64);
    window->AddRenderer(ren);
    window->Render();
    CHECK(std::string(automatic->GetLastUsedBackendName()) ==
      (vtkOctreeVolumeMapper::IsCudaAvailable() ? "CUDA" : "CPU"));
  }

  vtkSmartPointer<vtkPolyData> cloud = Cloud(2000, 3);
  vtkSmartPointer<vtkOctreeVolumeMapper> mapper = NewMapper(backend);
  Events events(mapper);
  mapper->SetInputData(cloud);
  vtkNew<vtkRenderer> ren;
  vtkSmartPointer<vtkVolume> volume = Volume(mapper);
  ren->AddVolume(volume);
  SetCamera(ren->GetActiveCamera());
  vtkSmartPointer<vtkRenderWindow> window = Window(160, 120);
  window->AddRenderer(ren);
  window->Render();
  CHECK(Made(mapper, 1, 0, 1));
  CHECK(DrewWith(mapper, backend));
  CHECK(mapper->GetNumberOfOctreePoints() == 2000);
  CHECK(events.starts == 1 && events.ends == 1);
  // TimeToDraw covers the build and the trace, so it is at least the trace.
  CHECK(mapper->GetTimeToDraw() >= mapper->GetLastTraceSeconds());
  CHECK(mapper->GetTimeToDraw() > 0.0);
  // Nothing changed: no build, no trace.
  window->Render();
  CHECK(Made(mapper, 1, 0, 1));
  CHECK(events.starts == 2 && events.ends == 2);
  // The camera moved: trace, no build.
  ren->GetActiveCamera()->Azimuth(10);
  window->Render();
  CHECK(Made(mapper, 1, 0, 2));
  // A light added, then changed: trace each time.
  vtkNew<vtkLight> light;
  light->SetPosition(1, 2, 3);
  ren->AddLight(light);
  window->Render();
  CHECK(Made(mapper, 1, 0, 3));
  light->SetIntensity(0.5);
  window->Render();
  CHECK(Made(mapper, 1, 0, 4));
  // The property changed: trace.
  volume->GetProperty()->SetAmbient(0.3);
  window->Render();
  CHECK(Made(mapper, 1, 0, 5));
  // Opaque geometry appeared in front (the window depth changed): trace;
  // then nothing changed again: no trace.
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(0.5, 0.3, 0.8);
  sphere->SetRadius(0.3);
  vtkNew<vtkPolyDataMapper> sphereMapper;
  sphereMapper->SetInputConnection(sphere->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(sphereMapper);
  ren->AddActor(actor);
  window->Render();
  CHECK(Made(mapper, 1, 0, 6));
  window->Render();
  CHECK(Made(mapper, 1, 0, 6));
  ren->RemoveActor(actor);
  window->Render();
  CHECK(Made(mapper, 1, 0, 7));
  // Only the positions changed (same array, modified in place): update.
  double p[3];
  cloud->GetPoints()->GetPoint(0, p);
  p[0] += 0.01;
  cloud->GetPoints()->SetPoint(0, p);
  cloud->GetPoints()->Modified();
  window->Render();
  CHECK(Made(mapper, 1, 1, 8));
  // The colours changed: rebuild.
  cloud->GetPointData()->GetScalars()->Modified();
  window->Render();
  CHECK(Made(mapper, 2, 1, 9));
  // A mapper setting that shapes the octree: rebuild.
  mapper->SetLeafDepth(3);
  window->Render();
  CHECK(Made(mapper, 3, 1, 10));
  // Depth 3: a leaf is an eighth of the root cube, which is about 2 wide.
  CHECK(mapper->GetLeafSize() * 8 > 1.8 && mapper->GetLeafSize() * 8 < 2.01);
  // A setting of the picture only: trace, no build.
  mapper->SetBlendModeToMaximumIntensity();
  window->Render();
  CHECK(Made(mapper, 3, 1, 11));
  CHECK(DrewWith(mapper, backend));

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
    vtkSmartPointer<vtkOctreeVolumeMapper> imageMapper = NewMapper(backend);
    imageMapper->SetInputData(image);
    imageMapper->SetImageBackground(1.0);
    vtkNew<vtkRenderer> r2;
    r2->AddVolume(Volume(imageMapper));
    r2->ResetCamera();
    vtkSmartPointer<vtkRenderWindow> w2 = Window(100, 100);
    w2->AddRenderer(r2);
    w2->Render();
    CHECK(imageMapper->GetNumberOfOctreePoints() == 250);
    CHECK(DrewWith(imageMapper, backend));
  }
  return Result();
}
