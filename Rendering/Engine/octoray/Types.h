// Small value types shared by host and device code.
#pragma once

#include "Config.h"
#include "VecMath.h"

#include <stdexcept>
#include <string>

namespace octoray
{
struct alignas(16) Rgba
{
  float r, g, b, a;
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
