// Per-pixel rendering, written once for both backends: primary rays from
// the inverse view-projection, surface shading (flat, depth cue, Phong,
// shadows, reflections) and the volume blend modes.
#pragma once

#include "Render.h"
#include "Traversal.h"

namespace octoray
{
struct UnitLight
{
  Vec3f position; // unit-cube position, or direction towards the light
  bool directional;
  Vec3f color;    // colour x intensity
};

// Everything a frame's rays share, in the unit cube; passed by value.
struct FrameConstants
{
  int width = 0, height = 0;
  double unitFromNdc[16];
  double ndcFromUnit[16];
  BlendMode blend = BlendMode::Surface;
  ShadeMode shade = ShadeMode::Flat;
  float ambient, diffuse, specular, specularPower, depthCue;
  float cueNear = 0, cueFar = 1; // distances from the near plane across which depth cue fades
  int lightCount = 0;            // 0: headlight
  UnitLight lights[kMaxLights];
  bool shadows = false;
  int maxBounces = 0;            // 0 when no node reflects
  float footprint0 = 0, footprintSlope = 0, lodPixels = 0;
  float opacityUnitDistance = 1.0f / 256;
  const Rgba* transfer = nullptr; // colour and opacity by scalar; null = node colours
  int transferSize = 0;
  float transferRange[2] = { 0, 1 };
  const float* depthBuffer = nullptr;
  int clipPlaneCount = 0;
  double clipPlanes[kMaxClipPlanes][4]; // a . u + d >= 0 is kept, u in the unit cube
};

// What a frame uses, fixed at compile time: each combination is its own
// instantiation of RenderPixel, so a frame without lights, shadows or
// secondary rays carries none of their code or registers (DispatchFeatures
// picks the instantiation per frame).
template <bool Volume, bool Lit, bool Shadows, bool Secondary>
struct Features
{
  static constexpr bool kVolume = Volume;       // a volume blend mode, not a surface
  static constexpr bool kLit = Lit;             // Phong shading
  static constexpr bool kShadows = Shadows;     // shadow rays towards the lights
  static constexpr bool kSecondary = Secondary; // mirror and refracted rays
};

// Calls fn(Features<...>()) with the frame's feature set.
template <typename Fn>
void DispatchFeatures(const FrameConstants& f, Fn&& fn);

OCTORAY_HD void Transform(const double m[16], const double in[4], double out[4])
{
  for (int r = 0; r < 4; ++r)
  {
    out[r] = m[4 * r] * in[0] + m[4 * r + 1] * in[1] + m[4 * r + 2] * in[2] + m[4 * r + 3] * in[3];
  }
}

OCTORAY_HD Vec3d Unproject(const double m[16], double x, double y, double z)
{
  const double ndc[4] = { x, y, z, 1.0 };
  double h[4];
  Transform(m, ndc, h);
  return Vec3d{ h[0] / h[3], h[1] / h[3], h[2] / h[3] };
}

// Window depth (OpenGL convention, [0,1]) of a unit-cube point.
OCTORAY_HD float WindowDepth(const FrameConstants& f, const Vec3d& p)
{
  const double in[4] = { p.x, p.y, p.z, 1.0 };
  double clip[4];
  Transform(f.ndcFromUnit, in, clip);
  return static_cast<float>(Clamp01(0.5 * clip[2] / clip[3] + 0.5));
}

// The centre of pixel (x, y) in normalised device coordinates, at depth z.
OCTORAY_HD Vec3d PixelNdc(const FrameConstants& f, int x, int y, double z)
{
  return Vec3d{ 2.0 * (x + 0.5) / f.width - 1.0, 2.0 * (y + 0.5) / f.height - 1.0, z };
}

// The line through the centre of pixel (x, y): its point on the near plane,
// its unit direction and its length to the far plane, in double. False
// for a degenerate projection.
OCTORAY_HD bool PixelLine(const FrameConstants& f, int x, int y, Vec3d& nearPoint, Vec3d& d, double& length)
{
  const Vec3d ndc = PixelNdc(f, x, y, -1.0);
  nearPoint = Unproject(f.unitFromNdc, ndc.x, ndc.y, -1.0);
  d = Unproject(f.unitFromNdc, ndc.x, ndc.y, 1.0) - nearPoint;
  length = Length(d);
  if (!(length > 0.0))
  {
    return false;
  }
  d /= length;
  return true;
}

// How far inside the kept side a clipped ray starts and ends (unit-cube
// lengths, d of unit length): a plane on a voxel face (a cropping box on the
// lattice) leaves the ray in float on either side of the face by a few
// ulps, and the voxel beyond it would be drawn for a touch of no length.
// A thousandth of a leaf at depth 10, a sixteenth at depth 16.
constexpr double kClipMargin = 1e-6;

// Narrows [t0, t1] of the line p + t d to the part that every clipping
// plane keeps (a half-space each, so what is kept of a line is one span),
// kClipMargin inside each plane. False when nothing is left.
OCTORAY_HD bool ClipLine(const FrameConstants& f, const Vec3d& p, const Vec3d& d, double& t0, double& t1)
{
  for (int i = 0; i < f.clipPlaneCount; ++i)
  {
    const double* c = f.clipPlanes[i];
    const double start = c[0] * p.x + c[1] * p.y + c[2] * p.z + c[3];
    const double rate = c[0] * d.x + c[1] * d.y + c[2] * d.z;
    if (rate == 0.0)
    {
      if (start < 0.0)
      {
        return false;
      }
      continue;
    }
    const double t = -start / rate;
    if (rate > 0.0)
    {
      t0 = t + kClipMargin > t0 ? t + kClipMargin : t0;
    }
    else
    {
      t1 = t - kClipMargin < t1 ? t - kClipMargin : t1;
    }
  }
  return t0 <= t1;
}

// A secondary ray's [tMin, tMax] narrowed to what the clipping planes keep:
// false when they keep none of it, and the ray need not be traced.
OCTORAY_HD bool ClipRay(const FrameConstants& f, Ray& ray)
{
  if (f.clipPlaneCount == 0)
  {
    return true;
  }
  double t0 = ray.tMin, t1 = ray.tMax;
  if (!ClipLine(f, ToDouble(ray.origin), ToDouble(ray.direction), t0, t1))
  {
    return false;
  }
  ray.tMin = static_cast<float>(t0);
  ray.tMax = static_cast<float>(t1);
  return ray.tMin <= ray.tMax;
}

// A pixel's primary ray, its origin moved to where it enters the root cube
// (computed in double). `tBase` is that entry's distance from the near plane.
// False when the ray misses the cube, or the clipping range, the clipping
// planes or opaque geometry end it before.
OCTORAY_HD bool PrimaryRay(const FrameConstants& f, int x, int y, Ray& ray, double& tBase)
{
  Vec3d nearPoint, d;
  double length;
  if (!PixelLine(f, x, y, nearPoint, d, length))
  {
    return false;
  }
  double tEnd = length;
  if (f.depthBuffer)
  {
    const float w = f.depthBuffer[static_cast<std::size_t>(y) * f.width + x];
    if (w < 1.0f)
    {
      const Vec3d ndc = PixelNdc(f, x, y, 2.0 * w - 1.0);
      tEnd = Dot(Unproject(f.unitFromNdc, ndc.x, ndc.y, ndc.z) - nearPoint, d);
    }
  }
  // The root cube's slab interval, in double.
  double t0 = 0.0, t1 = tEnd;
  for (int a = 0; a < 3; ++a)
  {
    if (d[a] == 0.0)
    {
      if (!(nearPoint[a] >= 0.0 && nearPoint[a] < 1.0))
      {
        return false;
      }
      continue;
    }
    double ta = (0.0 - nearPoint[a]) / d[a];
    double tb = (1.0 - nearPoint[a]) / d[a];
    if (ta > tb)
    {
      const double s = ta;
      ta = tb;
      tb = s;
    }
    t0 = ta > t0 ? ta : t0;
    t1 = tb < t1 ? tb : t1;
  }
  if (!(t0 <= t1) || !ClipLine(f, nearPoint, d, t0, t1))
  {
    return false;
  }
  tBase = t0;
  ray.origin = ToFloat(nearPoint + t0 * d);
  SetDirection(ray, ToFloat(d));
  ray.tMin = 0.0f;
  ray.tMax = static_cast<float>(t1 - t0);
  return true;
}

// b^e for b > 0 from +, -, *, / and exact exponent manipulation only, so
// that the CPU and CUDA backends round it alike (their libm powf do not
// agree to the last bit, and a composite ray compounds that over hundreds of
// voxels). Accurate to a few float ulps.
OCTORAY_HD float PortablePow(float b, float e)
{
  if (!(b > 0.0f))
  {
    return 0.0f;
  }
  int exponent;
  const float m = frexpf(b, &exponent); // b = m 2^exponent, m in [0.5, 1)
  // log2(m) = 2 atanh(s) / ln 2 with s = (m - 1) / (m + 1) in [-1/3, 0).
  const float s = (m - 1.0f) / (m + 1.0f);
  const float s2 = s * s;
  const float series =
    s * (1.0f + s2 * (1.0f / 3 + s2 * (1.0f / 5 + s2 * (1.0f / 7 + s2 * (1.0f / 9 + s2 * (1.0f / 11 + s2 / 13))))));
  const float x = e * (static_cast<float>(exponent) + 2.0f * series * 1.44269504f); // e log2(b)
  if (x < -149.0f)
  {
    return 0.0f;
  }
  if (x > 128.0f)
  {
    return INFINITY;
  }
  const float whole = floorf(x);
  const float y = (x - whole) * 0.693147181f; // 2^f = e^y, y in [0, ln 2)
  const float p =
    1.0f + y * (1.0f + y * (0.5f + y * (1.0f / 6 + y * (1.0f / 24 + y * (1.0f / 120 + y * (1.0f / 720 + y / 5040))))));
  return ldexpf(p, static_cast<int>(whole));
}

// The transfer function's colour and opacity of a scalar: the range mapped
// onto the table, rounded to the nearest entry, clamped to the ends.
OCTORAY_HD Rgba TransferLookup(const FrameConstants& f, float value)
{
  const float u = Clamp01((value - f.transferRange[0]) / (f.transferRange[1] - f.transferRange[0]));
  return f.transfer[static_cast<int>(u * (f.transferSize - 1) + 0.5f)];
}

OCTORAY_HD Vec3f RgbOf(const Rgba& c)
{
  return Vec3f{ c.r, c.g, c.b };
}

// Colour and opacity of a node: through the transfer function when the
// frame has one and the node a scalar, else its averaged colour.
OCTORAY_HD Rgba NodeColor(const FrameConstants& f, const OctreeView& tree, std::uint32_t node)
{
  if (f.transfer && tree.scalar)
  {
    return TransferLookup(f, DecodeScalar(tree.scalarRange, tree.scalar[node]));
  }
  return StoredColor(tree, node);
}

// The normal of the cut where a clipping plane cuts the hit voxel and the
// ray starts there: the plane nearest the start, if one passes within the
// voxel's size of it. False where none does.
OCTORAY_HD bool CutNormal(const FrameConstants& f, const Ray& ray, const NodeHit& hit, Vec3f& n)
{
  const Vec3f start = ray.origin + ray.tMin * ray.direction;
  float nearest = hit.size;
  for (int i = 0; i < f.clipPlaneCount; ++i)
  {
    const double* c = f.clipPlanes[i];
    const float distance = static_cast<float>(fabs(c[0] * start.x + c[1] * start.y + c[2] * start.z + c[3]));
    if (distance < nearest)
    {
      nearest = distance;
      n = Vec3f{ static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2]) };
    }
  }
  return nearest < hit.size;
}

