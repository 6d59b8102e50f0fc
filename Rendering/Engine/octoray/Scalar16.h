// Scalars in 16 bits, as the octree stores them: half the memory of a float.
//
// A scalar is coded relative to the range of the build's finite scalars
// (ScalarRange, kept with the octree), in kScalarSteps equal steps: its
// error is at most half a step, (hi - lo) / 131064, wherever the values lie
// in the range. That is finer than the transfer function's table (1024
// entries over the mapped range) by two orders of magnitude, and unlike a
// half float it does not lose digits for data far from zero (a pressure of
// 1000.0 to 1000.5, HU near 3000). The three codes above the steps keep
// -inf, +inf and NaN as they were, so a mean with them in it behaves as the
// float mean did.
//
// The build sums and averages the codes' unit values (code / kScalarSteps),
// not the scalars, so that its loops need no range: a mean of unit values
// is the unit value of the mean.
#pragma once

#include "Config.h"

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace octoray
{
struct alignas(2) Scalar16
{
  std::uint16_t code;
};

constexpr int kScalarSteps = 65532;
constexpr std::uint16_t kScalarMinusInfinity = 65533;
constexpr std::uint16_t kScalarPlusInfinity = 65534;
constexpr std::uint16_t kScalarNaN = 65535;

// A unit value: [0, 1] for finite scalars (clamped), or one of the three.
OCTORAY_HD Scalar16 EncodeUnitScalar(float u)
{
  if (std::isnan(u))
  {
    return Scalar16{ kScalarNaN };
  }
  if (std::isinf(u))
  {
    return Scalar16{ u > 0.0f ? kScalarPlusInfinity : kScalarMinusInfinity };
  }
  const float clamped = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
  return Scalar16{ static_cast<std::uint16_t>(floorf(clamped * kScalarSteps + 0.5f)) };
}

// EncodeUnitScalar of n values into their codes, on the host: the CUDA
// staging codes each piece of a unit-valued input (Attributes.h's
// UnitInput) as it copies it, about as fast as it would copy the floats
// (Scalar16.cpp).
void EncodeUnitScalars(const float* values, std::size_t n, std::uint16_t* codes);

OCTORAY_HD float UnitScalar(Scalar16 s)
{
  switch (s.code)
  {
    case kScalarNaN:
      return NAN; // the macros, not numeric_limits: constants in device code too
    case kScalarPlusInfinity:
      return INFINITY;
    case kScalarMinusInfinity:
      return -INFINITY;
    default:
      return static_cast<float>(s.code) / kScalarSteps;
  }
}

// The range of the build's finite scalars (lo = hi where they are all one
// value or there are none).
struct ScalarRange
{
  float lo = 0.0f, hi = 0.0f;

  // A scalar as a unit value; non-finite ones stay what they are.
  OCTORAY_HD float ToUnit(float x) const
  {
    if (!std::isfinite(x))
    {
      return x;
    }
    return hi > lo ? (x - lo) / (hi - lo) : 0.0f;
  }

  OCTORAY_HD float FromUnit(float u) const
  {
    return std::isfinite(u) ? lo + u * (hi - lo) : u;
  }

  // Half a step: the largest error of one rounding.
  double HalfStep() const { return 0.5 * (static_cast<double>(hi) - lo) / kScalarSteps; }

  // What decoding's float arithmetic adds: two roundings of a float the
  // size of the range's ends or its width (FromUnit's product and sum).
  double DecodingError() const
  {
    const double largest =
      std::fmax(std::fmax(std::fabs(double(lo)), std::fabs(double(hi))), static_cast<double>(hi) - lo);
    return largest > 0.0 ? std::ldexp(2.0, std::ilogb(largest) - 23) : 0.0;
  }
};

OCTORAY_HD float DecodeScalar(const ScalarRange& range, Scalar16 s)
{
  return range.FromUnit(UnitScalar(s));
}
}
