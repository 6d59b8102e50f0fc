// A 4096x4096 offscreen window: the cloud fills the middle of the window in
// all four quadrants, not only a corner (no viewport or texture size
// truncation). --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkRenderer.h"

using namespace octoray_test;

int TestOctreeVolumeMapperLarge(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  const int size = 4096;
  vtkSmartPointer<vtkOctreeVolumeMapper> mapper = NewMapper(backend);
  mapper->SetInputData(Cloud(5000, 9));
  mapper->SetLeafDepth(6);
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(Volume(mapper));
  SetCamera(ren->GetActiveCamera());
  vtkSmartPointer<vtkRenderWindow> window = Window(size, size);
  window->AddRenderer(ren);
  const Picture p = Capture(window);
  CHECK(DrewWith(mapper, backend));
  CHECK(p.w == size && p.h == size);
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
            << " s, picture to OpenGL (" << mapper->GetLastPictureTransferName() << ") "
            << mapper->GetLastUploadSeconds() << " s\n";
  CHECK(covered > (size / 4) * (size / 4) / 8);
  for (int q : quadrants)
  {
    CHECK(q > covered / 8);
  }
  return Result();
}