// The occupancy gradient of the six neighbours at the hit's level: it
// follows the shape, not the voxel's blocky faces. Zero where it vanishes
// (inside a solid block, a sheet one voxel thick).
OCTORAY_HD Vec3f OccupancyGradient(const OctreeView& tree, const NodeHit& hit)
{
  Vec3f n{ 0.0f, 0.0f, 0.0f };
  const float half = 0.5f * hit.size;
  const Vec3f centre = hit.lo + Vec3f{ half, half, half };
  for (int a = 0; a < 3; ++a)
  {
    Vec3f p = centre;
    p[a] -= hit.size;
    const float below = Occupied(tree, hit.level, p) ? 1.0f : 0.0f;
    p[a] += 2.0f * hit.size;
    const float above = Occupied(tree, hit.level, p) ? 1.0f : 0.0f;
    n[a] = below - above;
  }
  return n;
}

// Surface normal at a hit, facing the viewer. Where a clipping plane cuts
// the voxel the ray starts in, the plane's: what the ray sees there is the
// cut, a flat face, whatever the data says inside the solid (a CT's
// gradient within bone is noise, and shaded by it the cut was mottled;
// Weiskopf et al. 2003 light a clip surface by the clip geometry's normal
// for the same reason). Elsewhere the averaged point normals where the
// data has them and they do not cancel (a mean shorter than half a length
// step, 1/510, is stored as zero: OctahedralNormal.h); otherwise the
// occupancy gradient; where that vanishes too, the entry face.
OCTORAY_HD Vec3f SurfaceNormal(const FrameConstants& f, const OctreeView& tree, const Ray& ray, const NodeHit& hit)
{
  Vec3f n{ 0.0f, 0.0f, 0.0f };
  const bool startsInside = hit.tEnter < ray.tMin;
  if (!(startsInside && CutNormal(f, ray, hit, n)))
  {
    n = tree.normal ? DecodeNormal(tree.normal[hit.node]) : Vec3f{ 0.0f, 0.0f, 0.0f };
    if (Dot(n, n) < 1e-6f)
    {
      n = OccupancyGradient(tree, hit);
    }
    if (Dot(n, n) < 1e-6f)
    {
      const int axis = hit.axis >= 0 ? hit.axis : 2;
      n[axis] = ray.direction[axis] > 0.0f ? -1.0f : 1.0f;
    }
  }
  n = Normalize(n);
  return Dot(n, ray.direction) > 0.0f ? -n : n;
}

