// The engine's small vector vocabulary for host and device code, as
// pbrt-v4's util/vecmath.h: 3-vectors in float (rays, normals, shading) and
// in double (camera and root-cube arithmetic), and the clamp to [0, 1].
//
// Each operator is the per-component expression written out in the order a
// hand-written loop would evaluate it (Dot sums x, y, z from the left; a
// division stays a division, never a multiplication by the reciprocal), so a
// formula written with them rounds bit for bit like the loop it replaces.
// That is what keeps the backends' pictures identical: CUDA is built with
// --fmad=false, so neither side fuses a multiply into an add.
#pragma once

#include "Config.h"

#include <cmath>
#include <type_traits>

namespace octoray
{
template <typename T>
struct Vec3
{
  T x, y, z;

  // The components as the array they are laid out as (checked below), as
  // the loops over axes indexed their arrays: the same code on both
  // compilers (branches on `a` kept GCC from inlining the slab test).
  OCTORAY_HD T operator[](int a) const { return (&x)[a]; }
  OCTORAY_HD T& operator[](int a) { return (&x)[a]; }

  // The scalar operands are of T, not deduced, so a float scalar scales a
  // Vec3d in double as the scalar code did (float * double is double).
  friend OCTORAY_HD Vec3 operator+(const Vec3& a, const Vec3& b) { return Vec3{ a.x + b.x, a.y + b.y, a.z + b.z }; }
  friend OCTORAY_HD Vec3 operator-(const Vec3& a, const Vec3& b) { return Vec3{ a.x - b.x, a.y - b.y, a.z - b.z }; }
  friend OCTORAY_HD Vec3 operator-(const Vec3& a) { return Vec3{ -a.x, -a.y, -a.z }; }
  friend OCTORAY_HD Vec3 operator*(const Vec3& a, T s) { return Vec3{ a.x * s, a.y * s, a.z * s }; }
  friend OCTORAY_HD Vec3 operator*(T s, const Vec3& a) { return Vec3{ s * a.x, s * a.y, s * a.z }; }
  // Per component: colours times weights.
  friend OCTORAY_HD Vec3 operator*(const Vec3& a, const Vec3& b) { return Vec3{ a.x * b.x, a.y * b.y, a.z * b.z }; }
  friend OCTORAY_HD Vec3 operator/(const Vec3& a, T s) { return Vec3{ a.x / s, a.y / s, a.z / s }; }
  OCTORAY_HD Vec3& operator+=(const Vec3& b) { return *this = *this + b; }
  OCTORAY_HD Vec3& operator-=(const Vec3& b) { return *this = *this - b; }
  OCTORAY_HD Vec3& operator*=(T s) { return *this = *this * s; }
  OCTORAY_HD Vec3& operator/=(T s) { return *this = *this / s; }
};

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;
static_assert(std::is_standard_layout<Vec3f>::value && sizeof(Vec3f) == 3 * sizeof(float), "x, y, z as an array");
static_assert(std::is_standard_layout<Vec3d>::value && sizeof(Vec3d) == 3 * sizeof(double), "x, y, z as an array");

template <typename T>
OCTORAY_HD T Dot(const Vec3<T>& a, const Vec3<T>& b)
{
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <typename T>
OCTORAY_HD T Length(const Vec3<T>& v)
{
  return std::sqrt(Dot(v, v));
}

// a x b, each component as the two products' difference.
template <typename T>
OCTORAY_HD Vec3<T> Cross(const Vec3<T>& a, const Vec3<T>& b)
{
  return Vec3<T>{ a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
}

// v / |v|, each component divided; zero stays zero.
template <typename T>
OCTORAY_HD Vec3<T> Normalize(const Vec3<T>& v)
{
  const T len = Length(v);
  return len > T(0) ? v / len : v;
}

// Per component, as std::min and std::max for ordered (non-NaN) values.
template <typename T>
OCTORAY_HD Vec3<T> Min(const Vec3<T>& a, const Vec3<T>& b)
{
  return Vec3<T>{ a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z };
}

template <typename T>
OCTORAY_HD Vec3<T> Max(const Vec3<T>& a, const Vec3<T>& b)
{
  return Vec3<T>{ a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z };
}

OCTORAY_HD Vec3f ToFloat(const Vec3d& v)
{
  return Vec3f{ static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z) };
}

OCTORAY_HD Vec3d ToDouble(const Vec3f& v)
{
  return Vec3d{ static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z) };
}

// v limited to [0, 1], NaN taken as 0: no NaN reaches a colour, a depth or a
// table index through a clamp.
template <typename T>
OCTORAY_HD T Clamp01(T v)
{
  return !(v > T(0)) ? T(0) : (v > T(1) ? T(1) : v);
}
}
