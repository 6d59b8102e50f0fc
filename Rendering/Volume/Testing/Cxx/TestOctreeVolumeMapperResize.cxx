// A window resized between frames: the picture at each size is the one a
// new mapper in a new window of that size draws (textures, and on CUDA the
// interop registrations, follow the size), and going back to the first size
// gives the first picture again. --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkRenderer.h"

using namespace octoray_test;

namespace
{
struct Scene
{
  vtkSmartPointer<vtkOctreeVolumeMapper> Mapper;
  vtkNew<vtkRenderer> Renderer;
  vtkSmartPointer<vtkRenderWindow> RenderWindow;
  Scene(const Backend& backend, vtkPolyData* cloud, int w, int h)
  {
    this->Mapper = NewMapper(backend);
    this->Mapper->SetInputData(cloud);
    this->Mapper->SetLeafDepth(6);
    this->Renderer->AddVolume(Volume(this->Mapper));
    SetCamera(this->Renderer->GetActiveCamera());
    this->RenderWindow = Window(w, h);
    this->RenderWindow->AddRenderer(this->Renderer);
  }
};
}

int TestOctreeVolumeMapperResize(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  vtkSmartPointer<vtkPolyData> cloud = Cloud(3000, 41);
  const int sizes[][2] = { { 200, 150 }, { 320, 240 }, { 123, 301 }, { 200, 150 } };
  Scene resized(backend, cloud, sizes[0][0], sizes[0][1]);
  std::vector<Picture> seen;
  int differing = 0, notByBackend = 0;
  for (const auto& size : sizes)
  {
    resized.RenderWindow->SetSize(size[0], size[1]);
    const Picture p = Capture(resized.RenderWindow);
    notByBackend += !DrewWith(resized.Mapper, backend);
    Scene fresh(backend, cloud, size[0], size[1]);
    const Picture reference = Capture(fresh.RenderWindow);
    CHECK(p.w == size[0] && p.h == size[1]);
    CHECK(Covered(reference) > size[0] * size[1] / 10);
    const int d = Differing(p, reference);
    std::cout << size[0] << "x" << size[1] << ": " << d << " pixels differ from a new window's\n";
    differing += d;
    seen.push_back(p);
  }
  CHECK(notByBackend == 0);
  CHECK(differing == 0);
  CHECK(Differing(seen.front(), seen.back()) == 0);
  CHECK(resized.Mapper->GetNumberOfBuilds() == 1);
  return Result();
}
