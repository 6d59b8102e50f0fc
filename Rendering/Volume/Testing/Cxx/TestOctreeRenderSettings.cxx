// The mapper's render settings from VTK state (vtkOctreeRenderSettings),
// without OpenGL: each mapping against what VTK's own objects say.
#include "octorayMapperTesting.h"

#include "vtkColorTransferFunction.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMatrix4x4.h"
#include "vtkOctreeRenderSettings.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkTransform.h"

#include <string>
#include <utility>

using namespace octoray_test;

namespace
{
bool Near(double a, double b, double tolerance = 1e-9)
{
  return std::fabs(a - b) <= tolerance * std::max(1.0, std::fabs(b));
}

// `m` (row-major 4x4) applied to the homogeneous point `p`, divided by w.
void Apply(const double m[16], const double p[4], double out[3])
{
  double r[4];
  for (int i = 0; i < 4; ++i)
  {
    r[i] = m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + m[4 * i + 3] * p[3];
  }
  for (int i = 0; i < 3; ++i)
  {
    out[i] = r[i] / r[3];
  }
}

void TestCamera()
{
  // The centre of the near plane in NDC comes back as the point on the view
  // axis at the near clipping distance, in data coordinates: the volume is
  // moved by (1, 2, 3), so data = world - (1, 2, 3).
  vtkNew<vtkCamera> camera;
  SetCamera(camera);
  vtkNew<vtkMatrix4x4> volume;
  volume->SetElement(0, 3, 1.0);
  volume->SetElement(1, 3, 2.0);
  volume->SetElement(2, 3, 3.0);
  octoray::RenderSettings s;
  vtkOctreeRenderSettings::SetCamera(camera, 1.25, volume, s);
  double position[3], direction[3], range[2];
  camera->GetPosition(position);
  camera->GetDirectionOfProjection(direction);
  camera->GetClippingRange(range);
  const double nearCentre[4] = { 0, 0, -1, 1 }, farCentre[4] = { 0, 0, 1, 1 };
  double nearData[3], farData[3];
  Apply(s.inverseViewProjection, nearCentre, nearData);
  Apply(s.inverseViewProjection, farCentre, farData);
  const double shift[3] = { 1, 2, 3 };
  for (int a = 0; a < 3; ++a)
  {
    CHECK(Near(nearData[a], position[a] + range[0] * direction[a] - shift[a], 1e-9));
    CHECK(Near(farData[a], position[a] + range[1] * direction[a] - shift[a], 1e-9));
  }
}

void TestModes()
{
  // The engine's own modes, said nothing of; the others drawn as the first
  // hit, said as such.
  const std::pair<int, octoray::BlendMode> exact[] = { { vtkOctreeVolumeMapper::SURFACE_BLEND,
                                                         octoray::BlendMode::Surface },
    { vtkVolumeMapper::COMPOSITE_BLEND, octoray::BlendMode::Composite },
    { vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND, octoray::BlendMode::Maximum },
    { vtkVolumeMapper::MINIMUM_INTENSITY_BLEND, octoray::BlendMode::Minimum },
    { vtkVolumeMapper::AVERAGE_INTENSITY_BLEND, octoray::BlendMode::Average },
    { vtkVolumeMapper::ADDITIVE_BLEND, octoray::BlendMode::Additive } };
  std::string approximation = "left from before";
  for (const auto& mode : exact)
  {
    CHECK(vtkOctreeRenderSettings::Blend(mode.first, approximation) == mode.second);
    CHECK(approximation.empty());
  }
  const std::pair<int, const char*> nearest[] = { { vtkVolumeMapper::ISOSURFACE_BLEND,
                                                    "BlendMode ISOSURFACE_BLEND is drawn as SURFACE_BLEND: the first "
                                                    "voxel a ray meets, not the volume property's iso-values." },
    { vtkVolumeMapper::SLICE_BLEND,
      "BlendMode SLICE_BLEND is drawn as SURFACE_BLEND: the first voxel a ray meets, not the volume property's "
      "slice function." },
    { 77, "BlendMode 77 is not one of VTK's; it is drawn as SURFACE_BLEND, the first voxel a ray meets." } };
  for (const auto& mode : nearest)
  {
    CHECK(vtkOctreeRenderSettings::Blend(mode.first, approximation) == octoray::BlendMode::Surface);
    CHECK(approximation == mode.second);
  }

  vtkNew<vtkVolumeProperty> property;
  property->SetAmbient(0.25);
  property->SetDiffuse(0.5);
  property->SetSpecular(0.125);
  property->SetSpecularPower(30);
  property->SetScalarOpacityUnitDistance(0.5);
  octoray::RenderSettings s;
  property->ShadeOn();
  vtkOctreeRenderSettings::SetShading(property, 0.7, s);
  CHECK(s.shade == octoray::ShadeMode::Phong);
  CHECK(s.ambient == 0.25f && s.diffuse == 0.5f && s.specular == 0.125f && s.specularPower == 30.0f);
  CHECK(s.opacityUnitDistance == 0.5f);
  property->ShadeOff();
  vtkOctreeRenderSettings::SetShading(property, 0.7, s);
  CHECK(s.shade == octoray::ShadeMode::DepthCue && s.depthCue == 0.7f);
  vtkOctreeRenderSettings::SetShading(property, 0.0, s);
  CHECK(s.shade == octoray::ShadeMode::Flat);
}

void TestLights()
{
  vtkNew<vtkMatrix4x4> volume; // data = world - (0, 0, 10)
  volume->SetElement(2, 3, 10.0);
  vtkNew<vtkLightCollection> lights;
  vtkNew<vtkLight> positional, directional, off;
  positional->SetPositional(true);
  positional->SetPosition(1, 2, 13);
  positional->SetDiffuseColor(1.0, 0.5, 0.25);
  positional->SetIntensity(0.75);
  directional->SetPosition(0, 5, 0);
  directional->SetFocalPoint(0, 1, 0);
  off->SwitchOff();
  lights->AddItem(positional);
  lights->AddItem(off);
  lights->AddItem(directional);
  octoray::RenderSettings s;
  CHECK(vtkOctreeRenderSettings::SetLights(lights, volume, s) == 0);
  CHECK(s.lights.size() == 2);
  const octoray::Light& p = s.lights[0];
  CHECK(p.position[3] == 1.0 && Near(p.position[0], 1) && Near(p.position[1], 2) && Near(p.position[2], 3));
  CHECK(p.color[0] == 1.0f && p.color[1] == 0.5f && p.color[2] == 0.25f && p.intensity == 0.75f);
  const octoray::Light& d = s.lights[1];
  CHECK(d.position[3] == 0.0 && Near(d.position[0], 0) && Near(d.position[1], 4) && Near(d.position[2], 0));

  // More than the engine's 8: the rest are counted, not drawn.
  for (int i = 0; i < 9; ++i)
  {
    vtkNew<vtkLight> more;
    lights->AddItem(more);
  }
  CHECK(vtkOctreeRenderSettings::SetLights(lights, volume, s) == 3);
  CHECK(s.lights.size() == 8);
  // Every light off: one dark light (ambient only), not the engine's headlight.
  vtkNew<vtkLightCollection> dark;
  dark->AddItem(off);
  vtkOctreeRenderSettings::SetLights(dark, volume, s);
  CHECK(s.lights.size() == 1 && s.lights[0].intensity == 0.0f);
}

// Which side of an engine plane a data point lies on: + kept, - removed.
double Side(const octoray::ClipPlane& p, const double q[3])
{
  return p.normal[0] * (q[0] - p.origin[0]) + p.normal[1] * (q[1] - p.origin[1]) + p.normal[2] * (q[2] - p.origin[2]);
}

void TestClipPlanes()
{
  // A world plane through the volume turned, stretched and moved: each data
  // point is kept by the data plane exactly where its world point is kept
  // by the world plane.
  vtkNew<vtkTransform> turn;
  turn->Translate(0.5, -1, 2);
  turn->RotateWXYZ(35, 1, 2, 0.5);
  turn->Scale(2, 0.5, 1.5);
  vtkNew<vtkPlane> plane;
  plane->SetOrigin(0.3, 0.2, 1.9);
  plane->SetNormal(0.4, -1, 0.7);
  vtkNew<vtkPlaneCollection> planes;
  planes->AddItem(plane);
  octoray::RenderSettings s;
  CHECK(vtkOctreeRenderSettings::SetClipPlanes(planes, turn->GetMatrix(), nullptr, s) == 0);
  CHECK(s.clipPlanes.size() == 1);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2, 2);
  int kept = 0;
  for (int i = 0; i < 200; ++i)
  {
    const double q[3] = { u(rng), u(rng), u(rng) };
    double world[3];
    turn->TransformPoint(q, world);
    const double worldSide = plane->EvaluateFunction(world), dataSide = Side(s.clipPlanes[0], q);
    CHECK((worldSide >= 0) == (dataSide >= 0) || std::fabs(worldSide) < 1e-9);
    kept += worldSide >= 0;
  }
  CHECK(kept > 40 && kept < 160);

