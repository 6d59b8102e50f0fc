// A 64-bit signature of a window depth buffer: the VTK layer traces again
// only when the opaque geometry's depth changed, and on CUDA the depth
// never leaves the device, so a signature (not the values) is what it
// keeps. Each pixel adds a mix of its index and its bits; integer sums are
// exact, so the order of a parallel reduction cannot change the result and
// both backends give the same number.
#pragma once

#include "Config.h"

#include <cstring>

namespace octoray
{
OCTORAY_HD std::uint64_t DepthSignatureTerm(float depth, std::uint64_t index)
{
  std::uint32_t bits = 0;
  memcpy(&bits, &depth, sizeof bits);
  // splitmix64's finaliser: every input bit moves about half the output.
  std::uint64_t z = (static_cast<std::uint64_t>(bits) << 32 | (index & 0xFFFFFFFFu)) + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// The signature of `count` depths in host memory.
inline std::uint64_t DepthSignature(const float* depth, std::size_t count)
{
  std::uint64_t sum = count;
  for (std::size_t i = 0; i < count; ++i)
  {
    sum += DepthSignatureTerm(depth[i], i);
  }
  return sum;
}
}
