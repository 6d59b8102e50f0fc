/**
 * @class   vtkParticleNormals
 * @brief   Estimates point normals of a point cloud with PCL's NormalEstimationOMP.
 *
 * Each point's normal is the smallest-eigenvalue eigenvector of the
 * covariance of its neighbourhood: its k nearest neighbours
 * (NumberOfNeighbors, default 16) or, when Radius > 0, the points within that
 * radius. Normals are flipped to face ViewPoint (default the origin), as PCL's
 * flipNormalTowardsViewpoint does. Output: the input with a `Normals` array
 * (float, set as the active normals) and `Curvature` (PCL's surface
 * variation). Points with too few neighbours for a normal get (0, 0, 0) and
 * are counted (GetNumberOfInvalidNormals, and a warning). PCL works in
 * float; the points are handed to it relative to the centre of their
 * bounds, so that clouds far from the origin (UTM coordinates) keep their
 * precision.
 *
 * PCL's io and visualization components (which link VTK) are not used.
 */
#ifndef vtkParticleNormals_h
#define vtkParticleNormals_h

#include "octorayFiltersPCLModule.h" // for export macro
#include "vtkPolyDataAlgorithm.h"

class OCTORAYFILTERSPCL_EXPORT vtkParticleNormals : public vtkPolyDataAlgorithm
{
public:
  static vtkParticleNormals* New();
  vtkTypeMacro(vtkParticleNormals, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Neighbours per point (k nearest); used when Radius is 0. Default 16.
  vtkSetClampMacro(NumberOfNeighbors, int, 3, VTK_INT_MAX);
  vtkGetMacro(NumberOfNeighbors, int);
  ///@}

  ///@{
  /// Neighbourhood radius; 0 (default) means k nearest neighbours instead.
  vtkSetClampMacro(Radius, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(Radius, double);
  ///@}

  ///@{
  /// Normals are oriented to face this point. Default (0, 0, 0).
  vtkSetVector3Macro(ViewPoint, double);
  vtkGetVector3Macro(ViewPoint, double);
  ///@}

  ///@{
  /// OpenMP threads; 0 (default) means all.
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  /// Points of the last update that had too few neighbours for a normal.
  vtkGetMacro(NumberOfInvalidNormals, vtkIdType);

protected:
  vtkParticleNormals() = default;
  ~vtkParticleNormals() override = default;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int NumberOfNeighbors = 16;
  double Radius = 0;
  double ViewPoint[3] = { 0, 0, 0 };
  int NumberOfThreads = 0;
  vtkIdType NumberOfInvalidNormals = 0;

private:
  vtkParticleNormals(const vtkParticleNormals&) = delete;
  void operator=(const vtkParticleNormals&) = delete;
};

#endif