  // Cropping to a sub-volume: six faces in data coordinates, after the
  // planes; past twelve, the rest is counted, not kept.
  const double box[6] = { -1, 1, -2, 2, -3, 3 };
  CHECK(vtkOctreeRenderSettings::SetClipPlanes(nullptr, turn->GetMatrix(), box, s) == 0);
  CHECK(s.clipPlanes.size() == 6);
  const double inside[3] = { 0.9, -1.9, 2.9 }, outside[3] = { 0, 0, -3.1 };
  bool keepsInside = true, keepsOutside = true;
  for (const octoray::ClipPlane& p : s.clipPlanes)
  {
    keepsInside = keepsInside && Side(p, inside) >= 0;
    keepsOutside = keepsOutside && Side(p, outside) >= 0;
  }
  CHECK(keepsInside && !keepsOutside);
  for (int i = 0; i < 8; ++i)
  {
    planes->AddItem(plane);
  }
  CHECK(vtkOctreeRenderSettings::SetClipPlanes(planes, turn->GetMatrix(), box, s) == 3);
  CHECK(s.clipPlanes.size() == octoray::kMaxClipPlanes);
}

void TestTransfer()
{
  vtkNew<vtkVolumeProperty> property;
  vtkNew<vtkColorTransferFunction> colour;
  colour->AddRGBPoint(10.0, 1.0, 0.0, 0.0);
  colour->AddRGBPoint(20.0, 0.0, 0.0, 1.0);
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(10.0, 0.0);
  opacity->AddPoint(20.0, 1.0);
  property->SetColor(colour);
  property->SetScalarOpacity(opacity);
  octoray::RenderSettings s;
  const double range[2] = { 10.0, 20.0 };
  vtkOctreeRenderSettings::SetTransfer(property, range, s);
  CHECK(s.transfer.range[0] == 10.0f && s.transfer.range[1] == 20.0f);
  CHECK(!s.transfer.table.empty());
  const octoray::Rgba first = s.transfer.table.front(), last = s.transfer.table.back();
  CHECK(first.r == 1.0f && first.b == 0.0f && first.a == 0.0f);
  CHECK(last.r == 0.0f && last.b == 1.0f && last.a == 1.0f);
  // A single value: a range around it, not an empty one.
  const double single[2] = { 5.0, 5.0 };
  vtkOctreeRenderSettings::SetTransfer(property, single, s);
  CHECK(s.transfer.range[0] < 5.0f && s.transfer.range[1] > 5.0f);
}

