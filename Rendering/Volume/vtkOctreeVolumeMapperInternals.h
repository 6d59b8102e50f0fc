/**
 * @class   vtkOctreeVolumeMapper::vtkInternals
 * @brief   the work of vtkOctreeVolumeMapper::Render(): the engine, the
 *          octree, the frame and the compositor
 *
 * A private part of vtkOctreeVolumeMapper (not wrapped, not installed). A
 * frame is three steps, each of which may end in a CUDA failure that hands
 * the engine to the CPU (vtkOctreeBackend): acquire the engine, build or
 * update the octree when the input changed (vtkOctreeInputHelper), trace
 * when anything that shapes the picture changed (vtkOctreeRenderSettings)
 * and put the picture into the compositor's textures (vtkOctreeCompositor),
 * which then draws it.
 */
#ifndef vtkOctreeVolumeMapperInternals_h
#define vtkOctreeVolumeMapperInternals_h

#include "vtkOctreeBackend.h"
#include "vtkOctreeCompositor.h"
#include "vtkOctreeInputHelper.h"
#include "vtkOctreeRenderSettings.h"
#include "vtkOctreeVolumeMapper.h"

#include <octoray/Render.h>
#include <octoray/RootCube.h>

#include <cstdint>
#include <set>
#include <string>

class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkVolume;
class vtkVolumeProperty;

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
  void RenderOutsidePeeling(vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* window, vtkDataSet* input);
  Step Acquire();
  Step PrepareOctree(vtkDataSet* input, vtkVolumeProperty* property);
  Step Build(const vtkOctreeInputHelper::Request& request);
  Step Update(const vtkOctreeInputHelper::Request& request);
  Step Trace(vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* window);
  octoray::RenderSettings FrameSettings(vtkRenderer* ren, vtkVolume* vol, int width, int height);
  void SetClipPlanes(vtkVolume* vol, octoray::RenderSettings& settings);
  const double* CroppingBox();
  Step OpaqueDepth(vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height,
    octoray::RenderSettings& settings, std::uint64_t& signature);
  bool UsesInterop() const;
  void InteropFailed(const std::string& why);
  Step Deliver(vtkOpenGLRenderWindow* window, octoray::RenderSettings& settings);
  template <typename Call>
  Step Run(const char* what, Call&& call);
  Step Report(vtkOctreeBackend::Status status);
  void WarnOncePerInput(vtkDataSet* input, const std::string& message);
  void WarnOnce(const std::string& message);
  bool Drawable(const octoray::RenderSettings& settings);
  // Whether the octree held is `input`'s (the getters describe no other).
  bool OctreeOf(vtkDataSet* input) const { return this->Input.HasOctree() && this->BuiltFor == input; }
  void WarnNothingToDraw(const vtkOctreeInputHelper::Request& request);

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
  bool BuiltWithPoints = false; // KeepPointsForUpdates at the last build: Update can run
  // The warnings said about the mapper's settings and the renderer's
  // (WarnOnce): each once, not at every frame.
  std::set<std::string> SettingsWarnings;
  std::string SettingsProblem; // the error of the last frame's settings, said once; "" where none
  std::string CroppingProblem; // this frame's cropping box that no frame can be drawn with; "" where none
  // The warnings said about the input as it is, by its MTime
  // (WarnOncePerInput): each once for an input, not at every frame.
  std::set<std::string> InputWarnings;
  vtkMTimeType InputWarningMTime = 0;
  bool InteropUnusable = false; // said once; the host path from then on
  // The frame of dual depth peeling the octree was last drawn in, by the
  // MTime of the volume's keys, to which the peeling pass adds itself at
  // the start of each frame (RenderOutsidePeeling).
  vtkMTimeType PeeledFrame = 0;

  // The last picture and what it was traced from.
  octoray::Image Image;
  vtkOctreeRenderSettings::TraceKey LastTrace;
  int Transfer = TRANSFER_NONE;
};

#endif
// VTK-HeaderTest-Exclude: vtkOctreeVolumeMapperInternals.h
