#include "vtkOctreeVolumeMapper.h"

#include "vtkCamera.h"
#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"
#include "vtkOctreeBackend.h"
#include "vtkOctreeCompositor.h"
#include "vtkOctreeInputHelper.h"
#include "vtkOctreeRenderSettings.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPropCollection.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include <octoray/DepthSignature.h>
#include <octoray/Engine.h>
#include <octoray/RootCube.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

namespace
{
double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}

//------------------------------------------------------------------------------
class vtkOctreeVolumeMapper::vtkInternals
{
public:
  // How one step of a frame ended. A CUDA failure switches the engine to
  // the CPU; the frame then starts again there, once.
  enum class Step
  {
    Done,
    Retry,
    Stop
  };

  explicit vtkInternals(vtkOctreeVolumeMapper* self)
    : Self(self)
  {
  }

  void RenderOctree(vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* window, vtkDataSet* input);
  Step Acquire();
  Step PrepareOctree(vtkDataSet* input, vtkVolumeProperty* property);
  Step Build(const vtkOctreeInputHelper::Request& request);
  Step Trace(vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* window);
  octoray::RenderSettings FrameSettings(vtkRenderer* ren, vtkVolume* vol, int width, int height);
  Step OpaqueDepth(vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height,
    octoray::RenderSettings& settings, std::uint64_t& signature);
  bool UsesInterop() const;
  void InteropFailed(const std::string& why);
  Step Deliver(vtkOpenGLRenderWindow* window, octoray::RenderSettings& settings);
  template <typename Call>
  Step Run(const char* what, Call&& call);
  Step Report(vtkOctreeBackend::Status status);

  vtkOctreeVolumeMapper* Self;
  vtkOctreeBackend Backend;
  vtkOctreeInputHelper Input;
  vtkOctreeCompositor Compositor;
  unsigned long OctreeVersion = 0; // bumped by every build and update
  // The leaf size of the last build and the input it was built for
  // (GetVoxelBounds).
  octoray::RootCube BuiltCube;
  int BuiltDepth = 0;
  vtkDataSet* BuiltFor = nullptr;
  vtkMTimeType BuiltMTime = 0;
  bool CellScalarsWarned = false;
  bool InteropUnusable = false; // said once; the host path from then on

  // The last picture and what it was traced from.
  octoray::Image Image;
  vtkOctreeRenderSettings::TraceKey LastTrace;
  int Transfer = TRANSFER_NONE;
};

//------------------------------------------------------------------------------
// Every engine call goes through here: a failure goes to the backend, which
// replaces a failed CUDA engine by a CPU one (Retry) or gives up (Stop).
template <typename Call>
vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::Run(const char* what, Call&& call)
{
  try
  {
    call();
    return Step::Done;
  }
  catch (const std::exception& e)
  {
    return this->Report(this->Backend.Failed(what, e.what()));
  }
}

vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::Report(
  vtkOctreeBackend::Status status)
{
  switch (status)
  {
    case vtkOctreeBackend::Status::Ready:
      return Step::Done;
    case vtkOctreeBackend::Status::SwitchedToCPU:
      vtkWarningWithObjectMacro(this->Self, << this->Backend.Message());
      this->Input.Forget();
      return Step::Retry;
    default:
      vtkErrorWithObjectMacro(this->Self, << this->Backend.Message());
      this->Input.Forget();
      return Step::Stop;
  }
}

//------------------------------------------------------------------------------
vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::Acquire()
{
  const Step step = this->Report(this->Backend.Acquire(this->Self->RequestedBackend, this->Self->CudaDevice));
  if (step == Step::Done && this->Backend.Kind() == BACKEND_CUDA && this->Self->CudaMemoryBudget > 0)
  {
    this->Backend.Engine()->SetMemoryBudget(static_cast<std::size_t>(this->Self->CudaMemoryBudget));
  }
  return step;
}

