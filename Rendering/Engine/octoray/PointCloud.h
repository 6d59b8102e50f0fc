// The engine's input: N points with optional attributes, as plain views of
// the caller's arrays (nothing is copied until Build).
#pragma once

#include "Types.h"

namespace octoray
{
struct PointCloudView
{
  std::size_t count = 0;
  // Exactly one of the two position arrays, 3 values per point.
  const float* xyzFloat = nullptr;
  const double* xyzDouble = nullptr;

  // Colour as 8-bit (0..255) or float (0..1, HDR allowed), 3 or 4 components.
  const std::uint8_t* color8 = nullptr;
  const float* colorFloat = nullptr;
  int colorComponents = 0;

  const float* scalar = nullptr;
  const float* reflectivity = nullptr; // 0..1, the weight of the mirror ray
  const float* refraction = nullptr;   // index of refraction; 0 = opaque
  const float* normal = nullptr;       // 3 values per point, need not be unit length

  unsigned Attributes() const
  {
    unsigned bits = 0;
    bits |= (color8 || colorFloat) ? kHasColor : 0u;
    bits |= scalar ? kHasScalar : 0u;
    bits |= reflectivity ? kHasReflectivity : 0u;
    bits |= refraction ? kHasRefraction : 0u;
    bits |= normal ? kHasNormal : 0u;
    return bits;
  }

  double Coordinate(std::size_t i, int axis) const
  {
    return xyzDouble ? xyzDouble[3 * i + axis] : static_cast<double>(xyzFloat[3 * i + axis]);
  }
};

// New positions for an update: for all points (indices == nullptr, count ==
// the octree's point count) or for the points listed in indices.
struct PositionsView
{
  std::size_t count = 0;
  const float* xyzFloat = nullptr;
  const double* xyzDouble = nullptr;
  const std::uint32_t* indices = nullptr;
};
}
