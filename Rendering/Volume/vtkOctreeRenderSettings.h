/**
 * @class   vtkOctreeRenderSettings
 * @brief   a frame's octoray::RenderSettings from VTK's camera, volume,
 *          property and lights
 *
 * A private helper of vtkOctreeVolumeMapper (not wrapped, not installed).
 * Pure functions of VTK state, with no OpenGL, so that each mapping (the
 * ray matrix, blend and shade modes, lights in data coordinates, the
 * transfer table) is tested on its own. TraceKey is what a picture was
 * traced from: the mapper traces again only when it changes.
 */
#ifndef vtkOctreeRenderSettings_h
#define vtkOctreeRenderSettings_h

#include "vtkType.h" // for vtkMTimeType

#include <octoray/Render.h> // for octoray::RenderSettings

#include <cstdint> // for std::uint64_t
#include <string>  // for std::string
#include <vector>  // for std::vector

class vtkCamera;
class vtkLightCollection;
class vtkMatrix4x4;
class vtkPlaneCollection;
class vtkVolumeProperty;

class vtkOctreeRenderSettings
{
public:
  /**
   * The engine's ray matrix: the inverse of VTK's composite projection
   * (world -> NDC, row-major) times the volume's matrix (data -> world), so
   * that perspective, parallel projection, clipping range and tiled or
   * off-axis viewports agree with VTK by construction.
   */
  static void SetCamera(
    vtkCamera* camera, double aspect, vtkMatrix4x4* volumeMatrix, octoray::RenderSettings& settings);

  /**
   * VTK's blend mode as the engine's. Where the engine has none of its own
   * (ISOSURFACE_BLEND, SLICE_BLEND, a value VTK does not know), the nearest,
   * the first hit (SURFACE_BLEND), with what is drawn instead in
   * `approximation`; "" otherwise.
   */
  static octoray::BlendMode Blend(int vtkBlendMode, std::string& approximation);

  /**
   * Shade mode and Phong coefficients of component 0 of `property`: Phong
   * when it shades, else a depth cue when `depthCue` > 0, else flat.
   */
  static void SetShading(vtkVolumeProperty* property, double depthCue, octoray::RenderSettings& settings);

  /**
   * What of `property` the engine does not apply, as sentences to say once
   * (a gradient opacity that VTK's mappers would apply, 2D transfer
   * functions); "" where nothing.
   */
  static std::string UnappliedProperty(vtkVolumeProperty* property);

  /**
   * The switched-on lights in data coordinates (camera lights and the
   * headlight carry the camera's transform). Every light off: one dark
   * light, as VTK then leaves ambient light only. Returns how many lights
   * past the engine's 8 were left out.
   */
  static int SetLights(
    vtkLightCollection* lights, vtkMatrix4x4* volumeMatrix, octoray::RenderSettings& settings);

  /**
   * The mapper's clipping planes (world coordinates, as VTK's volume
   * mappers take them; may be null) in data coordinates, then, where
   * `croppingBox` is given (xmin, xmax, ymin, ymax, zmin, zmax in data
   * coordinates: cropping to the sub-volume), the box's six faces. Returns
   * how many planes past the engine's kMaxClipPlanes were left out.
   */
  static int SetClipPlanes(vtkPlaneCollection* planes, vtkMatrix4x4* volumeMatrix, const double* croppingBox,
    octoray::RenderSettings& settings);

  /**
   * The colour (or grey) transfer function and scalar opacity of component
   * 0, sampled over `range` (widened when empty).
   */
  static void SetTransfer(vtkVolumeProperty* property, const double range[2], octoray::RenderSettings& settings);

  /**
   * The window depth at the centre of each traced pixel, when one ray
   * serves step x step pixels (ImageSampleDistance).
   */
  static std::vector<float> SampleDepth(
    const std::vector<float>& depth, int width, int height, int step, int tracedWidth, int tracedHeight);

  /**
   * What a picture was traced from.
   */
  struct TraceKey
  {
    double InverseViewProjection[16] = {};
    int Width = 0, Height = 0;
    vtkMTimeType MapperMTime = 0, PropertyMTime = 0;
    unsigned long OctreeVersion = 0; // bumped by every build and update
    std::vector<octoray::Light> Lights;
    std::uint64_t DepthSignature = 0; // of the opaque depth (octoray/DepthSignature.h)

    static TraceKey Of(const octoray::RenderSettings& settings, vtkMTimeType mapperMTime,
      vtkMTimeType propertyMTime, unsigned long octreeVersion, std::uint64_t depthSignature);
    bool operator==(const TraceKey& o) const;
    bool operator!=(const TraceKey& o) const { return !(*this == o); }
  };
};

#endif
// VTK-HeaderTest-Exclude: vtkOctreeRenderSettings.h