// The point where the ray enters the hit voxel, nudged back out of it along
// the entry face so that secondary rays do not start inside the voxel.
OCTORAY_HD Vec3f EntryPoint(const Ray& ray, const NodeHit& hit)
{
  const float t = hit.tEnter > ray.tMin ? hit.tEnter : ray.tMin;
  Vec3f p = ray.origin + t * ray.direction;
  if (hit.axis >= 0)
  {
    p[hit.axis] += (ray.direction[hit.axis] > 0.0f ? -1.0f : 1.0f) * 1e-3f * hit.size;
  }
  return p;
}

// Where shadow rays start: one voxel above the hit along its shading normal.
// A smooth normal (the points' normals, a CT's gradient) leans away from the
// voxel faces of the staircase the octree draws, so a ray started on the
// face itself meets the neighbouring steps and speckles lit surfaces with
// shadow acne; one voxel along the normal clears the steps.
OCTORAY_HD Vec3f ShadowRayOrigin(const Vec3f& surface, const Vec3f& normal, const NodeHit& hit)
{
  return surface + hit.size * normal;
}

// A surface hit where it is lit: the point, its shading normal and the
// direction back along the ray.
struct SurfacePoint
{
  Vec3f point, normal, view;
};

OCTORAY_HD SurfacePoint SurfaceAt(const FrameConstants& f, const OctreeView& tree, const Ray& ray, const NodeHit& hit)
{
  return SurfacePoint{ EntryPoint(ray, hit), SurfaceNormal(f, tree, ray, hit), -ray.direction };
}