//------------------------------------------------------------------------------
// The frame: engine, octree, picture; a CUDA failure in any of them starts
// it again on the CPU.
void vtkOctreeVolumeMapper::vtkInternals::RenderOctree(
  vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* window, vtkDataSet* input)
{
  for (int attempt = 0; attempt < 2; ++attempt)
  {
    Step step = this->Acquire();
    if (step == Step::Done)
    {
      step = this->PrepareOctree(input, vol->GetProperty());
    }
    if (step == Step::Done)
    {
      step = this->Trace(ren, vol, window);
    }
    if (step == Step::Stop)
    {
      return;
    }
    if (step == Step::Done)
    {
      break;
    }
  }
  const double t0 = Now();
  if (!this->Compositor.Draw(window))
  {
    vtkErrorWithObjectMacro(this->Self, "Could not compile the composite shader.");
  }
  this->Self->LastDrawSeconds = Now() - t0;
}

//------------------------------------------------------------------------------
// Builds, updates or keeps the octree.
vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::PrepareOctree(
  vtkDataSet* input, vtkVolumeProperty* property)
{
  const vtkOctreeInputHelper::Request request =
    vtkOctreeInputHelper::MakeRequest(input, this->Self, property, this->Backend.Generation());
  if (request.CellScalars && !this->CellScalarsWarned)
  {
    this->CellScalarsWarned = true;
    vtkWarningWithObjectMacro(this->Self, "Cell scalars are not supported; the points are drawn without them.");
  }
  switch (this->Input.Compare(request))
  {
    case vtkOctreeInputHelper::Change::None:
      return Step::Done;
    case vtkOctreeInputHelper::Change::Positions:
    {
      // Only the positions moved (a point set animated in place).
      const double start = Now();
      const octoray::PositionsView moved = this->Input.Positions(request);
      const Step step = this->Run("update", [&] { this->Backend.Engine()->Update(moved); });
      if (step == Step::Done)
      {
        this->Input.Remember(request);
        ++this->OctreeVersion;
        ++this->Self->NumberOfUpdates;
        this->Self->LastBuildSeconds = Now() - start;
      }
      return step;
    }
    default:
      return this->Build(request);
  }
}

//------------------------------------------------------------------------------
vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::Build(
  const vtkOctreeInputHelper::Request& request)
{
  const double start = Now();
  vtkOctreeVolumeMapper* self = this->Self;
  self->UpdateProgress(0.0);
  this->Input.Forget();
  const octoray::PointCloudView view =
    this->Input.PointCloud(request, [self](double progress) { self->UpdateProgress(progress); });
  if (view.count == 0)
  {
    vtkWarningWithObjectMacro(self, "Every voxel of the image is at or below the background "
        << request.ImageBackground << "; nothing to draw.");
    return Step::Stop;
  }
  self->UpdateProgress(0.5);
  octoray::BuildOptions options;
  options.depth = request.LeafDepth;
  const bool rootBounds = vtkMath::AreBoundsInitialized(request.RootBounds.data());
  if (rootBounds)
  {
    // The caller's cube (e.g. global bounds over parallel ranks): the same
    // voxel grid on every rank.
    const double* b = request.RootBounds.data();
    const double lo[3] = { b[0], b[2], b[4] }, hi[3] = { b[1], b[3], b[5] };
    options.fixedCube = true;
    options.cube = octoray::RootCube::FromBounds(lo, hi);
  }
  // Points on a lattice (an image, the slice-stack reader's particles) with
  // the depth left automatic: leaves as large as the lattice's largest step
  // and aligned with it, so that the volume has no gap (octorayLattice.h),
  // in a cube around the caller's bounds where there are some (then the
  // same on every rank).
  octoray::lattice::Lattice lattice;
  double bounds[6];
  if (request.LeafDepth == 0 && this->Input.PointLattice(lattice, bounds))
  {
    if (rootBounds)
    {
      std::copy(request.RootBounds.begin(), request.RootBounds.end(), bounds);
    }
    const octoray::lattice::LeafGrid grid = octoray::lattice::ChooseLeafGrid(lattice, bounds, octoray::kMaxLevel);
    if (grid.Valid)
    {
      options.depth = grid.Depth;
      options.fixedCube = true;
      std::copy(grid.Origin, grid.Origin + 3, options.cube.origin);
      options.cube.size = grid.Size;
    }
  }
  octoray::BuildStats stats;
  const Step step = this->Run("build", [&] { stats = this->Backend.Engine()->Build(view, options); });
  if (step == Step::Done)
  {
    // The leaf grid, for GetVoxelBounds.
    this->BuiltCube = stats.cube;
    this->BuiltDepth = stats.depth;
    this->BuiltFor = request.Input;
    this->BuiltMTime = request.Input->GetMTime();
    this->Input.Remember(request);
    ++this->OctreeVersion;
    ++self->NumberOfBuilds;
    self->LastBuildSeconds = Now() - start;
  }
  self->UpdateProgress(1.0);
  return step;
}

