// The engine's own copy of the points it was built from: positions in the
// caller's precision, attributes in compact form, and each point's
// full-depth Morton key. Kept so that updates and rebuilds need no input.
#pragma once

#include "Config.h"
#include "RootCube.h"
#include "Types.h"

#include <cmath>

namespace octoray
{
// Slots of the attribute vector every node averages. Only the slots of
// attributes present in the input are read or written.
enum AttributeSlot : int
{
  kSlotR = 0,
  kSlotG,
  kSlotB,
  kSlotA,
  kSlotScalar,
  kSlotReflectivity,
  kSlotRefraction,
  kSlotNx,
  kSlotNy,
  kSlotNz,
  kSlotCount
};

struct PointArraysView
{
  std::size_t count = 0;
  const float* xyzFloat = nullptr;
  const double* xyzDouble = nullptr;
  const std::uint8_t* color8 = nullptr; // RGBA, 4 bytes a point
  const Rgba* colorFloat = nullptr;
  const float* scalar = nullptr;
  const float* reflectivity = nullptr;
  const float* refraction = nullptr;
  const Vec3f* normal = nullptr;        // unit length, or zero where the input's was zero

  OCTORAY_HD void Position(std::size_t i, double p[3]) const
  {
    for (int a = 0; a < 3; ++a)
    {
      p[a] = xyzDouble ? xyzDouble[3 * i + a] : static_cast<double>(xyzFloat[3 * i + a]);
    }
  }

  // The point's attribute vector (slots of absent attributes are left alone).
  OCTORAY_HD void Attributes(std::size_t i, float v[kSlotCount]) const
  {
    if (color8)
    {
      for (int c = 0; c < 4; ++c)
      {
        v[kSlotR + c] = color8[4 * i + c] * (1.0f / 255.0f);
      }
    }
    else if (colorFloat)
    {
      const Rgba c = colorFloat[i];
      v[kSlotR] = c.r;
      v[kSlotG] = c.g;
      v[kSlotB] = c.b;
      v[kSlotA] = c.a;
    }
    if (scalar)
    {
      v[kSlotScalar] = scalar[i];
    }
    if (reflectivity)
    {
      v[kSlotReflectivity] = reflectivity[i];
    }
    if (refraction)
    {
      v[kSlotRefraction] = refraction[i];
    }
    if (normal)
    {
      v[kSlotNx] = normal[i].x;
      v[kSlotNy] = normal[i].y;
      v[kSlotNz] = normal[i].z;
    }
  }
};

// True when all three coordinates are finite.
OCTORAY_HD bool IsFinitePoint(const double p[3])
{
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// Unit normal of a caller's normal; zero stays zero (it carries no direction).
OCTORAY_HD Vec3f UnitNormal(float x, float y, float z)
{
  const float len2 = x * x + y * y + z * z;
  if (!(len2 > 0.0f) || !std::isfinite(len2))
  {
    return Vec3f{ 0.0f, 0.0f, 0.0f };
  }
  const float inv = 1.0f / std::sqrt(len2);
  return Vec3f{ x * inv, y * inv, z * inv };
}
}
