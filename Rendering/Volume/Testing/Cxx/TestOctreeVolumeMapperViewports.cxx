// One window, two renderers side by side drawing the same scene: a cloud
// with a sphere half inside it (depth both ways between the octree and an
// OpenGL actor). The right renderer's viewport is away from the window's
// corner, where VTK scissors the viewport; the mapper's copy of the depth
// there was scissored away, and the cloud vanished behind depth 0 (in a
// multisampled window, and on CUDA in any). Both halves must be the same
// picture, and hold the cloud: the same colours, depths within 1e-5
// (OpenGL rasterises the sphere's depth a few ulps apart at another window
// position), but for at most one pixel in a thousand (multisampled, a few
// pixels of the sphere's edge resolve otherwise there). --samples N
// (default 8); --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkActor.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkSphereSource.h"

#include <cmath>

using namespace octoray_test;

namespace
{
vtkSmartPointer<vtkActor> Sphere()
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(0.6, 0.2, 0.3);
  sphere->SetRadius(0.6);
  sphere->SetThetaResolution(48);
  sphere->SetPhiResolution(48);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(sphere->GetOutputPort());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(0.2, 0.4, 1.0);
  return actor;
}

// Pixels whose colour differs, or whose depth differs by more than 1e-5,
// between two pictures of one size.
int DifferingBeyondRounding(const Picture& a, const Picture& b)
{
  int n = 0;
  for (int y = 0; y < a.h; ++y)
  {
    for (int x = 0; x < a.w; ++x)
    {
      n += !Same(a.At(x, y), b.At(x, y)) || std::abs(a.Depth(x, y) - b.Depth(x, y)) > 1e-5f;
    }
  }
  return n;
}

// The pixels of `p` from column x0 on, `w` wide.
Picture Columns(const Picture& p, int x0, int w)
{
  Picture part;
  part.w = w;
  part.h = p.h;
  for (int y = 0; y < p.h; ++y)
  {
    part.rgb.insert(part.rgb.end(), p.At(x0, y), p.At(x0, y) + 3 * w);
    part.depth.insert(part.depth.end(), &p.depth[static_cast<size_t>(y) * p.w + x0],
      &p.depth[static_cast<size_t>(y) * p.w + x0] + w);
  }
  return part;
}
}

int TestOctreeVolumeMapperViewports(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  const int samples = std::stoi(Argument(argc, argv, "--samples", "8"));
  const int size = 160;
  vtkSmartPointer<vtkPolyData> cloud = Cloud(1500, 11);
  vtkSmartPointer<vtkRenderWindow> window = Window(2 * size, size, samples);
  vtkSmartPointer<vtkOctreeVolumeMapper> mappers[2] = { NewMapper(backend), NewMapper(backend) };
  for (int k = 0; k < 2; ++k)
  {
    mappers[k]->SetInputData(cloud);
    mappers[k]->SetLeafDepth(5);
    vtkNew<vtkRenderer> ren;
    ren->SetViewport(0.5 * k, 0.0, 0.5 * (k + 1), 1.0);
    ren->AddVolume(Volume(mappers[k]));
    ren->AddActor(Sphere());
    SetCamera(ren->GetActiveCamera());
    window->AddRenderer(ren);
  }
  const Picture both = Capture(window);
  const Picture left = Columns(both, 0, size), right = Columns(both, size, size);

  vtkSmartPointer<vtkRenderWindow> sphereWindow = Window(size, size, samples);
  vtkNew<vtkRenderer> sphereOnly;
  sphereOnly->AddActor(Sphere());
  SetCamera(sphereOnly->GetActiveCamera());
  sphereWindow->AddRenderer(sphereOnly);
  const int sphereCovers = Covered(Capture(sphereWindow));

  const int differing = DifferingBeyondRounding(left, right);
  std::cout << "viewports: " << differing << " pixels differ between the halves; covered " << Covered(left)
            << " and " << Covered(right) << ", the sphere alone " << sphereCovers << "\n";
  CHECK(DrewWith(mappers[0], backend) && DrewWith(mappers[1], backend));
  CHECK(differing <= size * size / 1000);
  CHECK(Covered(left) > sphereCovers + 1000);
  return Result();
}
