#include "vtkOctreeRenderSettings.h"

#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkOctreeVolumeMapper.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cstring>

//------------------------------------------------------------------------------
void vtkOctreeRenderSettings::SetCamera(
  vtkCamera* camera, double aspect, vtkMatrix4x4* volumeMatrix, octoray::RenderSettings& settings)
{
  vtkNew<vtkMatrix4x4> ndcFromData;
  vtkMatrix4x4::Multiply4x4(camera->GetCompositeProjectionTransformMatrix(aspect, -1, 1), volumeMatrix, ndcFromData);
  vtkNew<vtkMatrix4x4> dataFromNdc;
  vtkMatrix4x4::Invert(ndcFromData, dataFromNdc);
  std::copy(dataFromNdc->GetData(), dataFromNdc->GetData() + 16, settings.inverseViewProjection);
}

//------------------------------------------------------------------------------
octoray::BlendMode vtkOctreeRenderSettings::Blend(int vtkBlendMode, std::string& approximation)
{
  approximation.clear();
  switch (vtkBlendMode)
  {
    case vtkVolumeMapper::COMPOSITE_BLEND:
      return octoray::BlendMode::Composite;
    case vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND:
      return octoray::BlendMode::Maximum;
    case vtkVolumeMapper::MINIMUM_INTENSITY_BLEND:
      return octoray::BlendMode::Minimum;
    case vtkVolumeMapper::AVERAGE_INTENSITY_BLEND:
      return octoray::BlendMode::Average;
    case vtkVolumeMapper::ADDITIVE_BLEND:
      return octoray::BlendMode::Additive;
    case vtkOctreeVolumeMapper::SURFACE_BLEND:
      return octoray::BlendMode::Surface;
    case vtkVolumeMapper::ISOSURFACE_BLEND:
      approximation = "BlendMode ISOSURFACE_BLEND is drawn as SURFACE_BLEND: the first voxel a ray meets, not the "
                      "volume property's iso-values.";
      return octoray::BlendMode::Surface;
    case vtkVolumeMapper::SLICE_BLEND:
      approximation = "BlendMode SLICE_BLEND is drawn as SURFACE_BLEND: the first voxel a ray meets, not the "
                      "volume property's slice function.";
      return octoray::BlendMode::Surface;
    default:
      approximation = "BlendMode " + std::to_string(vtkBlendMode) +
        " is not one of VTK's; it is drawn as SURFACE_BLEND, the first voxel a ray meets.";
      return octoray::BlendMode::Surface;
  }
}

//------------------------------------------------------------------------------
void vtkOctreeRenderSettings::SetShading(
  vtkVolumeProperty* property, double depthCue, octoray::RenderSettings& settings)
{
  settings.shade = property->GetShade(0)
    ? octoray::ShadeMode::Phong
    : (depthCue > 0.0 ? octoray::ShadeMode::DepthCue : octoray::ShadeMode::Flat);
  settings.ambient = static_cast<float>(property->GetAmbient(0));
  settings.diffuse = static_cast<float>(property->GetDiffuse(0));
  settings.specular = static_cast<float>(property->GetSpecular(0));
  settings.specularPower = static_cast<float>(property->GetSpecularPower(0));
  settings.depthCue = static_cast<float>(depthCue);
  settings.opacityUnitDistance = static_cast<float>(property->GetScalarOpacityUnitDistance(0));
}

