#include "vtkOctreeVolumeMapper.h"
#include "vtkOctreeVolumeMapperInternals.h"

#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkCompositeDataSet.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkRectilinearGrid.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"
#include "vtkUnsignedCharArray.h"

#include <octoray/Engine.h>
#include <octoray/RootCube.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace
{
double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}

//------------------------------------------------------------------------------
vtkObjectFactoryNewMacro(vtkOctreeVolumeMapper);

//------------------------------------------------------------------------------
vtkOctreeVolumeMapper::vtkOctreeVolumeMapper()
  : Internals(new vtkInternals(this))
{
  // Point clouds are surfaces more often than clouds of density: first hit.
  this->BlendMode = SURFACE_BLEND;
  this->SetReflectivityArrayName(vtkOctreeInputHelper::DefaultReflectivityArrayName);
  this->SetRefractionArrayName(vtkOctreeInputHelper::DefaultRefractionArrayName);
}

//------------------------------------------------------------------------------
vtkOctreeVolumeMapper::~vtkOctreeVolumeMapper()
{
  this->SetReflectivityArrayName(nullptr);
  this->SetRefractionArrayName(nullptr);
  delete this->Internals;
}

//------------------------------------------------------------------------------
bool vtkOctreeVolumeMapper::IsCudaAvailable()
{
  return octoray::CudaAvailable(nullptr);
}

//------------------------------------------------------------------------------
int vtkOctreeVolumeMapper::GetLastUsedBackend()
{
  return this->Internals->Input.HasOctree() ? this->Internals->Backend.Kind() : -1;
}

const char* vtkOctreeVolumeMapper::GetLastUsedBackendName()
{
  switch (this->GetLastUsedBackend())
  {
    case BACKEND_CUDA:
      return "CUDA";
    case BACKEND_CPU:
      return "CPU";
    default:
      return "none";
  }
}

const char* vtkOctreeVolumeMapper::GetBackendDescription()
{
  return this->Internals->Backend.Description().c_str();
}

int vtkOctreeVolumeMapper::GetCudaDeviceInUse()
{
  return this->GetLastUsedBackend() == BACKEND_CUDA ? this->Internals->Backend.CudaDevice() : -1;
}

int vtkOctreeVolumeMapper::GetLastPictureTransfer()
{
  return this->Internals->Transfer;
}

