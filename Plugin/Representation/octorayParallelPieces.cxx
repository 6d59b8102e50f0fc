#include "octorayParallelPieces.h"

#include "vtkCellArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkUnstructuredGrid.h"

#include <dlfcn.h>

namespace octoray
{
//----------------------------------------------------------------------------
vtkSmartPointer<vtkUnstructuredGrid> PointCloudPiece(vtkPointSet* input)
{
  auto cloud = vtkSmartPointer<vtkUnstructuredGrid>::New();
  if (input->GetPoints())
  {
    cloud->SetPoints(input->GetPoints());
  }
  else
  {
    vtkNew<vtkPoints> none;
    cloud->SetPoints(none);
  }
  const vtkIdType n = input->GetNumberOfPoints();
  vtkNew<vtkIdTypeArray> offsets;
  vtkNew<vtkIdTypeArray> connectivity;
  offsets->SetNumberOfValues(n + 1);
  connectivity->SetNumberOfValues(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    offsets->SetValue(i, i);
    connectivity->SetValue(i, i);
  }
  offsets->SetValue(n, n);
  vtkNew<vtkCellArray> verts;
  verts->SetData(offsets, connectivity);
  cloud->SetCells(VTK_VERTEX, verts);
  cloud->GetPointData()->ShallowCopy(input->GetPointData());
  cloud->GetFieldData()->ShallowCopy(input->GetFieldData());
  return cloud;
}

//----------------------------------------------------------------------------
std::string MissingExpatCompat()
{
  if (!dlsym(RTLD_DEFAULT, "XML_SetReparseDeferralEnabled") ||
    dlsym(RTLD_DEFAULT, "octoray_expat_reparse_deferral_off"))
  {
    return std::string();
  }
  // Beside the plugin's build: lib/paraview-5.11/plugins/Octoray/Octoray.so.
  Dl_info self;
  std::string dir = dladdr(reinterpret_cast<void*>(&MissingExpatCompat), &self) && self.dli_fname
    ? self.dli_fname
    : "lib/paraview-5.11/plugins/Octoray/Octoray.so";
  for (int up = 0; up < 4 && dir.find('/') != std::string::npos; ++up)
  {
    dir.erase(dir.rfind('/'));
  }
  return dir + "/liboctorayExpatCompat.so";
}
}
