// What the representation needs for ParaView's parallel rendering: the
// piece the view redistributes, and whether this ParaView's ranks can
// exchange data at all.
#ifndef octorayParallelPieces_h
#define octorayParallelPieces_h

#include "vtkSmartPointer.h" // for the piece

#include <string> // for the path

class vtkPointSet;
class vtkUnstructuredGrid;

namespace octoray
{
// The points of a point set as a vtkUnstructuredGrid with one vertex cell per
// point, the piece the view redistributes before ordered compositing
// (vtkOrderedCompositeDistributor, a vtkRedistributeDataSetFilter with the
// view's k-d tree cuts):
// - the filter moves cells, so points that no cell uses (a point cloud
//   without vertex cells) would be lost, and the points of a mesh's faces
//   would be duplicated along the cuts; with one vertex per point every
//   point goes to exactly one rank;
// - an unstructured grid, not polydata: the distributor turns redistributed
//   polydata back into polydata with vtkDataSetSurfaceFilter, which
//   dereferences the points of its input, and a rank that receives no cell
//   gets a grid without points (ParaView 5.11 then crashes with SIGSEGV in
//   vtkDataSetSurfaceFilter::UnstructuredGridExecuteInternal); an
//   unstructured grid is passed on as it is.
// Point data and field data are shallow copies; the octree uses neither
// cells nor cell data.
vtkSmartPointer<vtkUnstructuredGrid> PointCloudPiece(vtkPointSet* input);

// ParaView 5.11's ranks exchange data as XML whose binary part VTK 9.2's
// parser leaves to expat to skip; a libexpat that defers reparsing (expat
// 2.6, and Debian 12's libexpat1 2.5.0-1+deb12u2 and later) does not, and
// every exchange fails. Plugin/ExpatCompat, preloaded, turns the deferral off
// and says so by a symbol. Returns the preload's path when it is needed and
// missing, else an empty string.
std::string MissingExpatCompat();
}

#endif
// VTK-HeaderTest-Exclude: octorayParallelPieces.h