//------------------------------------------------------------------------------
// What the frame asks of the engine, from the renderer, the volume and the
// mapper's settings.
octoray::RenderSettings vtkOctreeVolumeMapper::vtkInternals::FrameSettings(
  vtkRenderer* ren, vtkVolume* vol, int width, int height)
{
  vtkOctreeVolumeMapper* self = this->Self;
  vtkVolumeProperty* property = vol->GetProperty();
  octoray::RenderSettings s;
  const int step = std::max(1, static_cast<int>(std::lround(self->ImageSampleDistance)));
  s.width = (width + step - 1) / step;
  s.height = (height + step - 1) / step;
  vtkOctreeRenderSettings::SetCamera(ren->GetActiveCamera(), ren->GetTiledAspectRatio(), vol->GetMatrix(), s);
  s.blend = vtkOctreeRenderSettings::Blend(self->BlendMode);
  vtkOctreeRenderSettings::SetShading(property, self->DepthCue, s);
  s.shadows = self->Shadows;
  s.maxBounces = self->MaximumBounces;
  s.lodPixels = static_cast<float>(self->LODPixelThreshold);
  if (vtkOctreeRenderSettings::SetLights(ren->GetLights(), vol->GetMatrix(), s) > 0)
  {
    vtkWarningWithObjectMacro(self, "The octree engine takes at most 8 lights; the others are ignored.");
  }
  // Transfer function on the scalars (unless the points carry colours).
  if (this->Input.HasScalar())
  {
    vtkOctreeRenderSettings::SetTransfer(property, this->Input.ScalarRange(), s);
  }
  return s;
}