OCTORAY_HD int LightsOf(const FrameConstants& f)
{
  return f.lightCount > 0 ? f.lightCount : 1; // none set: the headlight
}

// Light i as a surface point sees it: the unit direction towards it, its
// colour and distance, and the cosine at which it falls (<= 0: the surface
// faces away; nothing to add, no shadow ray).
struct LightSample
{
  Vec3f direction, color;
  float distance, cosine;
};

OCTORAY_HD LightSample SampleLight(const FrameConstants& f, int i, const SurfacePoint& s)
{
  LightSample light{ s.view, Vec3f{ 1.0f, 1.0f, 1.0f }, INFINITY, 0.0f }; // the headlight
  if (f.lightCount > 0)
  {
    const UnitLight& l = f.lights[i];
    const Vec3f towards = l.directional ? l.position : l.position - s.point;
    light.color = l.color;
    light.distance = l.directional ? INFINITY : Length(towards);
    light.direction = Normalize(towards);
  }
  light.cosine = Dot(s.normal, light.direction);
  return light;
}

// The shadow ray from a surface hit towards a light it faces, within what
// the clipping planes keep. False when they keep none of it: nothing there
// can cast a shadow.
OCTORAY_HD bool ShadowRay(
  const FrameConstants& f, const SurfacePoint& s, const NodeHit& hit, const LightSample& light, Ray& shadow)
{
  shadow.origin = ShadowRayOrigin(s.point, s.normal, hit);
  SetDirection(shadow, light.direction);
  shadow.tMin = 0.0f;
  shadow.tMax = light.distance;
  return ClipRay(f, shadow);
}

// Whether a voxel lies on the ray.
OCTORAY_HD bool Occluded(const OctreeView& tree, const Ray& ray, const LevelOfDetail& lod)
{
  FirstHitVisitor blocker;
  Traverse(tree, ray, lod, blocker);
  return blocker.found;
}

// Whether a voxel lies between a surface hit and a light it faces.
OCTORAY_HD bool Shadowed(const FrameConstants& f, const OctreeView& tree, const SurfacePoint& s, const NodeHit& hit,
  const LightSample& light, const LevelOfDetail& lod)
{
  Ray shadow;
  return ShadowRay(f, s, hit, light, shadow) && Occluded(tree, shadow, lod);
}

// The shadow rays of one hit, traced by the caller already (the CPU's
// packets of them): the surface point they left from, and whether each
// light's met a voxel, by light index.
struct TracedShadows
{
  SurfacePoint surface;
  bool occluded[kMaxLights];
};

