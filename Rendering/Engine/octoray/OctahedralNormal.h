// Normals in one 4-byte word, as the octree stores them: a third of the
// memory of three floats.
//
// A node's normal is the mean of its points' unit normals (Attributes.h),
// a vector no longer than 1: shorter where the normals disagree, zero where
// they cancel. Its direction goes on the octahedron (Cigolle et al., "A
// Survey of Efficient Representations for Independent Unit Vectors", JCGT
// 2014): the unit sphere projected onto |x| + |y| + |z| = 1, the lower half
// folded over the upper, flattened onto the square [-1, 1]^2, 12 bits per
// coordinate. Its length takes the other 8 bits. The length matters beyond
// the zero test of shading: an inner node's mean is the count-weighted mean
// of its children's, and a child whose normals disagree must weigh less.
//
// Encoding and decoding are plain float arithmetic with no fused
// multiply-add (--fmad=false on CUDA), so both backends store the same bits.
#pragma once

#include "VecMath.h"

#include <cstdint>

namespace octoray
{
struct alignas(4) OctNormal
{
  std::uint32_t bits; // u: bits 0-11, v: bits 12-23, length: bits 24-31
};

// Grid steps across [-1, 1]: an even count, so that 0 (the axes and the
// fold's edges) lies on the grid, and a coordinate's code is symmetric
// about it: -u decodes to exactly minus u's value.
constexpr int kOctSteps = 4094;
constexpr int kOctHalfSteps = kOctSteps / 2;
constexpr int kLengthSteps = 255;

// The largest angle, in radians, between a direction and its decoded code.
// Rounding moves (u, v) by at most half a step (1 / kOctSteps) per
// coordinate, so by sqrt(2) / kOctSteps; the octahedron's point moves by at
// most twice that (the folded half stretches (u, v) by up to 2), and it
// lies at least 1/sqrt(3) from the centre, which turns a move into an angle
// of at most sqrt(3) times its length: 2 sqrt(6) / kOctSteps in all.
constexpr double kOctDirectionError = 2.0 * 2.449489742783178 / kOctSteps;
// The largest distance between a vector no longer than 1 and its decoded
// code: the direction's angle, plus half a step of the length.
constexpr double kOctVectorError = kOctDirectionError + 0.5 / kLengthSteps;

// The lower hemisphere's fold: the triangle beyond |u| + |v| = 1 mirrored
// onto the one inside it (its own inverse).
OCTORAY_HD void FoldOctahedron(float& u, float& v)
{
  const float fu = (1.0f - fabsf(v)) * (u >= 0.0f ? 1.0f : -1.0f);
  const float fv = (1.0f - fabsf(u)) * (v >= 0.0f ? 1.0f : -1.0f);
  u = fu;
  v = fv;
}

// x in [0, 1] on a grid of `steps`, rounded to nearest, at bit `shift`.
OCTORAY_HD std::uint32_t RoundToGrid(float x, int steps, int shift)
{
  return static_cast<std::uint32_t>(floorf(x * steps + 0.5f)) << shift;
}

// A coordinate u in [-1, 1] and its 12-bit code.
OCTORAY_HD std::uint32_t OctCode(float u, int shift)
{
  return static_cast<std::uint32_t>(floorf(u * kOctHalfSteps + 0.5f) + kOctHalfSteps) << shift;
}

OCTORAY_HD float OctCoordinate(std::uint32_t bits, int shift)
{
  return (static_cast<float>((bits >> shift) & 0xFFFu) - kOctHalfSteps) / kOctHalfSteps;
}

// n, of length at most 1 (longer is taken as 1); vectors shorter than half a
// length step are stored as zero.
OCTORAY_HD OctNormal EncodeNormal(const Vec3f& n)
{
  const float length = Length(n);
  const std::uint32_t lengthBits = RoundToGrid(length < 1.0f ? length : 1.0f, kLengthSteps, 24);
  if (lengthBits == 0)
  {
    return OctNormal{ 0 };
  }
  const float l1 = fabsf(n.x) + fabsf(n.y) + fabsf(n.z);
  float u = n.x / l1, v = n.y / l1;
  if (n.z < 0.0f)
  {
    FoldOctahedron(u, v);
  }
  return OctNormal{ OctCode(u, 0) | OctCode(v, 12) | lengthBits };
}

OCTORAY_HD Vec3f DecodeNormal(OctNormal e)
{
  const std::uint32_t lengthBits = e.bits >> 24;
  if (lengthBits == 0)
  {
    return Vec3f{ 0.0f, 0.0f, 0.0f };
  }
  float u = OctCoordinate(e.bits, 0), v = OctCoordinate(e.bits, 12);
  const float z = 1.0f - fabsf(u) - fabsf(v);
  if (z < 0.0f)
  {
    FoldOctahedron(u, v);
  }
  return Normalize(Vec3f{ u, v, z }) * (static_cast<float>(lengthBits) / kLengthSteps);
}
}
