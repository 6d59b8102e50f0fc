// The CUDA backend falls back to the CPU, with one warning and no error, and
// the CPU draws the picture: (1) when CUDA cannot build at all (no device
// here, or a memory budget far too small for any octree on a GPU machine);
// (2) where a device is usable, when CUDA fails in the middle of a session
// (the budget shrinks and the window grows, so the next frame's buffers
// cannot be had): the next picture is the CPU backend's, pixel for pixel.
#include "octorayMapperTesting.h"

#include "vtkCallbackCommand.h"
#include "vtkRenderer.h"

using namespace octoray_test;

namespace
{
// Counts warnings and errors, and keeps VTK from printing them.
struct Messages
{
  int warnings = 0, errors = 0;
  std::string last, all;
  vtkNew<vtkCallbackCommand> callback;
  explicit Messages(vtkObject* o)
  {
    callback->SetClientData(this);
    callback->SetCallback([](vtkObject*, unsigned long event, void* self, void* text) {
      auto* m = static_cast<Messages*>(self);
      (event == vtkCommand::WarningEvent ? m->warnings : m->errors)++;
      m->last = text ? static_cast<const char*>(text) : "";
      m->all += m->last + "\n";
    });
    o->AddObserver(vtkCommand::WarningEvent, callback);
    o->AddObserver(vtkCommand::ErrorEvent, callback);
  }
};

struct Scene
{
  vtkSmartPointer<vtkOctreeVolumeMapper> Mapper;
  vtkNew<vtkRenderer> Renderer;
  vtkSmartPointer<vtkRenderWindow> RenderWindow;
  Scene(int backend, vtkPolyData* cloud, int w, int h)
  {
    this->Mapper = vtkSmartPointer<vtkOctreeVolumeMapper>::New();
    this->Mapper->SetRequestedBackend(backend);
    this->Mapper->SetInputData(cloud);
    this->Mapper->SetLeafDepth(6);
    this->Renderer->AddVolume(Volume(this->Mapper));
    SetCamera(this->Renderer->GetActiveCamera());
    this->RenderWindow = Window(w, h);
    this->RenderWindow->AddRenderer(this->Renderer);
  }
};
}

int TestOctreeVolumeMapperFallback(int, char*[])
{
  vtkSmartPointer<vtkPolyData> cloud = Cloud(3000, 3);
  {
    Scene cuda(vtkOctreeVolumeMapper::BACKEND_CUDA, cloud, 120, 120);
    Messages messages(cuda.Mapper);
    cuda.Mapper->SetCudaMemoryBudget(1024); // far too little for any octree
    cuda.RenderWindow->Render();
    std::cout << "CUDA mapper with 1 kB: " << cuda.Mapper->GetLastUsedBackendName() << " ("
              << cuda.Mapper->GetBackendDescription() << "), warning: " << messages.last << "\n";
    CHECK(cuda.Mapper->GetLastUsedBackend() == vtkOctreeVolumeMapper::BACKEND_CPU);
    CHECK(messages.warnings == 1);
    CHECK(messages.errors == 0);
    CHECK(cuda.Mapper->GetNumberOfTraces() == 1);
    cuda.RenderWindow->Render(); // said once
    CHECK(messages.warnings == 1);
  }
  if (!vtkOctreeVolumeMapper::IsCudaAvailable())
  {
    std::cout << "no CUDA device: the failure in mid-session is not exercised here\n";
    return Result();
  }
  Scene cuda(vtkOctreeVolumeMapper::BACKEND_CUDA, cloud, 120, 100);
  Messages messages(cuda.Mapper);
  Capture(cuda.RenderWindow);
  CHECK(std::string(cuda.Mapper->GetLastUsedBackendName()) == "CUDA");
  cuda.Mapper->SetCudaMemoryBudget(1); // what it holds already is over the budget
  cuda.RenderWindow->SetSize(240, 200);
  const Picture fallen = Capture(cuda.RenderWindow);
  std::cout << "after a CUDA failure: " << cuda.Mapper->GetLastUsedBackendName() << ", warning: " << messages.last
            << "\n";
  CHECK(std::string(cuda.Mapper->GetLastUsedBackendName()) == "CPU");
  CHECK(messages.warnings == 1 && messages.errors == 0);
  if (messages.warnings != 1 || messages.errors != 0)
  {
    std::cerr << "messages:\n" << messages.all;
  }
  Scene cpu(vtkOctreeVolumeMapper::BACKEND_CPU, cloud, 240, 200);
  const Picture reference = Capture(cpu.RenderWindow);
  const int differing = Differing(fallen, reference);
  std::cout << differing << " pixels differ from the CPU mapper's picture\n";
  CHECK(differing == 0);
  CHECK(Covered(reference) > 240 * 200 / 10);
  return Result();
}
