// vtkSliceStackReader on the bundled DICOM series (Data/DICOM/CT5N): order
// by position, geometry, rescale, the particles filled between slices and
// their lattice, and the particles of the slices alone.
#include "octorayTestCheck.h"

#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkSliceStackReader.h"
#include "vtkTestUtilities.h"

#include <cmath>
#include <string>

int TestSliceStackReader(int argc, char* argv[])
{
  char* series = vtkTestUtilities::ExpandDataFileName(argc, argv, "Data/DICOM/CT5N");
  vtkNew<vtkSliceStackReader> r;
  r->SetDirectoryName(series);
  delete[] series;
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
  return octoray_test::Result();
}
