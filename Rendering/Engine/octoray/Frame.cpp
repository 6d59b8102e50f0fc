#include "Frame.h"
#include "VecMath.h"

#include <array>
#include <cmath>
#include <string>
#include <utility>

namespace octoray
{
bool Invert4x4(const double m[16], double inverse[16])
{
  double a[4][8];
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      a[r][c] = m[4 * r + c];
      a[r][c + 4] = r == c ? 1.0 : 0.0;
    }
  }
  for (int c = 0; c < 4; ++c)
  {
    int pivot = c;
    for (int r = c + 1; r < 4; ++r)
    {
      if (std::fabs(a[r][c]) > std::fabs(a[pivot][c]))
      {
        pivot = r;
      }
    }
    if (!(std::fabs(a[pivot][c]) > 0.0))
    {
      return false;
    }
    for (int k = 0; k < 8; ++k)
    {
      std::swap(a[c][k], a[pivot][k]);
    }
    const double inv = 1.0 / a[c][c];
    for (int k = 0; k < 8; ++k)
    {
      a[c][k] *= inv;
    }
    for (int r = 0; r < 4; ++r)
    {
      if (r != c)
      {
        const double factor = a[r][c];
        for (int k = 0; k < 8; ++k)
        {
          a[r][k] -= factor * a[c][k];
        }
      }
    }
  }
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      inverse[4 * r + c] = a[r][c + 4];
    }
  }
  return true;
}

namespace
{
void Multiply(const double a[16], const double b[16], double out[16])
{
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      double s = 0.0;
      for (int k = 0; k < 4; ++k)
      {
        s += a[4 * r + k] * b[4 * k + c];
      }
      out[4 * r + c] = s;
    }
  }
}

std::string Triple(const double v[3])
{
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}

void CheckClipPlanes(const std::vector<ClipPlane>& planes)
{
  if (planes.size() > static_cast<std::size_t>(kMaxClipPlanes))
  {
    throw Error("octoray: at most " + std::to_string(kMaxClipPlanes) + " clipping planes, got " +
      std::to_string(planes.size()));
  }
  for (std::size_t i = 0; i < planes.size(); ++i)
  {
    const ClipPlane& p = planes[i];
    const Vec3d normal{ p.normal[0], p.normal[1], p.normal[2] };
    const Vec3d origin{ p.origin[0], p.origin[1], p.origin[2] };
    if (!(Length(normal) > 0.0) || !std::isfinite(Length(normal)) || !std::isfinite(Length(origin)))
    {
      throw Error("octoray: clipping plane " + std::to_string(i) +
        " needs a finite origin and a non-zero normal, got " + Triple(p.origin) + " and " + Triple(p.normal));
    }
  }
}
}

void CheckSettings(const RenderSettings& s)
{
  if (s.width <= 0 || s.height <= 0)
  {
    throw Error("octoray: the viewport must be at least 1x1, got " + std::to_string(s.width) + "x" +
      std::to_string(s.height));
  }
  if (!s.depthBuffer.empty() && s.depthBuffer.size() != static_cast<std::size_t>(s.width) * s.height)
  {
    throw Error("octoray: the depth buffer has " + std::to_string(s.depthBuffer.size()) + " values for a " +
      std::to_string(s.width) + "x" + std::to_string(s.height) + " viewport");
  }
  if (s.lights.size() > static_cast<std::size_t>(kMaxLights))
  {
    throw Error("octoray: at most " + std::to_string(kMaxLights) + " lights, got " + std::to_string(s.lights.size()));
  }
  CheckClipPlanes(s.clipPlanes);
  // A NaN here (VTK's clamped setters let one through) would turn every
  // pixel it touches NaN, drawn black.
  const std::pair<const char*, float> numbers[] = { { "ambient coefficient", s.ambient },
    { "diffuse coefficient", s.diffuse }, { "specular coefficient", s.specular },
    { "specular power", s.specularPower }, { "depth cue", s.depthCue }, { "level-of-detail pixel size", s.lodPixels },
    { "opacity unit distance", s.opacityUnitDistance } };
  for (const auto& number : numbers)
  {
    if (!std::isfinite(number.second))
    {
      throw Error(std::string("octoray: the ") + number.first + " must be a finite number, got " +
        std::to_string(number.second));
    }
  }
  if (!s.transfer.table.empty() && !(s.transfer.range[1] > s.transfer.range[0]))
  {
    throw Error("octoray: the transfer function's scalar range is empty");
  }
}

