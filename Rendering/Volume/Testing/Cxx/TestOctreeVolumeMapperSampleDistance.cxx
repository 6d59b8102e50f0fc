// ImageSampleDistance 2: one ray per 2x2 pixels, stretched over the window.
// The rays are exactly those of the same camera in a window of half the
// size, so the picture must be that half-size picture with each pixel
// doubled in both directions: colour and depth, pixel for pixel.
// --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkRenderer.h"

using namespace octoray_test;

int TestOctreeVolumeMapperSampleDistance(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  const int w = 160, h = 120; // even: every traced pixel covers exactly 2x2
  vtkSmartPointer<vtkPolyData> cloud = Cloud(2500, 17);
  auto render = [&](int width, int height, double sampleDistance, bool& drew) {
    vtkSmartPointer<vtkOctreeVolumeMapper> mapper = NewMapper(backend);
    mapper->SetInputData(cloud);
    mapper->SetLeafDepth(6);
    mapper->SetImageSampleDistance(sampleDistance);
    vtkNew<vtkRenderer> ren;
    ren->AddVolume(Volume(mapper));
    SetCamera(ren->GetActiveCamera());
    vtkSmartPointer<vtkRenderWindow> window = Window(width, height);
    window->AddRenderer(ren);
    const Picture p = Capture(window);
    drew = DrewWith(mapper, backend);
    return p;
  };
  bool drewCoarse = false, drewSmall = false;
  const Picture coarse = render(w, h, 2.0, drewCoarse);
  const Picture small = render(w / 2, h / 2, 1.0, drewSmall);
  CHECK(drewCoarse && drewSmall);
  int colour = 0, depth = 0;
  for (int y = 0; y < h; ++y)
  {
    for (int x = 0; x < w; ++x)
    {
      colour += !Same(coarse.At(x, y), small.At(x / 2, y / 2));
      depth += coarse.Depth(x, y) != small.Depth(x / 2, y / 2);
    }
  }
  std::cout << "sample distance 2: " << Covered(coarse) << " covered pixels, " << colour << " colour and " << depth
            << " depth differences against the half-size picture doubled\n";
  CHECK(Covered(coarse) > w * h / 8);
  CHECK(colour == 0);
  CHECK(depth == 0);
  return Result();
}
