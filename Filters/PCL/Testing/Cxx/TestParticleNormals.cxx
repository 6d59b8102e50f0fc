// vtkParticleNormals on the bundled depth map (Data/DepthMaps), read with
// its colour image by vtkDepthMapReader: every valid pixel a point, each
// with a normal that faces the camera, the colours kept.
#include "octorayTestCheck.h"

#include "vtkDataArray.h"
#include "vtkDepthMapReader.h"
#include "vtkNew.h"
#include "vtkParticleNormals.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkTestUtilities.h"

#include <string>

int TestParticleNormals(int argc, char* argv[])
{
  char* root = vtkTestUtilities::ExpandDataFileName(argc, argv, "Data/DepthMaps");
  const std::string maps = root;
  delete[] root;
  vtkNew<vtkDepthMapReader> depth;
  depth->SetFileName((maps + "/motorcycle_depth_mm.png").c_str());
  depth->SetColorFileName((maps + "/motorcycle_left.png").c_str());
  depth->SetIntrinsics(497.489, 497.489, 155.5965, 127.4385);
  depth->SetDepthScale(0.001);
  depth->SetStride(4);
  vtkNew<vtkParticleNormals> normals;
  normals->SetInputConnection(depth->GetOutputPort());
  normals->SetNumberOfNeighbors(8);
  normals->Update();
  vtkPolyData* out = normals->GetOutput();
  const vtkIdType n = out->GetNumberOfPoints();
  CHECK(n > 4000);
  CHECK(n + depth->GetNumberOfInvalidPixels() == 93 * 63);
  vtkDataArray* nm = out->GetPointData()->GetNormals();
  CHECK(nm && nm->GetNumberOfTuples() == n);
  // Normals face the camera at the origin: n . (0 - p) >= 0.
  vtkIdType away = 0;
  for (vtkIdType i = 0; nm && i < n; ++i)
  {
    double p[3], v[3];
    out->GetPoint(i, p);
    nm->GetTuple(i, v);
    away += (v[0] * -p[0] + v[1] * -p[1] + v[2] * -p[2]) < 0;
  }
  CHECK(away == 0);
  CHECK(out->GetPointData()->GetArray("Colors") != nullptr);
  return octoray_test::Result();
}