namespace
{
// The camera between normalised device coordinates and the octree's unit
// cube: unit <- world is u = (p - origin) / size, world <- unit its inverse.
void SetCamera(const RenderSettings& s, const RootCube& cube, FrameConstants& f)
{
  const double unitFromWorld[16] = { 1 / cube.size, 0, 0, -cube.origin[0] / cube.size, 0, 1 / cube.size, 0,
    -cube.origin[1] / cube.size, 0, 0, 1 / cube.size, -cube.origin[2] / cube.size, 0, 0, 0, 1 };
  const double worldFromUnit[16] = { cube.size, 0, 0, cube.origin[0], 0, cube.size, 0, cube.origin[1], 0, 0,
    cube.size, cube.origin[2], 0, 0, 0, 1 };
  double ndcFromWorld[16];
  if (!Invert4x4(s.inverseViewProjection, ndcFromWorld))
  {
    throw Error("octoray: the inverse view-projection matrix is singular");
  }
  Multiply(unitFromWorld, s.inverseViewProjection, f.unitFromNdc);
  Multiply(ndcFromWorld, worldFromUnit, f.ndcFromUnit);
}

// The lights in the unit cube: directions normalised, positions mapped.
void SetLights(const RenderSettings& s, const RootCube& cube, FrameConstants& f)
{
  f.lightCount = static_cast<int>(s.lights.size());
  for (int i = 0; i < f.lightCount; ++i)
  {
    const Light& l = s.lights[i];
    UnitLight& u = f.lights[i];
    const Vec3d position{ l.position[0], l.position[1], l.position[2] };
    const Vec3d origin{ cube.origin[0], cube.origin[1], cube.origin[2] };
    const double len = Length(position);
    u.directional = l.position[3] == 0.0;
    u.position = ToFloat(u.directional ? position / (len > 0 ? len : 1.0) : (position - origin) / cube.size);
    u.color = Vec3f{ l.color[0], l.color[1], l.color[2] } * l.intensity;
  }
}

// The clipping planes in the unit cube: with p = origin + size u, the kept
// side n . (p - o) >= 0 is (n / |n|) . u + n . (origin - o) / (|n| size) >= 0.
void SetClipPlanes(const RenderSettings& s, const RootCube& cube, FrameConstants& f)
{
  f.clipPlaneCount = static_cast<int>(s.clipPlanes.size());
  for (int i = 0; i < f.clipPlaneCount; ++i)
  {
    const ClipPlane& p = s.clipPlanes[i];
    const Vec3d normal{ p.normal[0], p.normal[1], p.normal[2] };
    const Vec3d toCube{ cube.origin[0] - p.origin[0], cube.origin[1] - p.origin[1], cube.origin[2] - p.origin[2] };
    const double length = Length(normal);
    for (int a = 0; a < 3; ++a)
    {
      f.clipPlanes[i][a] = normal[a] / length;
    }
    f.clipPlanes[i][3] = Dot(normal, toCube) / (length * cube.size);
  }
}

// A pixel's footprint at the near and far planes through the image
// centre, for the level of detail, and the unit cube's range of distances
// along the view, for the depth cue (f.unitFromNdc set).
void SetFootprintAndCue(const RenderSettings& s, FrameConstants& f)
{
  const int cx = s.width / 2, cy = s.height / 2;
  auto ndcX = [&](int x) { return 2.0 * (x + 0.5) / s.width - 1.0; };
  auto ndcY = [&](int y) { return 2.0 * (y + 0.5) / s.height - 1.0; };
  const Vec3d n0 = Unproject(f.unitFromNdc, ndcX(cx), ndcY(cy), -1.0);
  const Vec3d n1 = Unproject(f.unitFromNdc, ndcX(cx + 1), ndcY(cy), -1.0);
  const Vec3d f0 = Unproject(f.unitFromNdc, ndcX(cx), ndcY(cy), 1.0);
  const Vec3d f1 = Unproject(f.unitFromNdc, ndcX(cx + 1), ndcY(cy), 1.0);
  const double length = Length(n0 - f0);
  f.footprint0 = static_cast<float>(Length(n0 - n1));
  f.footprintSlope = static_cast<float>((Length(f0 - f1) - Length(n0 - n1)) / (length > 0 ? length : 1.0));
  double nearest = INFINITY, farthest = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    const double c[3] = { double(corner & 1), double((corner >> 1) & 1), double((corner >> 2) & 1) };
    double along = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      along += (c[a] - n0[a]) * (f0[a] - n0[a]) / (length > 0 ? length : 1.0);
    }
    nearest = std::fmin(nearest, along);
    farthest = std::fmax(farthest, along);
  }
  f.cueNear = static_cast<float>(std::fmax(nearest, 0.0));
  f.cueFar = static_cast<float>(std::fmax(farthest, f.cueNear + 1e-6));
}
}