// Lit colour of a surface hit (before reflection): depth cue, or Phong
// (ambient + diffuse + specular) from every light that sees the hit. The
// shadow rays are traced here unless `traced` holds them.
template <typename F>
OCTORAY_HD Vec3f ShadeSurface(const FrameConstants& f, const OctreeView& tree, const Ray& ray, const NodeHit& hit,
  float tFromNear, const LevelOfDetail& lod, const TracedShadows* traced, std::size_t& secondaryRays)
{
  const Vec3f albedo = RgbOf(NodeColor(f, tree, hit.node));
  if (f.shade == ShadeMode::DepthCue)
  {
    const float u = Clamp01((tFromNear - f.cueNear) / (f.cueFar - f.cueNear));
    return albedo * (1.0f - f.depthCue * u);
  }
  if constexpr (!F::kLit)
  {
    return albedo;
  }
  const SurfacePoint s = traced ? traced->surface : SurfaceAt(f, tree, ray, hit);
  Vec3f lit = f.ambient * albedo;
  for (int i = 0; i < LightsOf(f); ++i)
  {
    const LightSample light = SampleLight(f, i, s);
    const float nl = light.cosine;
    if (nl <= 0.0f)
    {
      continue;
    }
    if constexpr (F::kShadows)
    {
      ++secondaryRays;
      if (traced ? traced->occluded[i] : Shadowed(f, tree, s, hit, light, lod))
      {
        continue;
      }
    }
    const Vec3f r = 2.0f * nl * s.normal - light.direction; // the light mirrored about the normal
    const float rv = Dot(r, s.view);
    const float spec = rv > 0.0f ? f.specular * PortablePow(rv, f.specularPower) : 0.0f;
    lit += light.color * (f.diffuse * nl * albedo + Vec3f{ spec, spec, spec });
  }
  return lit;
}

// Accumulates the volume blend modes over the voxels a ray passes.
struct BlendVisitor
{
  const FrameConstants* f;
  const OctreeView* tree;
  float rgba[4] = { 0, 0, 0, 0 };
  float value = 0.0f;  // max, min, or the running integral
  float length = 0.0f; // path length through voxels
  bool any = false;
  float firstT = 0.0f;
  // The ray's end (its tMax: opaque geometry, a clipping plane): a voxel
  // that reaches past it counts only up to it, as the first counts only
  // from the ray's start at 0.
  float tEnd = INFINITY;

  OCTORAY_HD bool Visit(const NodeHit& hit)
  {
    const float t0 = hit.tEnter > 0.0f ? hit.tEnter : 0.0f;
    const float dt = (hit.tExit < tEnd ? hit.tExit : tEnd) - t0;
    if (!any)
    {
      firstT = t0;
    }
    const float s = tree->scalar ? DecodeScalar(tree->scalarRange, tree->scalar[hit.node]) : NodeLuminance(hit.node);
    switch (f->blend)
    {
      case BlendMode::Composite:
      {
        const Rgba c = NodeColor(*f, *tree, hit.node);
        // Opacity is given per unit distance; correct it for this length.
        const float alpha = 1.0f - PortablePow(1.0f - Clamp01(c.a), dt / f->opacityUnitDistance);
        const float w = (1.0f - rgba[3]) * alpha;
        rgba[0] += w * c.r, rgba[1] += w * c.g, rgba[2] += w * c.b, rgba[3] += w;
        any = true;
        return rgba[3] > 0.995f; // early ray termination
      }
      case BlendMode::Maximum:
        value = any ? fmaxf(value, s) : s;
        break;
      case BlendMode::Minimum:
        value = any ? fminf(value, s) : s;
        break;
      case BlendMode::Average:
      case BlendMode::Additive:
        value += s * dt;
        length += dt;
        break;
      default:
        break;
    }
    any = true;
    return false;
  }

  OCTORAY_HD float NodeLuminance(std::uint32_t node) const
  {
    const Rgba c = StoredColor(*tree, node);
    return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
  }
};

// Colour of a projected scalar (MIP, MinIP, average, additive).
OCTORAY_HD Rgba ProjectedColor(const FrameConstants& f, float value)
{
  if (f.transfer)
  {
    return TransferLookup(f, value);
  }
  const float v = Clamp01(value);
  return Rgba{ v, v, v, 1.0f };
}

// A ray still to be traced and the weight of its colour in the pixel.
struct PendingRay
{
  Ray ray;
  Vec3f weight;
  int bounces;
  float tFromNear;
};
// Enough for every path of 2 bounces (each hit spawns at most 2 rays).
constexpr int kMaxPendingRays = 8;
// Voxels a refracted ray may cross inside one medium before it is dropped.
constexpr int kMaxMediumSteps = 1 << 12;

OCTORAY_HD Vec3f Reflect(const Vec3f& d, const Vec3f& n)
{
  return d - 2.0f * Dot(d, n) * n;
}

// Snell's law: d enters through a surface with normal n (facing against d)
// from index n1 into n2, eta = n1 / n2. False on total internal reflection.
OCTORAY_HD bool Refract(const Vec3f& d, const Vec3f& n, float eta, Vec3f& t)
{
  const float cosIn = -Dot(d, n);
  const float sin2Out = eta * eta * (1.0f - cosIn * cosIn);
  if (sin2Out > 1.0f)
  {
    return false;
  }
  const float cosOut = sqrtf(1.0f - sin2Out);
  t = Normalize(eta * d + (eta * cosIn - cosOut) * n);
  return true;
}