//------------------------------------------------------------------------------
// Whether anything may have written depth in the viewport before the
// volumes are drawn: another visible 3D prop with opaque geometry (actors,
// and other volumes, which this mapper draws with depth), or a depth buffer
// the renderer keeps from the layer below. When nothing can, the depth read
// (a round trip through OpenGL) is skipped and rays run to the far plane.
static bool MayHaveOpaqueDepth(vtkRenderer* ren, vtkVolume* vol)
{
  if (ren->GetPreserveDepthBuffer())
  {
    return true;
  }
  vtkCollectionSimpleIterator it;
  vtkPropCollection* props = ren->GetViewProps();
  props->InitTraversal(it);
  while (vtkProp* prop = props->GetNextProp(it))
  {
    if (prop != vol && prop->GetVisibility() && vtkProp3D::SafeDownCast(prop) && prop->HasOpaqueGeometry())
    {
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
// Traces the picture when anything that shapes it changed since the last one.
vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::Trace(
  vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* window)
{
  vtkOctreeVolumeMapper* self = this->Self;
  int width = 0, height = 0, x0 = 0, y0 = 0;
  ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  if (width <= 0 || height <= 0)
  {
    return Step::Stop;
  }
  octoray::RenderSettings s = this->FrameSettings(ren, vol, width, height);
  std::uint64_t depthSignature = 0;
  self->LastDepthReadSeconds = 0.0;
  if (MayHaveOpaqueDepth(ren, vol))
  {
    const Step step = this->OpaqueDepth(window, x0, y0, width, height, s, depthSignature);
    if (step != Step::Done)
    {
      return step;
    }
  }
  const vtkOctreeRenderSettings::TraceKey key = vtkOctreeRenderSettings::TraceKey::Of(
    s, self->GetMTime(), vol->GetProperty()->GetMTime(), this->OctreeVersion, depthSignature);
  if (key == this->LastTrace && this->Compositor.HasPicture())
  {
    return Step::Done;
  }
  const Step traced = this->Deliver(window, s);
  if (traced == Step::Done)
  {
    ++self->NumberOfTraces;
    this->LastTrace = key;
  }
  return traced;
}

//------------------------------------------------------------------------------
// The depth of what VTK drew in the viewport, where rays must stop, and its
// signature (what the last trace is compared by). On CUDA with interop it
// stays on the GPU (vtkOctreeCompositor::ReadDepthToDevice), where the trace
// reads it; otherwise it is read back to the host (and sampled at the traced
// pixels when one ray serves several).
vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::OpaqueDepth(
  vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height, octoray::RenderSettings& s,
  std::uint64_t& signature)
{
  vtkOctreeVolumeMapper* self = this->Self;
  const double t0 = Now();
  const int step = std::max(1, static_cast<int>(std::lround(self->ImageSampleDistance)));
  if (step == 1 && this->UsesInterop())
  {
    std::string why;
    s.deviceDepthBuffer =
      this->Compositor.ReadDepthToDevice(window, x0, y0, width, height, this->Backend.CudaDevice(), why);
    if (!s.deviceDepthBuffer)
    {
      this->InteropFailed(why);
    }
    else
    {
      const Step summed = this->Run("depth signature", [&] {
        signature = this->Backend.Engine()->DeviceDepthSignature(
          s.deviceDepthBuffer, static_cast<std::size_t>(width) * height);
      });
      self->LastDepthReadSeconds = Now() - t0;
      return summed;
    }
  }
  std::vector<float> depth;
  if (!this->Compositor.ReadDepth(window, x0, y0, width, height, depth))
  {
    vtkWarningWithObjectMacro(self, "Could not read the depth of the opaque geometry; the octree is drawn without it.");
  }
  s.depthBuffer = vtkOctreeRenderSettings::SampleDepth(depth, width, height, step, s.width, s.height);
  signature = octoray::DepthSignature(s.depthBuffer.data(), s.depthBuffer.size());
  self->LastDepthReadSeconds = Now() - t0;
  return Step::Done;
}

//------------------------------------------------------------------------------
bool vtkOctreeVolumeMapper::vtkInternals::UsesInterop() const
{
  return this->Backend.Kind() == BACKEND_CUDA && this->Self->UseCudaGLInterop && !this->InteropUnusable;
}

void vtkOctreeVolumeMapper::vtkInternals::InteropFailed(const std::string& why)
{
  vtkWarningWithObjectMacro(
    this->Self, "CUDA-OpenGL interop cannot serve this window (" << why << "); the picture goes through host memory");
  this->InteropUnusable = true;
}

//------------------------------------------------------------------------------
// Traces and puts the picture into the compositor's textures: on CUDA
// straight from device memory where interop serves this window, otherwise
// through host memory.
vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::Deliver(
  vtkOpenGLRenderWindow* window, octoray::RenderSettings& s)
{
  vtkOctreeVolumeMapper* self = this->Self;
  octoray::Engine* engine = this->Backend.Engine();
  s.copyToHost = !this->UsesInterop();
  octoray::RenderStats stats;
  Step step = this->Run("render", [&] { stats = engine->Render(s, this->Image); });
  if (step != Step::Done)
  {
    return step;
  }
  double t0 = Now();
  std::string why;
  if (!s.copyToHost && !this->Compositor.SetPictureFromDevice(window, engine->LastDeviceImage(), why))
  {
    this->InteropFailed(why);
    s.copyToHost = true;
    step = this->Run("render", [&] { stats = engine->Render(s, this->Image); });
    if (step != Step::Done)
    {
      return step;
    }
    t0 = Now();
  }
  if (s.copyToHost)
  {
    this->Compositor.SetPictureFromHost(window, this->Image);
  }
  self->LastUploadSeconds = Now() - t0;
  self->LastTraceSeconds = stats.seconds + stats.copySeconds;
  this->Transfer = s.copyToHost ? TRANSFER_HOST : TRANSFER_DEVICE;
  return Step::Done;
}

//------------------------------------------------------------------------------
vtkObjectFactoryNewMacro(vtkOctreeVolumeMapper);

//------------------------------------------------------------------------------
vtkOctreeVolumeMapper::vtkOctreeVolumeMapper()
  : Internals(new vtkInternals(this))
{
  // Point clouds are surfaces more often than clouds of density: first hit.
  this->BlendMode = SURFACE_BLEND;
  this->SetReflectivityArrayName("Reflectivity");
  this->SetRefractionArrayName("Refraction");
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
    this->Internals->RenderOctree(ren, vol, window, input);
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
  if (!this->Internals->Input.HasOctree() || !engine)
  {
    return;
  }
  octoray::HostOctree tree;
  engine->CopyToHost(tree);
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
    octoray::DecodeMorton(tree.key[node], x, y, z);
    const double p[3] = { tree.cube.origin[0] + (x + 0.5) * leaf, tree.cube.origin[1] + (y + 0.5) * leaf,
      tree.cube.origin[2] + (z + 0.5) * leaf };
    const vtkIdType id = node - begin;
    points->SetPoint(id, p);
    const octoray::Rgba c = tree.color.empty() ? octoray::Rgba{ 1, 1, 1, 1 } : tree.color[node];
    const float rgba[4] = { c.r, c.g, c.b, c.a };
    for (int k = 0; k < 4; ++k)
    {
      colors->SetTypedComponent(id, k, octoray::ChannelToByte(rgba[k]));
    }
    if (!tree.scalar.empty())
    {
      scalars->SetValue(id, tree.scalar[node]);
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
  return this->Internals->Input.HasOctree() ? this->Internals->BuiltDepth : 0;
}

//------------------------------------------------------------------------------
double vtkOctreeVolumeMapper::GetLeafSize()
{
  octoray::Engine* engine = this->Internals->Backend.Engine();
  if (!this->Internals->Input.HasOctree() || !engine)
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
  return (this->Internals->Input.HasOctree() && engine) ? static_cast<vtkIdType>(engine->PointCount()) : 0;
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
  os << indent << "MaximumBounces: " << this->MaximumBounces << "\n";
  os << indent << "DepthCue: " << this->DepthCue << "\n";
  os << indent << "ImageSampleDistance: " << this->ImageSampleDistance << "\n";
  os << indent << "ImageBackground: " << this->ImageBackground << "\n";
  os << indent << "FillBetweenSlices: " << this->FillBetweenSlices << "\n";
  os << indent << "ImageGradientNormals: " << (this->ImageGradientNormals ? "on" : "off") << "\n";
  os << indent << "ReflectivityArrayName: "
     << (this->ReflectivityArrayName ? this->ReflectivityArrayName : "(none)") << "\n";
  os << indent << "RefractionArrayName: "
     << (this->RefractionArrayName ? this->RefractionArrayName : "(none)") << "\n";
  os << indent << "CudaMemoryBudget: " << this->CudaMemoryBudget << "\n";
  os << indent << "NumberOfBuilds: " << this->NumberOfBuilds << "\n";
  os << indent << "NumberOfUpdates: " << this->NumberOfUpdates << "\n";
  os << indent << "NumberOfTraces: " << this->NumberOfTraces << "\n";
  os << indent << "LastBuildSeconds: " << this->LastBuildSeconds << "\n";
  os << indent << "LastTraceSeconds: " << this->LastTraceSeconds << "\n";
  os << indent << "LastDepthReadSeconds: " << this->LastDepthReadSeconds << "\n";
  os << indent << "LastUploadSeconds: " << this->LastUploadSeconds << "\n";
  os << indent << "LastDrawSeconds: " << this->LastDrawSeconds << "\n";
}