FrameConstants MakeFrame(const RenderSettings& s, const OctreeView& tree)
{
  CheckSettings(s);
  const RootCube& cube = tree.cube;
  const bool secondaryRays = tree.reflectivity != nullptr || tree.refraction != nullptr;
  FrameConstants f;
  f.width = s.width;
  f.height = s.height;
  SetCamera(s, cube, f);
  f.blend = s.blend;
  f.shade = s.shade;
  f.ambient = s.ambient;
  f.diffuse = s.diffuse;
  f.specular = s.specular;
  f.specularPower = s.specularPower;
  f.depthCue = s.depthCue;
  f.shadows = s.shadows && !s.lights.empty() && s.shade == ShadeMode::Phong;
  f.maxBounces = secondaryRays ? s.maxBounces : 0;
  f.lodPixels = s.lodPixels;
  f.opacityUnitDistance = s.opacityUnitDistance > 0 ? s.opacityUnitDistance / static_cast<float>(cube.size) : 1.0f;
  SetLights(s, cube, f);
  SetClipPlanes(s, cube, f);
  SetFootprintAndCue(s, f);
  if (!s.transfer.table.empty())
  {
    f.transfer = s.transfer.table.data();
    f.transferSize = static_cast<int>(s.transfer.table.size());
    f.transferRange[0] = s.transfer.range[0];
    f.transferRange[1] = s.transfer.range[1];
  }
  f.depthBuffer = s.depthBuffer.empty() ? nullptr : s.depthBuffer.data();
  return f;
}

namespace
{
using Matrix = std::array<double, 16>;

Matrix Multiply(const Matrix& a, const Matrix& b)
{
  Matrix m{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k)
        m[4 * r + c] += a[4 * r + k] * b[4 * k + c];
  return m;
}
}

Matrix ViewProjection(const double eye[3], const double target[3], const double up[3], double fovyDegrees,
  double aspect, double zNear, double zFar, bool parallel, double parallelScale)
{
  const Vec3d from{ eye[0], eye[1], eye[2] };
  const Vec3d forward = Normalize(Vec3d{ target[0], target[1], target[2] } - from);
  const Vec3d side = Normalize(Cross(forward, Vec3d{ up[0], up[1], up[2] }));
  const Vec3d trueUp = Cross(side, forward);
  const Matrix view = { side.x, side.y, side.z, -Dot(side, from), trueUp.x, trueUp.y, trueUp.z, -Dot(trueUp, from),
    -forward.x, -forward.y, -forward.z, Dot(forward, from), 0, 0, 0, 1 };
  const double depth = zFar - zNear;
  Matrix projection{};
  if (parallel)
  {
    projection = { 1 / (parallelScale * aspect), 0, 0, 0, 0, 1 / parallelScale, 0, 0, 0, 0, -2 / depth,
      -(zFar + zNear) / depth, 0, 0, 0, 1 };
  }
  else
  {
    const double t = 1.0 / std::tan(fovyDegrees * M_PI / 360.0);
    projection = { t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, -(zFar + zNear) / depth, -2 * zFar * zNear / depth, 0, 0,
      -1, 0 };
  }
  return Multiply(projection, view);
}
}
