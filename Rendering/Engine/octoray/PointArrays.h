// The engine's own copy of the points it was built from: positions in the
// caller's precision, attributes in compact form, and each point's
// full-depth Morton key. Kept so that updates and rebuilds need no input.
#pragma once

#include "Attributes.h"
#include "Config.h"

#include <cmath>

namespace octoray
{
// The point arrays a backend holds, each a Buffer<its type>.
template <template <typename> class Buffer>
struct PointArrays
{
  Buffer<float> xyzFloat; // exactly one of the two, 3 values per point
  Buffer<double> xyzDouble;
  // Colours given as 8-bit stay 8-bit (a quarter of float RGBA's bytes);
  // the attribute `color` holds those given as float.
  Buffer<Rgba8> color8;
#define OCTORAY_MEMBER(member, Name, Type, ...) Buffer<Type> member;
  OCTORAY_ATTRIBUTES(OCTORAY_MEMBER)
#undef OCTORAY_MEMBER
  Buffer<std::uint64_t> key; // full-depth key of each point
};

// Plain pointers into PointArrays (or into a caller's positions): null
// where an array is absent.
struct PointArraysView
{
  std::size_t count = 0;
  const float* xyzFloat = nullptr;
  const double* xyzDouble = nullptr;
  const Rgba8* color8 = nullptr;
#define OCTORAY_POINTER(member, Name, Type, ...) const Type* member = nullptr;
  OCTORAY_ATTRIBUTES(OCTORAY_POINTER)
#undef OCTORAY_POINTER

  OCTORAY_HD Vec3d Position(std::size_t i) const
  {
    return xyzDouble ? Vec3d{ xyzDouble[3 * i], xyzDouble[3 * i + 1], xyzDouble[3 * i + 2] }
                     : Vec3d{ xyzFloat[3 * i], xyzFloat[3 * i + 1], xyzFloat[3 * i + 2] };
  }

  // The point's attribute vector (slots of absent attributes are left alone).
  OCTORAY_HD void Attributes(std::size_t i, float v[kSlotCount]) const
  {
    if (color8)
    {
      const Rgba8 c = color8[i]; // one load: the gather of a build's leaf pass is random
      v[kSlotColor + 0] = c.r * (1.0f / 255.0f);
      v[kSlotColor + 1] = c.g * (1.0f / 255.0f);
      v[kSlotColor + 2] = c.b * (1.0f / 255.0f);
      v[kSlotColor + 3] = c.a * (1.0f / 255.0f);
    }
    ForEachAttribute([&](auto a) {
      using A = decltype(a);
      if (A::Of(*this))
      {
        AttributeValue<typename A::Type>::ToSlots(A::Of(*this)[i], v + A::kSlot);
      }
    });
  }
};

// True when all three coordinates are finite.
OCTORAY_HD bool IsFinitePoint(const Vec3d& p)
{
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
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