// A secondary ray from p; tMin skips the surface it starts on.
OCTORAY_HD void StartRay(Ray& ray, const Vec3f& p, const Vec3f& d, float tMin)
{
  ray.origin = p;
  SetDirection(ray, d);
  ray.tMin = tMin;
  ray.tMax = INFINITY;
}

// Whether the clipping planes keep a point of the unit cube.
OCTORAY_HD bool KeptByClipPlanes(const FrameConstants& f, const Vec3d& p)
{
  double t0 = 0.0, t1 = 0.0;
  return ClipLine(f, p, Vec3d{ 0.0, 0.0, 0.0 }, t0, t1);
}

OCTORAY_HD Vec3d CellCentre(const std::uint32_t cell[3], float size)
{
  return Vec3d{ (cell[0] + 0.5) * size, (cell[1] + 0.5) * size, (cell[2] + 0.5) * size };
}

// The plane on axis a through which a ray going d leaves the cell `cell`
// of side `size`.
OCTORAY_HD float ExitPlane(const std::uint32_t cell[3], float size, const Vec3f& d, int a)
{
  return (static_cast<float>(cell[a]) + (d[a] > 0.0f ? 1.0f : 0.0f)) * size;
}

// Where a ray at p going d leaves the cell `cell` of side `size`: the
// distance, no less than 0, in tExit, and the axis of the face it leaves
// through, returned (-1: none, d being zero).
OCTORAY_HD int CellExit(const std::uint32_t cell[3], float size, const Vec3f& p, const Vec3f& d, float& tExit)
{
  tExit = INFINITY;
  int axis = -1;
  for (int a = 0; a < 3; ++a)
  {
    if (d[a] != 0.0f)
    {
      const float t = (ExitPlane(cell, size, d, a) - p[a]) / d[a];
      if (t < tExit)
      {
        tExit = t;
        axis = a;
      }
    }
  }
  tExit = tExit > 0.0f ? tExit : 0.0f;
  return axis;
}

// A ray that entered the refracting voxel `hit` through the shading normal n
// crosses the occupied voxels of the hit's level (the medium) voxel by
// voxel, reflecting totally inside where Snell allows no exit, until it
// leaves through a face, where it refracts back into air. The emerging ray
// goes into `out` (its weight and bounces set by the caller; each internal
// reflection costs a bounce). False when the bounces run out inside. A
// voxel whose centre the clipping planes take away is not medium.
OCTORAY_HD bool TraceThroughMedium(const FrameConstants& f, const OctreeView& tree, const Ray& in, const NodeHit& hit,
  const Vec3f& n, float ior, PendingRay& out)
{
  Vec3f d;
  if (!Refract(in.direction, n, 1.0f / ior, d))
  {
    return false; // an index below 1 seen at a grazing angle: all reflected
  }
  const float tEnter = hit.tEnter > in.tMin ? hit.tEnter : in.tMin;
  Vec3f p = in.origin + tEnter * in.direction;
  const int level = hit.level;
  const std::uint32_t cells = 1u << level;
  const float size = hit.size;
  std::uint32_t cell[3];
  for (int a = 0; a < 3; ++a)
  {
    cell[a] = static_cast<std::uint32_t>(hit.lo[a] * static_cast<float>(cells));
  }
  for (int step = 0; step < kMaxMediumSteps; ++step)
  {
    float tExit;
    const int axis = CellExit(cell, size, p, d, tExit);
    if (axis < 0)
    {
      return false;
    }
    p += tExit * d;
    p[axis] = ExitPlane(cell, size, d, axis); // exactly on the face
    const int stepDir = d[axis] > 0.0f ? 1 : -1;
    const long long next = static_cast<long long>(cell[axis]) + stepDir;
    bool medium = false;
    if (next >= 0 && next < static_cast<long long>(cells))
    {
      std::uint32_t c[3] = { cell[0], cell[1], cell[2] };
      c[axis] = static_cast<std::uint32_t>(next);
      const std::uint32_t node = tree.Find(level, EncodeMorton(c[0], c[1], c[2]));
      medium = node != kInvalidIndex && (!tree.refraction || tree.refraction[node] > 0.0f) &&
        KeptByClipPlanes(f, CellCentre(c, size));
    }
    if (medium)
    {
      cell[axis] = static_cast<std::uint32_t>(next);
      continue;
    }
    // At the medium's boundary: out into air, or totally reflected inside.
    Vec3f inward{ 0.0f, 0.0f, 0.0f };
    inward[axis] = -static_cast<float>(stepDir);
    Vec3f outDir;
    if (Refract(d, inward, ior, outDir))
    {
      StartRay(out.ray, p, outDir, 1e-4f * size);
      return true;
    }
    if (out.bounces >= f.maxBounces)
    {
      return false;
    }
    ++out.bounces;
    d[axis] = -d[axis];
  }
  return false;
}

