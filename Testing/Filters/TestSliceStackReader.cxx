// C++ use of vtkSliceStackReader on the bundled DICOM series, and of
// vtkDepthMapReader + vtkParticleNormals on the bundled depth map.
#include "octorayNaturalSort.h"
#include "octorayTestCheck.h"

#include "vtkDataArray.h"
#include "vtkDepthMapReader.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkParticleNormals.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSliceStackReader.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

int main(int argc, char* argv[])
{
  if (argc < 2)
  {
    std::cerr << "usage: " << argv[0] << " Data-directory" << std::endl;
    return EXIT_FAILURE;
  }
  const std::string data = argv[1];

  // Natural order of slice names: numbers by value, leading zeros and numbers
  // longer than 64 bits included.
  {
    std::vector<std::string> names = { "s10.png", "s2.png", "s1.png", "s02.png",
      "s100000000000000000000.png", "s99999999999999999999.png", "a.png", "s.png" };
    std::sort(names.begin(), names.end(), octoray::NaturalLess);
    const std::vector<std::string> expected = { "a.png", "s.png", "s1.png", "s2.png", "s02.png",
      "s10.png", "s99999999999999999999.png", "s100000000000000000000.png" };
    CHECK(names == expected);
  }

  {
    vtkNew<vtkSliceStackReader> r;
    r->SetDirectoryName((data + "/DICOM/CT5N").c_str());
    r->SetBackgroundRange(-10000, -500);
    r->Update();
    CHECK(r->GetIsDICOM());
    CHECK(r->GetNumberOfSlices() == 5);
    // Natural name order is the reverse of the position order for this series.
    CHECK_CONTAINS(r->GetSliceFileName(0), "3353.dcm");
    CHECK_CONTAINS(r->GetSliceFileName(4), "2062.dcm");
    vtkImageData* im = r->GetImageOutput();
    int dims[3];
    im->GetDimensions(dims);
    CHECK(dims[0] == 16 && dims[1] == 16 && dims[2] == 5);
    CHECK(std::abs(im->GetSpacing()[2] - 2.5) < 1e-9);
    CHECK(std::abs(im->GetOrigin()[2] - (-1.2375)) < 1e-5);
    double range[2];
    im->GetScalarRange(range);
    // Rescale intercept -1024 applied: air is near -1000 HU.
    CHECK(range[0] < -800 && range[1] > 0);
    // Filled between slices (the default): 6 planes per 2.5 mm gap (the
    // pixels are 0.488 mm), so 25 planes; the slices' own particles are
    // those of the reader without filling.
    CHECK(r->GetFillBetweenSlices());
    const vtkIdType filled = r->GetOutput()->GetNumberOfPoints();
    CHECK(filled > 0 && filled < 16 * 16 * 25);
    vtkDataArray* lattice = r->GetOutput()->GetFieldData()->GetArray("PointLattice");
    CHECK(lattice && lattice->GetNumberOfComponents() == 15);
    if (lattice)
    {
      CHECK(std::abs(lattice->GetComponent(0, 11) - 2.5 / 6) < 1e-9); // step along the slice normal
      CHECK(lattice->GetComponent(0, 14) == 25);                      // planes
    }
    r->FillBetweenSlicesOff();
    r->Update();
    const vtkIdType slices = r->GetOutput()->GetNumberOfPoints();
    CHECK(slices > 0 && slices < 16 * 16 * 5);
    CHECK(filled > 4 * slices);
  }

  {
    vtkNew<vtkDepthMapReader> depth;
    depth->SetFileName((data + "/DepthMaps/motorcycle_depth_mm.png").c_str());
    depth->SetColorFileName((data + "/DepthMaps/motorcycle_left.png").c_str());
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
    for (vtkIdType i = 0; i < n; ++i)
    {
      double p[3], v[3];
      out->GetPoint(i, p);
      nm->GetTuple(i, v);
      away += (v[0] * -p[0] + v[1] * -p[1] + v[2] * -p[2]) < 0;
    }
    CHECK(away == 0);
    CHECK(out->GetPointData()->GetArray("Colors") != nullptr);
  }

  if (octorayTestFailures)
  {
    std::cerr << octorayTestFailures << " check(s) failed" << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
