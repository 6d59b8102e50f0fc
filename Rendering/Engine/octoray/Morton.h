// 63-bit Morton keys: 21 bits per axis, x in the lowest bit of each triple.
#pragma once

#include "Config.h"

namespace octoray
{
// The lowest and the highest set bit of bits != 0 (of keys, of child masks).
OCTORAY_HD_INLINE unsigned LowestBit(unsigned bits)
{
#if defined(__CUDA_ARCH__)
  return static_cast<unsigned>(__ffs(static_cast<int>(bits)) - 1);
#else
  return static_cast<unsigned>(__builtin_ctz(bits));
#endif
}

OCTORAY_HD_INLINE int HighestBit(std::uint32_t bits)
{
#if defined(__CUDA_ARCH__)
  return 31 - __clz(static_cast<int>(bits));
#else
  return 31 - __builtin_clz(bits);
#endif
}

OCTORAY_HD_INLINE int HighestBit(std::uint64_t bits)
{
#if defined(__CUDA_ARCH__)
  return 63 - __clzll(static_cast<long long>(bits));
#else
  return 63 - __builtin_clzll(bits);
#endif
}

// Spreads the low 21 bits of v so that bit i lands on bit 3i.
OCTORAY_HD std::uint64_t SpreadBits3(std::uint64_t v)
{
  v &= 0x1FFFFFull;
  v = (v | (v << 32)) & 0x1F00000000FFFFull;
  v = (v | (v << 16)) & 0x1F0000FF0000FFull;
  v = (v | (v << 8)) & 0x100F00F00F00F00Full;
  v = (v | (v << 4)) & 0x10C30C30C30C30C3ull;
  v = (v | (v << 2)) & 0x1249249249249249ull;
  return v;
}

// Inverse of SpreadBits3: gathers bits 0, 3, 6, ... into the low 21 bits.
OCTORAY_HD std::uint32_t CompactBits3(std::uint64_t v)
{
  v &= 0x1249249249249249ull;
  v = (v ^ (v >> 2)) & 0x10C30C30C30C30C3ull;
  v = (v ^ (v >> 4)) & 0x100F00F00F00F00Full;
  v = (v ^ (v >> 8)) & 0x1F0000FF0000FFull;
  v = (v ^ (v >> 16)) & 0x1F00000000FFFFull;
  v = (v ^ (v >> 32)) & 0x1FFFFFull;
  return static_cast<std::uint32_t>(v);
}

OCTORAY_HD std::uint64_t EncodeMorton(std::uint32_t x, std::uint32_t y, std::uint32_t z)
{
  return SpreadBits3(x) | (SpreadBits3(y) << 1) | (SpreadBits3(z) << 2);
}

// Whether keys of `depth` levels (3 bits a level) fit a 32-bit word: depth
// 10 and less. The build sorts such keys as words (SortedKeys::Narrow) and
// stores its nodes' keys in one word (Attributes.h's kWideKeyDepth).
OCTORAY_HD constexpr bool KeysFitWord(int depth)
{
  return 3 * depth <= 32;
}

// SpreadBits3 of the low 10 bits, in 32-bit arithmetic.
OCTORAY_HD std::uint32_t SpreadBits3Narrow(std::uint32_t v)
{
  v &= 0x3FFu;
  v = (v | (v << 16)) & 0x030000FFu;
  v = (v | (v << 8)) & 0x0300F00Fu;
  v = (v | (v << 4)) & 0x030C30C3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

// The key at `depth` levels of full-depth cell (x, y, z): EncodeMorton's key
// without its triples below that depth, made from the cell's top bits
// alone, in 32-bit arithmetic where the key fits (depth 10 and less). On
// an H100 the build's keys of 100 M points at depth 10 took 567 us so,
// against 703 made at full depth and shifted
// (Benchmarks/gpu/variants-unkept-keys.txt).
OCTORAY_HD std::uint64_t EncodeMortonAt(std::uint32_t x, std::uint32_t y, std::uint32_t z, int depth)
{
  const int below = kMaxLevel - depth;
  x >>= below, y >>= below, z >>= below;
  if (KeysFitWord(depth))
  {
    return SpreadBits3Narrow(x) | (SpreadBits3Narrow(y) << 1) | (SpreadBits3Narrow(z) << 2);
  }
  return EncodeMorton(x, y, z);
}

OCTORAY_HD void DecodeMorton(std::uint64_t key, std::uint32_t& x, std::uint32_t& y, std::uint32_t& z)
{
  x = CompactBits3(key);
  y = CompactBits3(key >> 1);
  z = CompactBits3(key >> 2);
}

// The key of the level-`level` ancestor of a full-depth (level 21) key.
OCTORAY_HD std::uint64_t AncestorKey(std::uint64_t fullKey, int level)
{
  return fullKey >> (3 * (kMaxLevel - level));
}

// Which of its parent's eight octants a node occupies (bit 0: +x, 1: +y, 2: +z).
OCTORAY_HD int OctantOf(std::uint64_t key)
{
  return static_cast<int>(key & 7u);
}
}
