// Small value types shared by host and device code.
#pragma once

#include "Config.h"

#include <stdexcept>
#include <string>

namespace octoray
{
struct alignas(16) Rgba
{
  float r, g, b, a;
};

struct Vec3f
{
  float x, y, z;
};

// Every error the engine reports: bad input, exhausted memory, a failed
// device call. The message says what and where (point index, array, bytes).
class Error : public std::runtime_error
{
public:
  explicit Error(const std::string& what)
    : std::runtime_error(what)
  {
  }
};

// Which optional per-point attributes a cloud carries; an octree stores
// averages only of those its input had.
enum AttributeBits : unsigned
{
  kHasColor = 1u << 0,
  kHasScalar = 1u << 1,
  kHasReflectivity = 1u << 2,
  kHasRefraction = 1u << 3,
  kHasNormal = 1u << 4,
};
}