// A pixel's primary ray, with its start in double (for window depths) and
// the level of detail along it.
struct CameraRay
{
  Ray ray;
  double tBase; // where the ray entered the root cube, from the near plane
  int x, y;     // its pixel
  LevelOfDetail lod;

  // Window depth of the point at distance t along the ray. The pixel's line
  // is computed again in double rather than held through the traversal,
  // where its twelve registers would crowd the traversal's own.
  OCTORAY_HD float DepthAt(const FrameConstants& f, float t) const
  {
    Vec3d nearPoint, d;
    double length;
    PixelLine(f, x, y, nearPoint, d, length);
    return WindowDepth(f, (nearPoint + tBase * d) + double(t) * d);
  }
};

// A volume blend mode's pixel from what its ray collected (BlendVisitor).
OCTORAY_HD void ShadeBlend(const FrameConstants& f, const CameraRay& pixel, const BlendVisitor& blend, float rgba[4],
  float& depth)
{
  if (!blend.any)
  {
    return;
  }
  if (f.blend == BlendMode::Composite)
  {
    for (int k = 0; k < 4; ++k)
    {
      rgba[k] = blend.rgba[k];
    }
  }
  else
  {
    float v = blend.value;
    if (f.blend == BlendMode::Average)
    {
      v = blend.length > 0.0f ? blend.value / blend.length : 0.0f;
    }
    const Rgba c = ProjectedColor(f, v);
    rgba[0] = c.r * c.a, rgba[1] = c.g * c.a, rgba[2] = c.b * c.a, rgba[3] = c.a;
  }
  depth = pixel.DepthAt(f, blend.firstT);
}

// A surface, first hit only, from the voxel its ray hits first (if any);
// its shadow rays from `shadows` where the caller traced them.
template <typename F>
OCTORAY_HD void ShadeFirstHit(const FrameConstants& f, const OctreeView& tree, const CameraRay& pixel,
  const FirstHitVisitor& first, const TracedShadows* shadows, float rgba[4], float& depth,
  std::size_t& secondaryRays)
{
  if (first.found)
  {
    const float tHit = first.hit.tEnter > pixel.ray.tMin ? first.hit.tEnter : pixel.ray.tMin;
    depth = pixel.DepthAt(f, tHit);
    const float tFromNear = static_cast<float>(pixel.tBase) + tHit;
    const Vec3f rgb = ShadeSurface<F>(f, tree, pixel.ray, first.hit, tFromNear, pixel.lod, shadows, secondaryRays);
    rgba[0] = rgb.x, rgba[1] = rgb.y, rgba[2] = rgb.z, rgba[3] = 1.0f;
  }
}

// The mirror ray (of a reflecting voxel) and the ray through the medium (of
// a refracting one) that `path` spawns where it hits `hit` at tHit, each
// pushed onto the `top` pending rays where there is room.
OCTORAY_HD void SpawnRays(const FrameConstants& f, const OctreeView& tree, const PendingRay& path, const NodeHit& hit,
  float tHit, float reflectivity, float ior, PendingRay pending[kMaxPendingRays], int& top,
  std::size_t& secondaryRays)
{
  const Vec3f n = SurfaceNormal(f, tree, path.ray, hit);
  if (reflectivity > 0.0f && top < kMaxPendingRays)
  {
    PendingRay mirror;
    StartRay(mirror.ray, EntryPoint(path.ray, hit), Reflect(path.ray.direction, n), 0.0f);
    mirror.weight = path.weight * reflectivity;
    mirror.bounces = path.bounces + 1;
    mirror.tFromNear = path.tFromNear + tHit;
    if (ClipRay(f, mirror.ray))
    {
      pending[top++] = mirror;
      ++secondaryRays;
    }
  }
  if (ior > 0.0f && top < kMaxPendingRays)
  {
    PendingRay through;
    through.weight = path.weight * (1.0f - reflectivity) * RgbOf(NodeColor(f, tree, hit.node));
    through.bounces = path.bounces + 1;
    through.tFromNear = path.tFromNear + tHit;
    if (TraceThroughMedium(f, tree, path.ray, hit, n, ior, through) && ClipRay(f, through.ray))
    {
      pending[top++] = through;
      ++secondaryRays;
    }
  }
}

