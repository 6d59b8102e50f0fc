/**
 * @class   vtkOctreeVolumePresets
 * @brief   named colour and opacity transfer functions for CT data in
 *          Hounsfield units: bone, skin, muscle
 *
 * The presets are those VTK and 3D Slicer offer for CT: VTK's example
 * FixedPointVolumeRayCastMapperCT (its CT_Bone, CT_Skin and CT_Muscle blend
 * types) and the matching entries of 3D Slicer's volume-rendering presets
 * (Modules/Loadable/VolumeRendering/Resources/presets.xml: CT-Bone and
 * CT-Muscle have the same control points there, to more decimals; Slicer
 * has no skin preset). The control points (value, r, g, b, midpoint,
 * sharpness for the colour; value, opacity, midpoint, sharpness for the
 * scalar opacity) are:
 *
 * - "ct-bone": colour -3024 (0, 0, 0), -16 (0.73, 0.25, 0.30; midpoint 0.49,
 *   sharpness 0.61), 641 (0.90, 0.82, 0.56), 3071 (1, 1, 1); opacity
 *   -3024 0, -16 0 (0.49, 0.61), 641 0.72, 3071 0.71.
 * - "ct-skin": colour -3024 (0, 0, 0), -1000 (0.62, 0.36, 0.18), -500
 *   (0.88, 0.60, 0.29; midpoint 0.33, sharpness 0.45), 3071 (0.83, 0.66, 1);
 *   opacity -3024 0, -1000 0, -500 1 (0.33, 0.45), 3071 1.
 * - "ct-muscle": colour -3024 (0, 0, 0), -155 (0.55, 0.25, 0.15; 0.5, 0.92),
 *   217 (0.88, 0.60, 0.29; 0.33, 0.45), 420 (1, 0.94, 0.95), 3071
 *   (0.83, 0.66, 1); opacity -3024 0, -155 0 (0.5, 0.92), 217 0.68
 *   (0.33, 0.45), 420 0.83, 3071 0.80.
 *
 * Points without a midpoint and sharpness above have VTK's defaults (0.5,
 * 0). Every preset also sets shading on, ambient 0.1, diffuse 0.9, specular
 * 0.2, specular power 10 and linear interpolation. The scalar opacity unit
 * distance is left as it is: it depends on the data's voxel size.
 *
 * vtkOctreeVolumeMapper's surface mode draws the first voxel a ray meets,
 * whatever its opacity, so the octree should hold only the voxels the
 * preset makes visible. GetSurfaceThreshold() gives that value: the lowest
 * value at which the preset's opacity reaches half of its maximum, in steps
 * of 1 HU (ct-bone 306 HU, ct-skin -750 HU, ct-muscle 34 HU). Use it as the
 * mapper's ImageBackground for image input (or as the upper end of
 * vtkSliceStackReader's BackgroundRange for its particles).
 *
 * Names are matched without regard to case, and '_' matches '-'
 * ("CT_Bone" is "ct-bone"). An unknown name is an error that names the
 * known presets; the property is then left as it was.
 *
 * Python (`octoray.apply_preset`), `python3 -m octoray.render --preset` and
 * the ParaView "Octree Volume" representation's Preset all go through this
 * class.
 */
#ifndef vtkOctreeVolumePresets_h
#define vtkOctreeVolumePresets_h

#include "octorayRenderingVolumeModule.h" // for export macro
#include "vtkNew.h"                       // for vtkNew
#include "vtkObject.h"

#include <string> // for std::string

class vtkColorTransferFunction;
class vtkPiecewiseFunction;
class vtkStringArray;
class vtkVolumeProperty;

class OCTORAYRENDERINGVOLUME_EXPORT vtkOctreeVolumePresets : public vtkObject
{
public:
  static vtkOctreeVolumePresets* New();
  vtkTypeMacro(vtkOctreeVolumePresets, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The presets' names, in order ("ct-bone", "ct-skin", "ct-muscle").
   * GetName returns nullptr for an index out of range. GetNames fills an
   * array owned by this object. GetNamesAsString joins them with ", ".
   */
  static int GetNumberOfPresets();
  static const char* GetName(int index);
  vtkStringArray* GetNames();
  static std::string GetNamesAsString();
  ///@}

  /**
   * Whether `name` is a preset (without regard to case; '_' matches '-').
   */
  static bool HasPreset(const char* name);

  /**
   * One line on what the preset shows, or nullptr for an unknown name.
   */
  static const char* GetDescription(const char* name);

  ///@{
  /**
   * Replace the colour transfer function and scalar opacity of component 0
   * of `property` by the preset's (new function objects, so that functions
   * shared with other properties stay untouched), and set its shading as
   * the preset does. The second form fills the caller's two functions only
   * (all their points replaced). False, with an error naming the known
   * presets, for an unknown name or a null argument; nothing is changed
   * then.
   */
  bool Apply(const char* name, vtkVolumeProperty* property);
  bool Apply(const char* name, vtkColorTransferFunction* color, vtkPiecewiseFunction* opacity);
  ///@}

  /**
   * The value from which the preset makes voxels visible in the octree's
   * surface mode: the lowest value at which its scalar opacity reaches half
   * of its maximum. NaN for an unknown name.
   */
  static double GetSurfaceThreshold(const char* name);

  /**
   * The message of the last failed Apply ("" after a successful one).
   */
  const char* GetLastError() { return this->LastError.c_str(); }

protected:
  vtkOctreeVolumePresets();
  ~vtkOctreeVolumePresets() override;

private:
  vtkOctreeVolumePresets(const vtkOctreeVolumePresets&) = delete;
  void operator=(const vtkOctreeVolumePresets&) = delete;

  bool Fail(const std::string& message);

  vtkNew<vtkStringArray> Names;
  std::string LastError;
};

#endif