//------------------------------------------------------------------------------
// Whether `f` is 1 wherever it is read: every point 1, and outside its
// range the end points' values (clamping on).
static bool IsOneEverywhere(vtkPiecewiseFunction* f)
{
  if (f->GetSize() == 0 || !f->GetClamping())
  {
    return false;
  }
  for (int i = 0; i < f->GetSize(); ++i)
  {
    double node[4];
    f->GetNodeValue(i, node);
    if (node[1] != 1.0)
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
std::string vtkOctreeRenderSettings::UnappliedProperty(vtkVolumeProperty* property)
{
  if (property->GetTransferFunctionMode() == vtkVolumeProperty::TF_2D)
  {
    return "The volume property's 2D transfer function (TransferFunctionMode TF_2D) is not applied; the octree is "
           "drawn through its colour function and scalar opacity.";
  }
  // As VTK's GPU ray caster decides whether to apply it, but for a function
  // of 1 everywhere, which changes nothing: the default that
  // GetGradientOpacity makes, and so what DeepCopy of any property gives
  // (ParaView's CT Preset copies its property).
  if (property->HasGradientOpacity(0) && !property->GetDisableGradientOpacity(0) &&
    !IsOneEverywhere(property->GetGradientOpacity(0)))
  {
    return "The volume property's gradient opacity is not applied; the octree's opacity is the scalar opacity's "
           "alone (DisableGradientOpacityOn turns it off, and this warning with it).";
  }
  return "";
}

//------------------------------------------------------------------------------
int vtkOctreeRenderSettings::SetLights(
  vtkLightCollection* lights, vtkMatrix4x4* volumeMatrix, octoray::RenderSettings& settings)
{
  vtkNew<vtkMatrix4x4> dataFromWorld;
  vtkMatrix4x4::Invert(volumeMatrix, dataFromWorld);
  settings.lights.clear();
  int on = 0;
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  while (vtkLight* light = lights->GetNextLight(it))
  {
    if (!light->GetSwitch() || ++on > octoray::kMaxLights)
    {
      continue;
    }
    double world[2][4], data[2][4];
    light->GetTransformedPosition(world[0]);
    light->GetTransformedFocalPoint(world[1]);
    octoray::Light l;
    for (int k = 0; k < 2; ++k)
    {
      world[k][3] = 1.0;
      dataFromWorld->MultiplyPoint(world[k], data[k]);
    }
    const bool positional = light->GetPositional();
    for (int a = 0; a < 3; ++a)
    {
      // A positional light where it is; a directional one towards it.
      l.position[a] = data[0][a] / data[0][3] - (positional ? 0.0 : data[1][a] / data[1][3]);
    }
    l.position[3] = positional ? 1.0 : 0.0;
    double c[3];
    light->GetDiffuseColor(c);
    std::copy(c, c + 3, l.color);
    l.intensity = static_cast<float>(light->GetIntensity());
    settings.lights.push_back(l);
  }
  if (on == 0)
  {
    // Every light off: VTK leaves ambient light only; without a light the
    // engine would add its own headlight.
    octoray::Light dark;
    dark.intensity = 0.0f;
    settings.lights.push_back(dark);
  }
  return std::max(0, on - octoray::kMaxLights);
}

//------------------------------------------------------------------------------
// A world plane in data coordinates: n . (p - o) >= 0 for the world point
// p = M q of the data point q is (L^T n) . (q - M^-1 o) >= 0, with L the
// linear part of the volume's matrix M.
static octoray::ClipPlane DataPlane(vtkPlane* plane, vtkMatrix4x4* volumeMatrix, vtkMatrix4x4* dataFromWorld)
{
  double origin[4] = { 0, 0, 0, 1 }, normal[3], dataOrigin[4];
  plane->GetOrigin(origin);
  plane->GetNormal(normal);
  dataFromWorld->MultiplyPoint(origin, dataOrigin);
  octoray::ClipPlane p;
  for (int a = 0; a < 3; ++a)
  {
    p.origin[a] = dataOrigin[a] / dataOrigin[3];
    p.normal[a] = 0.0;
    for (int k = 0; k < 3; ++k)
    {
      p.normal[a] += volumeMatrix->GetElement(k, a) * normal[k];
    }
  }
  return p;
}

//------------------------------------------------------------------------------
int vtkOctreeRenderSettings::SetClipPlanes(vtkPlaneCollection* planes, vtkMatrix4x4* volumeMatrix,
  const double* croppingBox, octoray::RenderSettings& settings)
{
  std::vector<octoray::ClipPlane> all;
  if (planes)
  {
    vtkNew<vtkMatrix4x4> dataFromWorld;
    vtkMatrix4x4::Invert(volumeMatrix, dataFromWorld);
    vtkCollectionSimpleIterator it;
    planes->InitTraversal(it);
    while (vtkPlane* plane = planes->GetNextPlane(it))
    {
      all.push_back(DataPlane(plane, volumeMatrix, dataFromWorld));
    }
  }
  for (int face = 0; croppingBox && face < 6; ++face)
  {
    // Face 2a is the box's low side on axis a, kept above it; 2a + 1 its
    // high side, kept below.
    octoray::ClipPlane p;
    p.normal[0] = p.normal[1] = p.normal[2] = 0.0;
    p.origin[face / 2] = croppingBox[face];
    p.normal[face / 2] = face % 2 == 0 ? 1.0 : -1.0;
    all.push_back(p);
  }
  const std::size_t kept = std::min(all.size(), static_cast<std::size_t>(octoray::kMaxClipPlanes));
  settings.clipPlanes.assign(all.begin(), all.begin() + kept);
  return static_cast<int>(all.size() - kept);
}

//------------------------------------------------------------------------------
void vtkOctreeRenderSettings::SetTransfer(
  vtkVolumeProperty* property, const double scalarRange[2], octoray::RenderSettings& settings)
{
  double range[2] = { scalarRange[0], scalarRange[1] };
  if (!(range[1] > range[0]))
  {
    range[0] -= 0.5;
    range[1] += 0.5;
  }
  settings.transfer.range[0] = static_cast<float>(range[0]);
  settings.transfer.range[1] = static_cast<float>(range[1]);
  const int n = 1024; // entries: finer than any 8-bit colour step over the range
  std::vector<double> rgb(3 * n), alpha(n);
  if (property->GetColorChannels(0) == 1)
  {
    std::vector<double> grey(n);
    property->GetGrayTransferFunction(0)->GetTable(range[0], range[1], n, grey.data());
    for (int i = 0; i < n; ++i)
    {
      std::fill_n(&rgb[3 * i], 3, grey[i]);
    }
  }
  else
  {
    property->GetRGBTransferFunction(0)->GetTable(range[0], range[1], n, rgb.data());
  }
  property->GetScalarOpacity(0)->GetTable(range[0], range[1], n, alpha.data());
  settings.transfer.table.resize(n);
  for (int i = 0; i < n; ++i)
  {
    settings.transfer.table[i] = octoray::Rgba{ static_cast<float>(rgb[3 * i]),
      static_cast<float>(rgb[3 * i + 1]), static_cast<float>(rgb[3 * i + 2]), static_cast<float>(alpha[i]) };
  }
}

//------------------------------------------------------------------------------
std::vector<float> vtkOctreeRenderSettings::SampleDepth(
  const std::vector<float>& depth, int width, int height, int step, int tracedWidth, int tracedHeight)
{
  if (step == 1)
  {
    return depth;
  }
  std::vector<float> sampled(static_cast<std::size_t>(tracedWidth) * tracedHeight);
  for (int y = 0; y < tracedHeight; ++y)
  {
    const int sy = std::min(height - 1, y * step + step / 2);
    for (int x = 0; x < tracedWidth; ++x)
    {
      const int sx = std::min(width - 1, x * step + step / 2);
      sampled[static_cast<std::size_t>(y) * tracedWidth + x] = depth[static_cast<std::size_t>(sy) * width + sx];
    }
  }
  return sampled;
}

//------------------------------------------------------------------------------
vtkOctreeRenderSettings::TraceKey vtkOctreeRenderSettings::TraceKey::Of(const octoray::RenderSettings& s,
  vtkMTimeType mapperMTime, vtkMTimeType propertyMTime, unsigned long octreeVersion, std::uint64_t depthSignature)
{
  TraceKey k;
  std::copy(s.inverseViewProjection, s.inverseViewProjection + 16, k.InverseViewProjection);
  k.Width = s.width;
  k.Height = s.height;
  k.MapperMTime = mapperMTime;
  k.PropertyMTime = propertyMTime;
  k.OctreeVersion = octreeVersion;
  k.Lights = s.lights;
  k.DepthSignature = depthSignature;
  return k;
}

bool vtkOctreeRenderSettings::TraceKey::operator==(const TraceKey& o) const
{
  const auto sameLight = [](const octoray::Light& a, const octoray::Light& b) {
    return std::equal(a.position, a.position + 4, b.position) && std::equal(a.color, a.color + 3, b.color) &&
      a.intensity == b.intensity;
  };
  return std::equal(this->InverseViewProjection, this->InverseViewProjection + 16, o.InverseViewProjection) &&
    this->Width == o.Width && this->Height == o.Height && this->MapperMTime == o.MapperMTime &&
    this->PropertyMTime == o.PropertyMTime && this->OctreeVersion == o.OctreeVersion &&
    std::equal(this->Lights.begin(), this->Lights.end(), o.Lights.begin(), o.Lights.end(), sameLight) &&
    this->DepthSignature == o.DepthSignature;
}
