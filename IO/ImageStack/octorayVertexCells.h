// One VTK_VERTEX cell per point, for the module's readers: the cells'
// offsets and connectivity written at once rather than a cell at a time.
// Private to the module; not wrapped.
#ifndef octorayVertexCells_h
#define octorayVertexCells_h

#include "vtkCellArray.h"
#include "vtkIdTypeArray.h"
#include "vtkSmartPointer.h"

#include <numeric>

namespace octoray
{
// Cells 0, 1, ..., n - 1, each the vertex of its point.
inline vtkSmartPointer<vtkCellArray> VertexCells(vtkIdType n)
{
  auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
  offsets->SetNumberOfTuples(n + 1);
  auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
  conn->SetNumberOfTuples(n);
  std::iota(offsets->GetPointer(0), offsets->GetPointer(0) + n + 1, 0);
  std::iota(conn->GetPointer(0), conn->GetPointer(0) + n, 0);
  auto verts = vtkSmartPointer<vtkCellArray>::New();
  verts->SetData(offsets, conn);
  return verts;
}
} // namespace octoray

#endif