// A surface: the first voxel, then the mirror and refracted rays it spawns,
// each carrying its weight in the pixel, until the bounce limit. The first
// voxel is primaryHit, and its shadow rays primaryShadows, where the caller
// traced them already.
template <typename F>
OCTORAY_HD void TracedPixel(const FrameConstants& f, const OctreeView& tree, const CameraRay& pixel,
  const FirstHitVisitor* primaryHit, const TracedShadows* primaryShadows, float rgba[4], float& depth,
  std::size_t& secondaryRays)
{
  PendingRay pending[kMaxPendingRays];
  int top = 0;
  pending[top++] = PendingRay{ pixel.ray, Vec3f{ 1.0f, 1.0f, 1.0f }, 0, static_cast<float>(pixel.tBase) };
  bool primary = true;
  Vec3f color{ 0.0f, 0.0f, 0.0f };
  while (top > 0)
  {
    const PendingRay path = pending[--top];
    const TracedShadows* shadows = primary ? primaryShadows : nullptr;
    FirstHitVisitor first;
    if (primary && primaryHit)
    {
      first = *primaryHit;
    }
    else
    {
      Traverse(tree, path.ray, pixel.lod, first);
    }
    if (!first.found)
    {
      primary = false;
      continue;
    }
    const NodeHit& hit = first.hit;
    const float tHit = hit.tEnter > path.ray.tMin ? hit.tEnter : path.ray.tMin;
    if (primary)
    {
      depth = pixel.DepthAt(f, tHit);
      rgba[3] = 1.0f;
      primary = false;
    }
    const Vec3f rgb = ShadeSurface<F>(f, tree, path.ray, hit, path.tFromNear + tHit, pixel.lod, shadows, secondaryRays);
    const bool canBounce = path.bounces < f.maxBounces;
    const float reflectivity = Clamp01(canBounce && tree.reflectivity ? tree.reflectivity[hit.node] : 0.0f);
    const float ior = canBounce && tree.refraction ? tree.refraction[hit.node] : 0.0f;
    // A refracting voxel is clear: it tints what is seen through it instead
    // of showing its own lit colour.
    const float opaque = (1.0f - reflectivity) * (ior > 0.0f ? 0.0f : 1.0f);
    color += path.weight * opaque * rgb;
    if (reflectivity > 0.0f || ior > 0.0f)
    {
      SpawnRays(f, tree, path, hit, tHit, reflectivity, ior, pending, top, secondaryRays);
    }
  }
  rgba[0] = color.x, rgba[1] = color.y, rgba[2] = color.z;
}

// A pixel's primary ray and level of detail, and its colour and depth where
// nothing is hit (premultiplied RGBA 0, window depth 1). False where the
// ray misses the root cube.
OCTORAY_HD bool StartPixel(const FrameConstants& f, int x, int y, CameraRay& pixel, float rgba[4], float& depth)
{
  rgba[0] = rgba[1] = rgba[2] = rgba[3] = 0.0f;
  depth = 1.0f;
  if (!PrimaryRay(f, x, y, pixel.ray, pixel.tBase))
  {
    return false;
  }
  pixel.x = x;
  pixel.y = y;
  pixel.lod.pixels = f.lodPixels;
  pixel.lod.footprint0 = f.footprint0 + f.footprintSlope * static_cast<float>(pixel.tBase);
  pixel.lod.footprintSlope = f.footprintSlope;
  return true;
}

// One pixel: premultiplied RGBA and window depth (1 = nothing hit).
template <typename F>
OCTORAY_HD void RenderPixel(const FrameConstants& f, const OctreeView& tree, int x, int y, float rgba[4],
  float& depth, std::size_t& secondaryRays)
{
  CameraRay pixel;
  if (!StartPixel(f, x, y, pixel, rgba, depth))
  {
    return;
  }
  if constexpr (F::kVolume)
  {
    BlendVisitor blend{ &f, &tree };
    blend.tEnd = pixel.ray.tMax;
    Traverse(tree, pixel.ray, pixel.lod, blend);
    ShadeBlend(f, pixel, blend, rgba, depth);
  }
  else if constexpr (F::kSecondary)
  {
    TracedPixel<F>(f, tree, pixel, nullptr, nullptr, rgba, depth, secondaryRays);
  }
  else
  {
    FirstHitVisitor first;
    Traverse(tree, pixel.ray, pixel.lod, first);
    ShadeFirstHit<F>(f, tree, pixel, first, nullptr, rgba, depth, secondaryRays);
  }
}

template <typename Fn>
void DispatchFeatures(const FrameConstants& f, Fn&& fn)
{
  if (f.blend != BlendMode::Surface)
  {
    fn(Features<true, false, false, false>());
    return;
  }
  const bool lit = f.shade == ShadeMode::Phong;
  const bool shadows = lit && f.shadows;
  const bool secondary = f.maxBounces > 0;
  if (shadows)
  {
    secondary ? fn(Features<false, true, true, true>()) : fn(Features<false, true, true, false>());
  }
  else if (lit)
  {
    secondary ? fn(Features<false, true, false, true>()) : fn(Features<false, true, false, false>());
  }
  else
  {
    secondary ? fn(Features<false, false, false, true>()) : fn(Features<false, false, false, false>());
  }
}
}
