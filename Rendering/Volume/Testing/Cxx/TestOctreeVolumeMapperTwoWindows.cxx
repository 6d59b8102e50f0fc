// Two render windows with their own mappers on the same input, rendering in
// turn (each its own OpenGL context, and on CUDA its own engine and interop
// registrations): each round both show the same picture, and a camera seen
// before gives the picture it gave then. --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkRenderer.h"

using namespace octoray_test;

int TestOctreeVolumeMapperTwoWindows(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  const int w = 120, h = 120;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(3000, 33);
  vtkSmartPointer<vtkOctreeVolumeMapper> mappers[2] = { NewMapper(backend), NewMapper(backend) };
  vtkSmartPointer<vtkRenderWindow> windows[2] = { Window(w, h), Window(w, h) };
  vtkNew<vtkRenderer> renderers[2];
  for (int k = 0; k < 2; ++k)
  {
    mappers[k]->SetInputData(cloud);
    mappers[k]->SetLeafDepth(6);
    renderers[k]->AddVolume(Volume(mappers[k]));
    SetCamera(renderers[k]->GetActiveCamera());
    windows[k]->AddRenderer(renderers[k]);
  }
  std::vector<Picture> firstLap;
  int differing = 0, changedOnRevisit = 0, empty = 0, notByBackend = 0;
  for (int round = 0; round < 8; ++round)
  {
    // Four camera positions, visited twice.
    Picture p[2];
    for (int k = 0; k < 2; ++k)
    {
      renderers[k]->GetActiveCamera()->Azimuth(90);
      p[k] = Capture(windows[k]);
      notByBackend += !DrewWith(mappers[k], backend);
    }
    differing += Differing(p[0], p[1]);
    empty += Covered(p[0]) < 500;
    if (round >= 4)
    {
      for (int y = 0; y < h; ++y)
      {
        for (int x = 0; x < w; ++x)
        {
          changedOnRevisit += !Same(p[0].At(x, y), firstLap[round - 4].At(x, y));
        }
      }
    }
    else
    {
      firstLap.push_back(p[0]);
    }
  }
  std::cout << "two windows: " << differing << " pixels differ between the windows, " << changedOnRevisit
            << " changed on revisiting a camera; builds " << mappers[0]->GetNumberOfBuilds() << " and "
            << mappers[1]->GetNumberOfBuilds() << "\n";
  CHECK(notByBackend == 0);
  CHECK(differing == 0);
  CHECK(changedOnRevisit == 0);
  CHECK(empty == 0);
  CHECK(mappers[0]->GetNumberOfBuilds() == 1 && mappers[1]->GetNumberOfBuilds() == 1);
  return Result();
}
