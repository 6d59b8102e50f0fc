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

// A colour of 8-bit channels, read and written as one 4-byte word: how the
// octree and the engine's copy of the points keep colours given as 8-bit (a
// quarter of the memory of four floats).
struct alignas(4) Rgba8
{
  std::uint8_t r, g, b, a;
};

// A channel in [0,1] as a byte, rounded to nearest; the same byte on host
// and device (the device's multiply and add are spelled out so that no
// build can fuse them). Pictures and stored colours are rounded alike.
OCTORAY_HD std::uint8_t ChannelToByte(float v)
{
  v = Clamp01(v);
#if defined(__CUDA_ARCH__)
  return static_cast<std::uint8_t>(__fadd_rn(__fmul_rn(v, 255.0f), 0.5f));
#else
  return static_cast<std::uint8_t>(v * 255.0f + 0.5f);
#endif
}

OCTORAY_HD float ByteToChannel(std::uint8_t v)
{
  return v * (1.0f / 255.0f);
}

OCTORAY_HD Rgba ToRgba(Rgba8 c)
{
  return Rgba{ ByteToChannel(c.r), ByteToChannel(c.g), ByteToChannel(c.b), ByteToChannel(c.a) };
}

// Each channel rounded to a byte; ToRgba8(ToRgba(c)) is c for every byte.
OCTORAY_HD Rgba8 ToRgba8(const Rgba& c)
{
  return Rgba8{ ChannelToByte(c.r), ChannelToByte(c.g), ChannelToByte(c.b), ChannelToByte(c.a) };
}

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
