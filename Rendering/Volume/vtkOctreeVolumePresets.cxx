#include "vtkOctreeVolumePresets.h"

#include "vtkColorTransferFunction.h"
#include "vtkObjectFactory.h"
#include "vtkPiecewiseFunction.h"
#include "vtkStringArray.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <vector>

vtkStandardNewMacro(vtkOctreeVolumePresets);

namespace
{
struct ColorPoint
{
  double x, r, g, b, midpoint = 0.5, sharpness = 0.0;
};
struct OpacityPoint
{
  double x, y, midpoint = 0.5, sharpness = 0.0;
};
struct Preset
{
  const char* Name;
  const char* Description;
  std::vector<ColorPoint> Color;
  std::vector<OpacityPoint> Opacity;
  double Ambient, Diffuse, Specular, SpecularPower;
};

// The control points of VTK's FixedPointVolumeRayCastMapperCT example (its
// CT_Bone, CT_Skin and CT_Muscle), which 3D Slicer's presets.xml repeats for
// CT-Bone and CT-Muscle; values in Hounsfield units. The class
// documentation lists them, and the Python tests check them against their
// own copy.
const std::vector<Preset>& Presets()
{
  static const std::vector<Preset> presets = {
    { "ct-bone", "CT bone: soft tissue transparent, bone from about 300 HU opaque, red to ivory",
      { { -3024, 0, 0, 0 }, { -16, 0.73, 0.25, 0.30, 0.49, 0.61 }, { 641, 0.90, 0.82, 0.56 },
        { 3071, 1, 1, 1 } },
      { { -3024, 0 }, { -16, 0, 0.49, 0.61 }, { 641, 0.72 }, { 3071, 0.71 } }, 0.1, 0.9, 0.2, 10 },
    { "ct-skin", "CT skin: air transparent, everything denser than -500 HU opaque, skin-coloured",
      { { -3024, 0, 0, 0 }, { -1000, 0.62, 0.36, 0.18 }, { -500, 0.88, 0.60, 0.29, 0.33, 0.45 },
        { 3071, 0.83, 0.66, 1 } },
      { { -3024, 0 }, { -1000, 0 }, { -500, 1, 0.33, 0.45 }, { 3071, 1 } }, 0.1, 0.9, 0.2, 10 },
    { "ct-muscle", "CT muscle: fat and air transparent, muscle brown-orange, bone white",
      { { -3024, 0, 0, 0 }, { -155, 0.55, 0.25, 0.15, 0.5, 0.92 }, { 217, 0.88, 0.60, 0.29, 0.33, 0.45 },
        { 420, 1, 0.94, 0.95 }, { 3071, 0.83, 0.66, 1 } },
      { { -3024, 0 }, { -155, 0, 0.5, 0.92 }, { 217, 0.68, 0.33, 0.45 }, { 420, 0.83 }, { 3071, 0.80 } }, 0.1,
      0.9, 0.2, 10 },
  };
  return presets;
}

std::string Canonical(const char* name)
{
  std::string s = name ? name : "";
  for (char& c : s)
  {
    c = c == '_' ? '-' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return s;
}

const Preset* Find(const char* name)
{
  const std::string key = Canonical(name);
  for (const Preset& p : Presets())
  {
    if (key == p.Name)
    {
      return &p;
    }
  }
  return nullptr;
}

void Fill(const Preset& p, vtkColorTransferFunction* color, vtkPiecewiseFunction* opacity)
{
  color->RemoveAllPoints();
  color->SetColorSpaceToRGB();
  color->ClampingOn();
  for (const ColorPoint& c : p.Color)
  {
    color->AddRGBPoint(c.x, c.r, c.g, c.b, c.midpoint, c.sharpness);
  }
  opacity->RemoveAllPoints();
  opacity->ClampingOn();
  for (const OpacityPoint& o : p.Opacity)
  {
    opacity->AddPoint(o.x, o.y, o.midpoint, o.sharpness);
  }
}
}

//------------------------------------------------------------------------------
vtkOctreeVolumePresets::vtkOctreeVolumePresets() = default;
vtkOctreeVolumePresets::~vtkOctreeVolumePresets() = default;

//------------------------------------------------------------------------------
int vtkOctreeVolumePresets::GetNumberOfPresets()
{
  return static_cast<int>(Presets().size());
}

const char* vtkOctreeVolumePresets::GetName(int index)
{
  return index >= 0 && index < GetNumberOfPresets() ? Presets()[index].Name : nullptr;
}

vtkStringArray* vtkOctreeVolumePresets::GetNames()
{
  this->Names->SetNumberOfValues(GetNumberOfPresets());
  for (int i = 0; i < GetNumberOfPresets(); ++i)
  {
    this->Names->SetValue(i, GetName(i));
  }
  return this->Names;
}

std::string vtkOctreeVolumePresets::GetNamesAsString()
{
  std::string names;
  for (const Preset& p : Presets())
  {
    names += (names.empty() ? "" : ", ") + std::string(p.Name);
  }
  return names;
}

bool vtkOctreeVolumePresets::HasPreset(const char* name)
{
  return Find(name) != nullptr;
}

const char* vtkOctreeVolumePresets::GetDescription(const char* name)
{
  const Preset* p = Find(name);
  return p ? p->Description : nullptr;
}

//------------------------------------------------------------------------------
bool vtkOctreeVolumePresets::Fail(const std::string& message)
{
  this->LastError = message;
  vtkErrorMacro(<< message);
  return false;
}

bool vtkOctreeVolumePresets::Apply(const char* name, vtkVolumeProperty* property)
{
  const Preset* p = Find(name);
  if (!p)
  {
    return this->Fail(
      "Unknown volume preset '" + std::string(name ? name : "(null)") + "'; known presets: " + GetNamesAsString());
  }
  if (!property)
  {
    return this->Fail("No volume property to apply the preset '" + std::string(p->Name) + "' to");
  }
  vtkNew<vtkColorTransferFunction> color;
  vtkNew<vtkPiecewiseFunction> opacity;
  Fill(*p, color, opacity);
  property->SetColor(0, color);
  property->SetScalarOpacity(0, opacity);
  property->SetShade(0, 1);
  property->SetAmbient(0, p->Ambient);
  property->SetDiffuse(0, p->Diffuse);
  property->SetSpecular(0, p->Specular);
  property->SetSpecularPower(0, p->SpecularPower);
  property->SetInterpolationTypeToLinear();
  this->LastError.clear();
  return true;
}

bool vtkOctreeVolumePresets::Apply(const char* name, vtkColorTransferFunction* color, vtkPiecewiseFunction* opacity)
{
  const Preset* p = Find(name);
  if (!p)
  {
    return this->Fail(
      "Unknown volume preset '" + std::string(name ? name : "(null)") + "'; known presets: " + GetNamesAsString());
  }
  if (!color || !opacity)
  {
    return this->Fail("No colour or opacity function to apply the preset '" + std::string(p->Name) + "' to");
  }
  Fill(*p, color, opacity);
  this->LastError.clear();
  return true;
}

//------------------------------------------------------------------------------
double vtkOctreeVolumePresets::GetSurfaceThreshold(const char* name)
{
  const Preset* p = Find(name);
  if (!p)
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  vtkNew<vtkPiecewiseFunction> opacity;
  for (const OpacityPoint& o : p->Opacity)
  {
    opacity->AddPoint(o.x, o.y, o.midpoint, o.sharpness);
  }
  double maximum = 0.0;
  for (const OpacityPoint& o : p->Opacity)
  {
    maximum = std::max(maximum, o.y);
  }
  // In steps of 1 (a Hounsfield unit) from the first point: the first value
  // whose opacity reaches half the maximum.
  const double first = p->Opacity.front().x, last = p->Opacity.back().x;
  for (double x = first; x <= last; x += 1.0)
  {
    if (opacity->GetValue(x) >= 0.5 * maximum)
    {
      return x;
    }
  }
  return last;
}

//------------------------------------------------------------------------------
void vtkOctreeVolumePresets::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  for (const Preset& p : Presets())
  {
    os << indent << p.Name << ": " << p.Description << " (surface threshold " << GetSurfaceThreshold(p.Name)
       << ")\n";
  }
  os << indent << "LastError: " << this->LastError << "\n";
}
