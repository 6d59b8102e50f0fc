// Small value types shared by host and device code.
#pragma once

#include "Config.h"
#include "VecMath.h"

#include <cstdint>
#include <stdexcept>
#include <string>

namespace octoray
{
struct alignas(16) Rgba
{
  float r, g, b, a;
};

// A colour of 8-bit channels, read and written as one 4-byte word.
struct alignas(4) Rgba8
{
  std::uint8_t r, g, b, a;
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
}