void TestDepthAndKey()
{
  // 4x2 depth, one ray per 2x2: the centre sample (x+1, y+1) of each block.
  const std::vector<float> depth = { 0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f };
  const std::vector<float> sampled = vtkOctreeRenderSettings::SampleDepth(depth, 4, 2, 2, 2, 1);
  CHECK(sampled.size() == 2 && sampled[0] == 0.6f && sampled[1] == 0.8f);
  CHECK(vtkOctreeRenderSettings::SampleDepth(depth, 4, 2, 1, 4, 2) == depth);

  octoray::RenderSettings s;
  s.width = 10;
  s.height = 20;
  s.lights.resize(1);
  using Key = vtkOctreeRenderSettings::TraceKey;
  const Key key = Key::Of(s, 1, 2, 3, 4);
  CHECK(key == Key::Of(s, 1, 2, 3, 4));
  CHECK(key != Key::Of(s, 9, 2, 3, 4));
  CHECK(key != Key::Of(s, 1, 9, 3, 4));
  CHECK(key != Key::Of(s, 1, 2, 9, 4));
  CHECK(key != Key::Of(s, 1, 2, 3, 9));
  octoray::RenderSettings t = s;
  t.inverseViewProjection[5] = 1e-12;
  CHECK(key != Key::Of(t, 1, 2, 3, 4));
  t = s;
  t.lights[0].intensity = 0.5f;
  CHECK(key != Key::Of(t, 1, 2, 3, 4));
  t = s;
  t.width = 11;
  CHECK(key != Key::Of(t, 1, 2, 3, 4));
}
}

int TestOctreeRenderSettings(int, char*[])
{
  TestCamera();
  TestModes();
  TestLights();
  TestClipPlanes();
  TestTransfer();
  TestDepthAndKey();
  return Result();
}
