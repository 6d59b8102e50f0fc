#include "vtkParticleNormals.h"

#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <pcl/features/normal_3d_omp.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <cmath>
#include <thread>

vtkStandardNewMacro(vtkParticleNormals);

//------------------------------------------------------------------------------
int vtkParticleNormals::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* input = vtkPolyData::GetData(inputVector[0], 0);
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  output->ShallowCopy(input);
  this->NumberOfInvalidNormals = 0;
  const vtkIdType n = input->GetNumberOfPoints();
  if (n == 0)
  {
    return 1;
  }
  if (n < 3)
  {
    vtkErrorMacro(<< "normals need at least 3 points; the input has " << n);
    return 0;
  }

  // PCL takes float coordinates. Far from the origin (a LiDAR tile in UTM
  // metres: eastings near 6e5, northings up to 1e7) a float rounds to steps
  // of 6 cm to 1 m, coarser than a scan's spacing, and the neighbourhoods'
  // covariances turn to noise; so the points go to PCL relative to the
  // centre of their bounds, subtracted in double. A translation does not
  // change the normals.
  double bounds[6];
  input->GetBounds(bounds);
  const double centre[3] = { 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
    0.5 * (bounds[4] + bounds[5]) };
  const auto relative = [&centre](const double p[3]) {
    return pcl::PointXYZ(static_cast<float>(p[0] - centre[0]),
      static_cast<float>(p[1] - centre[1]), static_cast<float>(p[2] - centre[2]));
  };
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(static_cast<size_t>(n));
  double x[3];
  for (vtkIdType i = 0; i < n; ++i)
  {
    input->GetPoint(i, x);
    (*cloud)[i] = relative(x);
  }
  this->UpdateProgress(0.1);

  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> estimator(
    this->NumberOfThreads > 0 ? static_cast<unsigned>(this->NumberOfThreads)
                              : std::max(1u, std::thread::hardware_concurrency()));
  estimator.setInputCloud(cloud);
  estimator.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  if (this->Radius > 0)
  {
    estimator.setRadiusSearch(this->Radius);
  }
  else
  {
    estimator.setKSearch(std::min<int>(this->NumberOfNeighbors, static_cast<int>(n)));
  }
  const pcl::PointXYZ viewPoint = relative(this->ViewPoint);
  estimator.setViewPoint(viewPoint.x, viewPoint.y, viewPoint.z);
  pcl::PointCloud<pcl::Normal> normals;
  estimator.compute(normals);
  this->UpdateProgress(0.9);
  if (normals.size() != static_cast<size_t>(n))
  {
    vtkErrorMacro(<< "PCL returned " << normals.size() << " normals for " << n << " points");
    return 0;
  }

  auto out = vtkSmartPointer<vtkFloatArray>::New();
  out->SetName("Normals");
  out->SetNumberOfComponents(3);
  out->SetNumberOfTuples(n);
  auto curvature = vtkSmartPointer<vtkFloatArray>::New();
  curvature->SetName("Curvature");
  curvature->SetNumberOfTuples(n);
  float* o = out->GetPointer(0);
  float* c = curvature->GetPointer(0);
  for (vtkIdType i = 0; i < n; ++i)
  {
    const pcl::Normal& nm = normals[i];
    if (std::isfinite(nm.normal_x) && std::isfinite(nm.normal_y) && std::isfinite(nm.normal_z))
    {
      o[3 * i] = nm.normal_x;
      o[3 * i + 1] = nm.normal_y;
      o[3 * i + 2] = nm.normal_z;
      c[i] = nm.curvature;
    }
    else
    {
      o[3 * i] = o[3 * i + 1] = o[3 * i + 2] = 0;
      c[i] = 0;
      ++this->NumberOfInvalidNormals;
    }
  }
  if (this->NumberOfInvalidNormals)
  {
    vtkWarningMacro(<< this->NumberOfInvalidNormals << " of " << n
                    << " points had too few neighbours for a normal and got (0, 0, 0)"
                    << (this->Radius > 0 ? "; a larger Radius gives them more" : ""));
  }
  output->GetPointData()->SetNormals(out);
  output->GetPointData()->AddArray(curvature);
  return 1;
}

//------------------------------------------------------------------------------
void vtkParticleNormals::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfNeighbors: " << this->NumberOfNeighbors << "\n";
  os << indent << "Radius: " << this->Radius << "\n";
  os << indent << "ViewPoint: " << this->ViewPoint[0] << " " << this->ViewPoint[1] << " "
     << this->ViewPoint[2] << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "NumberOfInvalidNormals: " << this->NumberOfInvalidNormals << "\n";
}
