#include "vtkOctreeVolumeMapperInternals.h"

#include "vtkCamera.h"
#include "vtkDataSet.h"
#include "vtkDualDepthPeelingPass.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseVectorKey.h"
#include "vtkMath.h"
#include "vtkOpenGLRenderPass.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkPropCollection.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"
#include "vtkVolumeMapper.h"
#include "vtkVolumeProperty.h"
#include "vtk_glew.h"

#include <octoray/DepthSignature.h>
#include <octoray/Engine.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <sstream>
#include <vector>

namespace
{
double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}

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
    case vtkOctreeBackend::Status::KeptCPU:
      vtkWarningWithObjectMacro(this->Self, << this->Backend.Message());
      return Step::Done;
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
// Whether VTK's dual depth peeling of volumes (vtkRenderer's
// UseDepthPeelingForVolumes, with translucent geometry in the scene; on in
// ParaView's views) is drawing the volume: the pass is among the render
// passes in the volume's keys.
static bool InVolumePeeling(vtkInformation* keys)
{
  vtkInformationObjectBaseVectorKey* passes = vtkOpenGLRenderPass::RenderPasses();
  for (int i = 0; keys && keys->Has(passes) && i < keys->Length(passes); ++i)
  {
    if (vtkDualDepthPeelingPass::SafeDownCast(keys->Get(passes, i)))
    {
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
// Dual depth peeling calls volume mappers inside its own framebuffer, once
// or more a frame, where VTK's GPU ray caster casts between the peeled
// layers through the pass's shader code; the octree's picture, drawn there,
// came out garbled. Here it is drawn once a frame, as without peeling, into
// the framebuffer that the pass composites its layers onto (the pass steps
// out to it the same way to read the opaque depth): over the opaque
// geometry, behind every translucent layer. Said once.
void vtkOctreeVolumeMapper::vtkInternals::RenderOutsidePeeling(
  vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* window, vtkDataSet* input)
{
  vtkInformation* keys = vol->GetPropertyKeys();
  if (!InVolumePeeling(keys))
  {
    this->RenderOctree(ren, vol, window, input);
    return;
  }
  this->WarnOnce("The renderer peels volumes with translucent geometry (UseDepthPeelingForVolumes; in ParaView, "
                 "the view's Depth Peeling for Volumes), which the octree cannot join: it is drawn over the opaque "
                 "geometry and behind every translucent layer. Turn volume peeling off to draw it in front of "
                 "translucent geometry behind it.");
  if (keys->GetMTime() == this->PeeledFrame)
  {
    return; // drawn in this frame's first peel
  }
  this->PeeledFrame = keys->GetMTime();
  vtkOpenGLState* state = window->GetState();
  GLint peelingFramebuffer = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &peelingFramebuffer);
  state->PopDrawFramebufferBinding();
  {
    int width = 0, height = 0, x0 = 0, y0 = 0;
    ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
    vtkOpenGLState::ScopedglViewport viewport(state);
    vtkOpenGLState::ScopedglScissor scissor(state);
    state->vtkglViewport(x0, y0, width, height);
    state->vtkglScissor(x0, y0, width, height);
    this->RenderOctree(ren, vol, window, input);
  }
  state->PushDrawFramebufferBinding();
  state->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<unsigned int>(peelingFramebuffer));
}

//------------------------------------------------------------------------------
// Builds, updates or keeps the octree.
vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::PrepareOctree(
  vtkDataSet* input, vtkVolumeProperty* property)
{
  const vtkOctreeInputHelper::Request request =
    vtkOctreeInputHelper::MakeRequest(input, this->Self, property, this->Backend.Generation());
  if (request.CellScalars)
  {
    this->WarnOnce("Cell scalars are not supported; the points are drawn without them.");
  }
  for (const std::string& notice : request.Notices)
  {
    this->WarnOncePerInput(input, notice);
  }
  if (!request.Problem.empty())
  {
    this->WarnOncePerInput(input, request.Problem);
    this->Input.Forget(); // the last octree does not describe this input
    return Step::Stop;
  }
  if (this->Input.FailedBefore(request))
  {
    return Step::Stop; // its error was said at the failed build
  }
  switch (this->Input.Compare(request))
  {
    case vtkOctreeInputHelper::Change::None:
      return Step::Done;
    case vtkOctreeInputHelper::Change::Positions:
      // Only the positions moved (a point set animated in place): updated
      // where the engine kept its points (KeepPointsForUpdates).
      return this->BuiltWithPoints ? this->Update(request) : this->Build(request);
    default:
      return this->Build(request);
  }
}

//------------------------------------------------------------------------------
vtkOctreeVolumeMapper::vtkInternals::Step vtkOctreeVolumeMapper::vtkInternals::Update(
  const vtkOctreeInputHelper::Request& request)
{
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

//------------------------------------------------------------------------------
// A warning about the settings or the renderer, once for the mapper, each
// different text: frames come many a second, and repeat what rarely changes.
// "" says nothing.
void vtkOctreeVolumeMapper::vtkInternals::WarnOnce(const std::string& message)
{
  if (!message.empty() && this->SettingsWarnings.insert(message).second)
  {
    vtkWarningWithObjectMacro(this->Self, << message);
  }
}

//------------------------------------------------------------------------------
// A warning about the input, said once for an input (as it is, by its
// MTime): every frame looks at the input again.
void vtkOctreeVolumeMapper::vtkInternals::WarnOncePerInput(vtkDataSet* input, const std::string& message)
{
  if (input->GetMTime() != this->InputWarningMTime)
  {
    this->InputWarnings.clear();
    this->InputWarningMTime = input->GetMTime();
  }
  if (this->InputWarnings.insert(message).second)
  {
    vtkWarningWithObjectMacro(this->Self, << message);
  }
}

//------------------------------------------------------------------------------
// An image none of whose voxels is above the background: why.
void vtkOctreeVolumeMapper::vtkInternals::WarnNothingToDraw(const vtkOctreeInputHelper::Request& request)
{
  std::ostringstream why;
  if (!request.Scalars)
  {
    why << "The image has no point scalars selected, so every voxel counts as 1, at or below the background "
        << request.ImageBackground << "; nothing to draw. Select a point array (SelectScalarArray; in "
        << "ParaView, the Coloring array).";
  }
  else
  {
    why << "Every voxel of the image is at or below the background " << request.ImageBackground
        << "; nothing to draw.";
  }
  this->WarnOncePerInput(request.Input, why.str());
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
    // Not again at every frame (a 256^3 image was scanned each time) until
    // the input or its settings change.
    this->WarnNothingToDraw(request);
    this->Input.RememberFailure(request);
    return Step::Stop;
  }
  self->UpdateProgress(0.5);
  octoray::BuildOptions options;
  options.depth = request.LeafDepth;
  options.keepPoints = self->KeepPointsForUpdates;
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
    this->BuiltWithPoints = options.keepPoints;
    this->Input.Remember(request);
    ++this->OctreeVersion;
    ++self->NumberOfBuilds;
    self->LastBuildSeconds = Now() - start;
  }
  else if (step == Step::Stop)
  {
    this->Input.RememberFailure(request);
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
  std::string blendApproximation;
  s.blend = vtkOctreeRenderSettings::Blend(self->BlendMode, blendApproximation);
  this->WarnOnce(blendApproximation);
  vtkOctreeRenderSettings::SetShading(property, self->DepthCue, s);
  this->WarnOnce(vtkOctreeRenderSettings::UnappliedProperty(property));
  s.shadows = self->Shadows;
  s.estimateNormals = self->EstimateNormals;
  s.maxBounces = self->MaximumBounces;
  s.lodPixels = static_cast<float>(self->LODPixelThreshold);
  const int ignoredLights = vtkOctreeRenderSettings::SetLights(ren->GetLights(), vol->GetMatrix(), s);
  if (ignoredLights > 0)
  {
    this->WarnOnce("The octree engine takes at most " + std::to_string(octoray::kMaxLights) + " lights; " +
      std::to_string(ignoredLights) + " more are ignored.");
  }
  this->SetClipPlanes(vol, s);
  // Transfer function on the scalars (unless the points carry colours).
  if (this->Input.HasScalar())
  {
    vtkOctreeRenderSettings::SetTransfer(property, this->Input.ScalarRange(), s);
  }
  return s;
}

//------------------------------------------------------------------------------
// The clipping planes and the cropping box; what the engine cannot take is
// said once.
void vtkOctreeVolumeMapper::vtkInternals::SetClipPlanes(vtkVolume* vol, octoray::RenderSettings& s)
{
  vtkOctreeVolumeMapper* self = this->Self;
  const int ignored =
    vtkOctreeRenderSettings::SetClipPlanes(self->GetClippingPlanes(), vol->GetMatrix(), this->CroppingBox(), s);
  if (ignored > 0)
  {
    this->WarnOnce("The octree engine takes at most " + std::to_string(octoray::kMaxClipPlanes) +
      " clipping planes, a cropping box's six faces among them; " + std::to_string(ignored) + " more are ignored.");
  }
}

//------------------------------------------------------------------------------
// The box to crop to, where the mapper crops to the sub-volume. VTK's other
// cropping regions (fence, cross and their inverses) are not convex; they
// are said once, and the volume is drawn uncropped. Planes that are not
// finite are this frame's CroppingProblem (Drawable).
const double* vtkOctreeVolumeMapper::vtkInternals::CroppingBox()
{
  vtkOctreeVolumeMapper* self = this->Self;
  this->CroppingProblem.clear();
  if (!self->GetCropping())
  {
    return nullptr;
  }
  const double* planes = self->GetCroppingRegionPlanes();
  if (!std::all_of(planes, planes + 6, [](double v) { return std::isfinite(v); }))
  {
    std::ostringstream text;
    text << "CroppingRegionPlanes (" << planes[0];
    for (int i = 1; i < 6; ++i)
    {
      text << ", " << planes[i];
    }
    text << "): each must be finite; nothing is drawn.";
    this->CroppingProblem = text.str();
    return nullptr;
  }
  if (self->GetCroppingRegionFlags() == VTK_CROP_SUBVOLUME)
  {
    return planes;
  }
  std::ostringstream flags;
  flags << "0x" << std::hex << self->GetCroppingRegionFlags();
  this->WarnOnce("The octree engine crops to the sub-volume only (SetCroppingRegionFlagsToSubVolume); with "
                 "CroppingRegionFlags " + flags.str() + " the volume is drawn uncropped.");
  return nullptr;
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
  if (!this->Drawable(s))
  {
    return Step::Stop;
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
// Settings no frame can be drawn with (octoray::CheckSettings: a NaN in the
// volume property, which VTK's clamped setters let through; a cropping box
// that is not finite): an error said once while they last, and no trace. Checked here, not left to the trace,
// whose failure would drop the octree (vtkInternals::Report).
bool vtkOctreeVolumeMapper::vtkInternals::Drawable(const octoray::RenderSettings& s)
{
  std::string problem = this->CroppingProblem;
  try
  {
    if (problem.empty())
    {
      octoray::CheckSettings(s);
    }
  }
  catch (const std::exception& e)
  {
    problem = e.what();
  }
  if (problem.empty())
  {
    this->SettingsProblem.clear();
    return true;
  }
  if (this->SettingsProblem != problem)
  {
    this->SettingsProblem = problem;
    vtkErrorWithObjectMacro(this->Self, << problem);
  }
  return false;
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
  self->LastNormalEstimateSeconds = stats.normalSeconds;
  this->Transfer = s.copyToHost ? TRANSFER_HOST : TRANSFER_DEVICE;
  return Step::Done;
}