const char* vtkOctreeVolumeMapper::GetLastPictureTransferName()
{
  switch (this->Internals->Transfer)
  {
    case TRANSFER_HOST:
      return "host";
    case TRANSFER_DEVICE:
      return "CUDA-OpenGL interop";
    default:
      return "none";
  }
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::SetInputData(vtkDataSet* input)
{
  if (input && !vtkPointSet::SafeDownCast(input) && !vtkImageData::SafeDownCast(input))
  {
    vtkErrorMacro("The input must be a vtkPointSet or a vtkImageData, not a " << input->GetClassName());
    return;
  }
  this->SetInputDataInternal(0, input);
}

void vtkOctreeVolumeMapper::SetInputData(vtkImageData* input)
{
  this->SetInputData(static_cast<vtkDataSet*>(input));
}

void vtkOctreeVolumeMapper::SetInputData(vtkRectilinearGrid* input)
{
  this->SetInputData(static_cast<vtkDataSet*>(input));
}

//------------------------------------------------------------------------------
// vtkSetClampMacro lets a NaN through (no comparison holds for it), and
// frames would trace with it: a NaN is refused by name, the value kept.
void vtkOctreeVolumeMapper::SetNumber(const char* name, double value, double low, double high, double& member)
{
  if (std::isnan(value))
  {
    vtkErrorMacro(<< name << " must be a number, not NaN; it stays " << member << ".");
    return;
  }
  value = std::clamp(value, low, high);
  if (member != value)
  {
    member = value;
    this->Modified();
  }
}

void vtkOctreeVolumeMapper::SetLODPixelThreshold(double pixels)
{
  this->SetNumber("LODPixelThreshold", pixels, 0.0, VTK_DOUBLE_MAX, this->LODPixelThreshold);
}

void vtkOctreeVolumeMapper::SetDepthCue(double fraction)
{
  this->SetNumber("DepthCue", fraction, 0.0, 1.0, this->DepthCue);
}

void vtkOctreeVolumeMapper::SetImageSampleDistance(double pixels)
{
  this->SetNumber("ImageSampleDistance", pixels, 1.0, 32.0, this->ImageSampleDistance);
}

void vtkOctreeVolumeMapper::SetImageBackground(double value)
{
  const double infinity = std::numeric_limits<double>::infinity();
  this->SetNumber("ImageBackground", value, -infinity, infinity, this->ImageBackground);
}

//------------------------------------------------------------------------------
int vtkOctreeVolumeMapper::FillInputPortInformation(int port, vtkInformation* info)
{
  (void)port;
  // vtkPointSet (points with attributes) and vtkImageData (voxels above the
  // background become points); vtkVolumeMapper itself asks for images only.
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

//------------------------------------------------------------------------------
// The input, brought up to date when it comes from a pipeline connection;
// null when there is none or it cannot be drawn.
vtkDataSet* vtkOctreeVolumeMapper::UpdatedInput()
{
  if (this->GetInputAlgorithm())
  {
    this->GetInputAlgorithm()->Update();
  }
  vtkDataSet* input = this->GetInput();
  if (!input && vtkCompositeDataSet::SafeDownCast(this->GetInputDataObject(0, 0)))
  {
    // Said once, not "No input." at every frame.
    this->Internals->WarnOnce(std::string("The input is composite data (a ") +
      this->GetInputDataObject(0, 0)->GetClassName() +
      "), which the mapper does not draw: merge its blocks into one point set first (vtkMergeBlocks, or "
      "vtkAppendDataSets); ParaView's Octree Volume representation does so itself.");
    return nullptr;
  }
  if (!input)
  {
    vtkErrorMacro("No input.");
    return nullptr;
  }
  if (!vtkPointSet::SafeDownCast(input) && !vtkImageData::SafeDownCast(input))
  {
    vtkErrorMacro("The input must be a vtkPointSet or a vtkImageData, not a " << input->GetClassName());
    return nullptr;
  }
  return input;
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  const double start = Now();
  this->InvokeEvent(vtkCommand::VolumeMapperRenderStartEvent, nullptr);
  auto* window = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  vtkDataSet* input = window ? this->UpdatedInput() : nullptr;
  if (!window)
  {
    vtkErrorMacro("vtkOctreeVolumeMapper draws only into OpenGL render windows.");
  }
  else if (input && input->GetNumberOfPoints() > 0) // nothing to draw is not an error
  {
    this->Internals->RenderOutsidePeeling(ren, vol, window, input);
  }

  // What the frame cost, for VTK's level-of-detail and interactive-rate
  // logic (vtkVolume adds it to its estimated render time); never zero, as
  // VTK's own mappers do.
  this->TimeToDraw = std::max(Now() - start, 1e-4);
  this->InvokeEvent(vtkCommand::VolumeMapperRenderEndEvent, nullptr);
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Internals->Compositor.ReleaseGraphicsResources(window);
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::GetLeafVoxels(vtkPolyData* output)
{
  output->Initialize();
  octoray::Engine* engine = this->Internals->Backend.Engine();
  if (!this->Internals->OctreeOf(this->GetInput()) || !engine)
  {
    return;
  }
  octoray::HostOctree tree;
  engine->CopyToHost(tree);
  const octoray::OctreeView view = tree.View();
  const int depth = tree.depth;
  const std::uint32_t begin = tree.levelBegin[depth], end = tree.levelBegin[depth + 1];
  const double leaf = tree.cube.size / static_cast<double>(1u << depth);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(end - begin);
  vtkNew<vtkUnsignedCharArray> colors;
  colors->SetName("Colors");
  colors->SetNumberOfComponents(4);
  colors->SetNumberOfTuples(end - begin);
  vtkNew<vtkFloatArray> scalars;
  scalars->SetName("Scalars");
  scalars->SetNumberOfTuples(tree.scalar.empty() ? 0 : end - begin);
  vtkNew<vtkCellArray> verts;
  for (std::uint32_t node = begin; node < end; ++node)
  {
    std::uint32_t x, y, z;
    octoray::DecodeMorton(tree.Key(node), x, y, z);
    const double p[3] = { tree.cube.origin[0] + (x + 0.5) * leaf, tree.cube.origin[1] + (y + 0.5) * leaf,
      tree.cube.origin[2] + (z + 0.5) * leaf };
    const vtkIdType id = node - begin;
    points->SetPoint(id, p);
    // 8-bit colours come back as they are stored (ToRgba8 undoes ToRgba).
    const octoray::Rgba8 c8 = octoray::ToRgba8(octoray::StoredColor(view, node));
    const unsigned char rgba[4] = { c8.r, c8.g, c8.b, c8.a };
    for (int k = 0; k < 4; ++k)
    {
      colors->SetTypedComponent(id, k, rgba[k]);
    }
    if (!tree.scalar.empty())
    {
      scalars->SetValue(id, tree.Scalar(node));
    }
    verts->InsertNextCell(1, &id);
  }
  output->SetPoints(points);
  output->SetVerts(verts);
  output->GetPointData()->SetScalars(colors);
  if (!tree.scalar.empty())
  {
    output->GetPointData()->AddArray(scalars);
  }
}

//------------------------------------------------------------------------------
int vtkOctreeVolumeMapper::GetOctreeDepth()
{
  return this->Internals->OctreeOf(this->GetInput()) ? this->Internals->BuiltDepth : 0;
}

//------------------------------------------------------------------------------
double vtkOctreeVolumeMapper::GetLeafSize()
{
  octoray::Engine* engine = this->Internals->Backend.Engine();
  if (!this->Internals->OctreeOf(this->GetInput()) || !engine)
  {
    return 0.0;
  }
  octoray::HostOctree tree;
  engine->CopyToHost(tree);
  return tree.cube.size / static_cast<double>(1u << tree.depth);
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::GetVoxelBounds(double bounds[6])
{
  vtkMath::UninitializeBounds(bounds);
  vtkDataSet* input = this->GetInput();
  const vtkIdType n = input ? input->GetNumberOfPoints() : 0;
  if (n == 0)
  {
    return;
  }
  double box[6];
  input->GetBounds(box);
  const bool image = vtkImageData::SafeDownCast(input) != nullptr;
  const vtkInternals& in = *this->Internals;
  octoray::RootCube cube;
  int depth = 0;
  if (in.Input.HasOctree() && in.BuiltFor == input && in.BuiltMTime == input->GetMTime())
  {
    cube = in.BuiltCube;
    depth = in.BuiltDepth;
  }
  else
  {
    // Not built yet: the cube the build will use and a depth not above the
    // one it will choose. Leaves of a shallower level of the same cube hold
    // the deeper ones, so the bounds below still hold the voxels.
    const bool fixed = vtkMath::AreBoundsInitialized(this->RootBounds);
    if (image && !fixed)
    {
      // The cube is fitted to the voxels above the background, unknown
      // until the build: the image's bounds widened by half their largest
      // extent hold any such cube.
      const double half = 0.5 * std::max({ box[1] - box[0], box[3] - box[2], box[5] - box[4] });
      for (int a = 0; a < 3; ++a)
      {
        bounds[2 * a] = box[2 * a] - half;
        bounds[2 * a + 1] = box[2 * a + 1] + half;
      }
      return;
    }
    const double* c = fixed ? this->RootBounds : box;
    const double lo[3] = { c[0], c[2], c[4] }, hi[3] = { c[1], c[3], c[5] };
    cube = octoray::RootCube::FromBounds(lo, hi);
    depth = this->LeafDepth;
    if (depth == 0)
    {
      depth = image
        ? 1
        : std::max(1, static_cast<int>(std::floor(std::log(std::max(0.5 * n, 1.0)) / std::log(8.0))));
    }
  }
  // The input's bounds out to the boundaries of the leaves that hold them.
  const double leaf = std::ldexp(cube.size, -depth);
  for (int a = 0; a < 3; ++a)
  {
    const double o = cube.origin[a];
    bounds[2 * a] = o + std::floor((box[2 * a] - o) / leaf) * leaf;
    bounds[2 * a + 1] = o + (std::floor((box[2 * a + 1] - o) / leaf) + 1.0) * leaf;
  }
}

//------------------------------------------------------------------------------
vtkIdType vtkOctreeVolumeMapper::GetNumberOfOctreePoints()
{
  octoray::Engine* engine = this->Internals->Backend.Engine();
  return (this->Internals->OctreeOf(this->GetInput()) && engine) ? static_cast<vtkIdType>(engine->PointCount()) : 0;
}

//------------------------------------------------------------------------------
void vtkOctreeVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  static const char* backends[] = { "Auto", "CUDA", "CPU" };
  os << indent << "RequestedBackend: " << backends[this->RequestedBackend] << "\n";
  os << indent << "LastUsedBackend: " << this->GetLastUsedBackendName() << "\n";
  os << indent << "BackendDescription: " << this->GetBackendDescription() << "\n";
  os << indent << "CudaDevice: " << this->CudaDevice << (this->CudaDevice < 0 ? " (by local rank)" : "") << "\n";
  os << indent << "UseCudaGLInterop: " << (this->UseCudaGLInterop ? "On" : "Off") << "\n";
  os << indent << "LastPictureTransfer: " << this->GetLastPictureTransferName() << "\n";
  os << indent << "LeafDepth: " << this->LeafDepth << (this->LeafDepth == 0 ? " (auto)" : "") << "\n";
  os << indent << "LODPixelThreshold: " << this->LODPixelThreshold << "\n";
  os << indent << "RootBounds: " << this->RootBounds[0] << " " << this->RootBounds[1] << " "
     << this->RootBounds[2] << " " << this->RootBounds[3] << " " << this->RootBounds[4] << " "
     << this->RootBounds[5] << "\n";
  os << indent << "Shadows: " << (this->Shadows ? "On" : "Off") << "\n";
  os << indent << "EstimateNormals: " << (this->EstimateNormals ? "On" : "Off") << "\n";
  os << indent << "MaximumBounces: " << this->MaximumBounces << "\n";
  os << indent << "DepthCue: " << this->DepthCue << "\n";
  os << indent << "ImageSampleDistance: " << this->ImageSampleDistance << "\n";
  os << indent << "ImageBackground: " << this->ImageBackground << "\n";
  os << indent << "FillBetweenSlices: " << (this->FillBetweenSlices ? "On" : "Off") << "\n";
  os << indent << "ImageGradientNormals: " << (this->ImageGradientNormals ? "On" : "Off") << "\n";
  os << indent << "ReflectivityArrayName: "
     << (this->ReflectivityArrayName ? this->ReflectivityArrayName : "(none)") << "\n";
  os << indent << "RefractionArrayName: "
     << (this->RefractionArrayName ? this->RefractionArrayName : "(none)") << "\n";
  os << indent << "CudaMemoryBudget: " << this->CudaMemoryBudget << "\n";
  os << indent << "KeepPointsForUpdates: " << (this->KeepPointsForUpdates ? "On" : "Off") << "\n";
  os << indent << "NumberOfBuilds: " << this->NumberOfBuilds << "\n";
  os << indent << "NumberOfUpdates: " << this->NumberOfUpdates << "\n";
  os << indent << "NumberOfTraces: " << this->NumberOfTraces << "\n";
  os << indent << "LastBuildSeconds: " << this->LastBuildSeconds << "\n";
  os << indent << "LastTraceSeconds: " << this->LastTraceSeconds << "\n";
  os << indent << "LastNormalEstimateSeconds: " << this->LastNormalEstimateSeconds << "\n";
  os << indent << "LastDepthReadSeconds: " << this->LastDepthReadSeconds << "\n";
  os << indent << "LastUploadSeconds: " << this->LastUploadSeconds << "\n";
  os << indent << "LastDrawSeconds: " << this->LastDrawSeconds << "\n";
}
