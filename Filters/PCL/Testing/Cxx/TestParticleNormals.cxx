// vtkParticleNormals on the bundled depth map (Data/DepthMaps), read with
// its colour image by vtkDepthMapReader: every valid pixel a point, each
// with a normal that faces the camera, the colours kept. And on a tilted
// plane of points 2 cm apart in UTM coordinates (northing 5.5e6 m, where a
// float steps by 0.5 m): every normal within 1 degree of the plane's.
#include "octorayTestCheck.h"

#include "vtkDataArray.h"
#include "vtkDepthMapReader.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkParticleNormals.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkTestUtilities.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace
{
// z = 0.3 x + 0.1 y over a 1.2 m square of points 2 cm apart (each moved
// up to 0.5 cm along the plane, fixed pattern), around a UTM position;
// normals should face up (ViewPoint above). Returns the largest angle in
// degrees between a point's normal and the plane's (180 where a point got
// none).
double LargestAngleOnFarPlane()
{
  const double origin[3] = { 637012.0, 5549028.0, 431.0 };
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (int i = 0; i < 60; ++i)
  {
    for (int j = 0; j < 60; ++j)
    {
      const double x = 0.02 * i + 0.005 * std::sin(7.0 * i + 3.0 * j);
      const double y = 0.02 * j + 0.005 * std::cos(5.0 * i - 11.0 * j);
      points->InsertNextPoint(origin[0] + x, origin[1] + y, origin[2] + 0.3 * x + 0.1 * y);
    }
  }
  vtkNew<vtkPolyData> plane;
  plane->SetPoints(points);
  vtkNew<vtkParticleNormals> normals;
  normals->SetInputData(plane);
  normals->SetViewPoint(origin[0], origin[1], origin[2] + 100.0);
  normals->Update();
  double up[3] = { -0.3, -0.1, 1.0 };
  vtkMath::Normalize(up);
  vtkDataArray* nm = normals->GetOutput()->GetPointData()->GetNormals();
  double largest = nm ? 0.0 : 180.0;
  for (vtkIdType i = 0; nm && i < nm->GetNumberOfTuples(); ++i)
  {
    double v[3];
    nm->GetTuple(i, v);
    // (0, 0, 0), a point without a normal, counts as the worst.
    const double angle = vtkMath::Norm(v) > 0.5
      ? vtkMath::DegreesFromRadians(vtkMath::AngleBetweenVectors(v, up))
      : 180.0;
    largest = std::max(largest, angle);
  }
  return largest;
}
}

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

  const double angle = LargestAngleOnFarPlane();
  std::cout << "plane at UTM coordinates: largest angle to its normal " << angle << " degrees\n";
  CHECK(angle < 1.0);
  return octoray_test::Result();
}
