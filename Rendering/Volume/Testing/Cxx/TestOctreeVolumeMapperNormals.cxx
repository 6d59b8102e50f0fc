// Shading points that have no normals (EstimateNormals): a tilted sheet of
// white points, a voxel or two thick, lit by the headlight under a parallel
// camera, against the brightness its plane gives (ambient + diffuse times
// the cosine between the plane's normal and the view); with EstimateNormals
// off, the six-neighbour occupancy gradient misses it. Normals the input has
// are drawn the same either way. Arguments: --backend cpu|cuda.
#include "octorayMapperTesting.h"

#include "vtkRenderer.h"

#include <array>

using namespace octoray_test;

namespace
{
// The sheet z = 0.3 x - 0.2 y over [-1, 1]^2 (its normal (-0.3, 0.2, 1)),
// with that normal as its "Normals" where asked.
vtkSmartPointer<vtkPolyData> Sheet(bool withNormals)
{
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  vtkNew<vtkPoints> points;
  vtkNew<vtkFloatArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  for (int i = 0; i < 40000; ++i)
  {
    const double x = u(rng), y = u(rng);
    points->InsertNextPoint(x, y, 0.3 * x - 0.2 * y);
    normals->InsertNextTuple3(-0.3, 0.2, 1.0);
  }
  auto sheet = vtkSmartPointer<vtkPolyData>::New();
  sheet->SetPoints(points);
  if (withNormals)
  {
    sheet->GetPointData()->SetNormals(normals);
  }
  return sheet;
}

struct Lit
{
  Picture picture;
  int covered = 0;
  int asThePlane = 0; // covered pixels within 6/255 of the plane's brightness
};

Lit Draw(const Backend& backend, bool withNormals, bool estimate)
{
  vtkSmartPointer<vtkOctreeVolumeMapper> mapper = NewMapper(backend);
  mapper->SetInputData(Sheet(withNormals));
  mapper->SetLeafDepth(7);
  mapper->SetEstimateNormals(estimate);
  vtkSmartPointer<vtkVolume> volume = Volume(mapper);
  vtkVolumeProperty* property = volume->GetProperty();
  property->ShadeOn();
  property->SetAmbient(0.1);
  property->SetDiffuse(0.7);
  property->SetSpecular(0.0);
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(volume);
  vtkCamera* camera = ren->GetActiveCamera();
  const std::array<double, 3> view{ 0.4, -0.9, 2.0 }; // from the focal point towards the camera
  camera->SetFocalPoint(0, 0, 0);
  camera->SetPosition(view[0], view[1], view[2]);
  camera->SetViewUp(0, 1, 0);
  camera->ParallelProjectionOn();
  camera->SetParallelScale(1.2);
  camera->SetClippingRange(0.5, 5.0);
  vtkSmartPointer<vtkRenderWindow> window = Window(160, 160);
  window->AddRenderer(ren);
  Lit lit;
  lit.picture = Capture(window);
  CHECK(DrewWith(mapper, backend));
  const double n[3] = { -0.3, 0.2, 1.0 };
  const double cosine = (n[0] * view[0] + n[1] * view[1] + n[2] * view[2]) /
    std::sqrt((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) * (view[0] * view[0] + view[1] * view[1] + view[2] * view[2]));
  const double expected = 255.0 * (0.1 + 0.7 * cosine);
  for (int y = 0; y < lit.picture.h; ++y)
  {
    for (int x = 0; x < lit.picture.w; ++x)
    {
      if (lit.picture.Depth(x, y) < 1.0f)
      {
        ++lit.covered;
        lit.asThePlane += std::fabs(lit.picture.At(x, y)[0] - expected) <= 6.0;
      }
    }
  }
  std::cout << (withNormals ? "normals given" : "no normals") << ", EstimateNormals " << (estimate ? "on" : "off")
            << ": " << lit.asThePlane << " of " << lit.covered << " pixels within 6/255 of the plane's "
            << expected << std::endl;
  return lit;
}
}

int TestOctreeVolumeMapperNormals(int argc, char* argv[])
{
  OCTORAY_TEST_BACKEND(backend);
  const Lit estimated = Draw(backend, false, true);
  const Lit occupancy = Draw(backend, false, false);
  // On the CPU here: 11244 of 13335 pixels (84 %) by the estimate, 0 by
  // the occupancy gradient. The voxels' steps tilt some fits by a few
  // degrees, as on a sphere (TestNormalEstimation).
  CHECK(estimated.covered > 10000);
  CHECK(estimated.asThePlane >= 0.75 * estimated.covered);
  CHECK(occupancy.asThePlane < 0.5 * occupancy.covered);
  // The input's own normals win: the switch changes nothing.
  const Lit given = Draw(backend, true, true);
  CHECK(given.asThePlane >= 0.9 * given.covered);
  CHECK(Differing(given.picture, Draw(backend, true, false).picture) == 0);
  return Result();
}
