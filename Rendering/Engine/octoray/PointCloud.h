// The engine's input: N points with optional attributes, as plain views of
// the caller's arrays (nothing is copied until Build). The arrays are host
// memory; the CUDA backend also takes a build's arrays in device memory
// (a CUDA simulation's, points generated on the GPU) and copies them on
// the device. An update's positions and indices are host memory.
#pragma once

#include "Attributes.h"

namespace octoray
{
struct PointCloudView;

// How an attribute (Attributes.h) arrives in a PointCloudView: whether a
// cloud has it. How each becomes the engine's copy: OctreeDriver.h.
struct CopiedInput // one value per point, in the member of the attribute's name
{
  template <typename A>
  static bool Present(const PointCloudView& points)
  {
    return A::Of(points) != nullptr;
  }
};
struct ScalarInput : CopiedInput // one float per point, any value
{
};
struct UnitInput : CopiedInput // one float per point, 0..1 (others clamped)
{
};
struct UnitNormalInput : CopiedInput // 3 floats per point, of any length
{
};
struct FloatColorInput // colorFloat, of colorComponents each
{
  template <typename A>
  static bool Present(const PointCloudView& points);
};
struct ByteColorInput // color8, of colorComponents each
{
  template <typename A>
  static bool Present(const PointCloudView& points);
};

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
  const float* reflectivity = nullptr; // 0..1, the weight of the mirror ray (UnitInput)
  const float* refraction = nullptr;   // index of refraction; 0 = opaque
  const float* normal = nullptr;       // 3 values per point, need not be unit length

  // AttributeBits of the attributes given.
  unsigned Attributes() const;

  double Coordinate(std::size_t i, int axis) const
  {
    return xyzDouble ? xyzDouble[3 * i + axis] : static_cast<double>(xyzFloat[3 * i + axis]);
  }
  Vec3d Position(std::size_t i) const { return Vec3d{ Coordinate(i, 0), Coordinate(i, 1), Coordinate(i, 2) }; }
};

template <typename A>
bool FloatColorInput::Present(const PointCloudView& points)
{
  return points.colorFloat != nullptr;
}

template <typename A>
bool ByteColorInput::Present(const PointCloudView& points)
{
  return points.color8 != nullptr;
}

inline unsigned PointCloudView::Attributes() const
{
  unsigned bits = 0;
  ForEachAttribute([&](auto a) {
    using A = decltype(a);
    bits |= A::Input::template Present<A>(*this) ? A::kBit : 0u;
  });
  return bits;
}

// New positions for an update: for all points (indices == nullptr, count ==
// the octree's point count) or for the points listed in indices.
struct PositionsView
{
  std::size_t count = 0;
  const float* xyzFloat = nullptr;
  const double* xyzDouble = nullptr;
  const std::uint32_t* indices = nullptr;

  // The new position of the k-th point given.
  Vec3d Position(std::size_t k) const
  {
    return xyzDouble ? Vec3d{ xyzDouble[3 * k], xyzDouble[3 * k + 1], xyzDouble[3 * k + 2] }
                     : Vec3d{ xyzFloat[3 * k], xyzFloat[3 * k + 1], xyzFloat[3 * k + 2] };
  }
};
}
