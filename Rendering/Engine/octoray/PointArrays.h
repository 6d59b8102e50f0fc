// The engine's own copy of the points it was built from: positions in the
// caller's precision, attributes in compact form (one record per point),
// and each point's full-depth Morton key. Kept so that updates and
// rebuilds need no input.
#pragma once

#include "Attributes.h"
#include "Config.h"

#include <cmath>
#include <cstdint>
#include <cstring>

namespace octoray
{
// Where each attribute lies in a point's record of 4-byte words. A point's
// attributes sit side by side: the build's leaf pass reads the points in
// sorted order, which is random in memory, and a record of up to 64 bytes
// (aligned) then costs one DRAM burst where separate arrays cost one per
// attribute (Benchmarks/gpu/profile-build.txt).
struct PointRecordLayout
{
  int offset[kAttributeCount]; // first word of each attribute; -1: absent
  int stride = 0;              // words per point

  OCTORAY_HD PointRecordLayout()
  {
    for (int a = 0; a < kAttributeCount; ++a)
    {
      offset[a] = -1;
    }
  }

  // The attributes a record holds (AttributeBits).
  OCTORAY_HD unsigned Attributes() const
  {
    unsigned bits = 0;
    for (int a = 0; a < kAttributeCount; ++a)
    {
      bits |= offset[a] >= 0 ? 1u << a : 0u;
    }
    return bits;
  }
};

// The words a value of type T takes in a record: whole words, so that every
// attribute starts on one (a 16-bit scalar is padded to a word).
template <typename T>
constexpr int kWordsOf = static_cast<int>((sizeof(T) + sizeof(std::uint32_t) - 1) / sizeof(std::uint32_t));

// The words of attribute A in a record: a value of the type its nodes store.
template <class A>
constexpr int RecordWords(A)
{
  return kWordsOf<typename A::Type>;
}

// A value of type T into a point's record, its padding zero. Whole words,
// as ForEachRecordSlot reads them: a memcpy straight into the record writes
// it a byte at a time. Written at a random place a point, the bytes made
// 100 M-point stores take 20-28 ms against 9-11 on an H200
// (Benchmarks/gpu/variants-landed-records.txt, not kept); in the build's
// one record loop, in order, no difference was measured.
template <typename T>
OCTORAY_HD void StoreInRecord(std::uint32_t* records, const PointRecordLayout& layout, std::size_t i, int attribute,
  const T& value)
{
  std::uint32_t words[kWordsOf<T>] = {};
  memcpy(words, &value, sizeof(T));
  std::uint32_t* record = records + i * layout.stride + layout.offset[attribute];
  for (int w = 0; w < kWordsOf<T>; ++w)
  {
    record[w] = words[w];
  }
}

// fn(slot, value) for each slot of each attribute the record holds, of
// those in Possible (AttributeBits; the caller knows the record holds no
// others): the code of the rest is left out when compiled. The build's
// loops add up only these slots: summing every slot, absent attributes'
// zeros included, cost a conversion to double and an add per slot and point
// (with the byte-wise reads below, the leaf kernel took 1.63 ms at 100 M
// points on an H100 against 1.32: Benchmarks/gpu/variants-slots.txt).
template <unsigned Possible = kAllAttributes, typename Fn>
OCTORAY_HD void ForEachRecordSlot(const std::uint32_t* record, const PointRecordLayout& layout, Fn&& fn)
{
  ForEachAttribute([&](auto a) {
    using A = decltype(a);
    if constexpr ((Possible & A::kBit) != 0)
    {
      const int offset = layout.offset[A::kIndex];
      if (offset < 0)
      {
        return;
      }
      // Whole words: a memcpy straight from the record reads it a byte at a time.
      std::uint32_t words[kWordsOf<typename A::Type>];
      for (int w = 0; w < kWordsOf<typename A::Type>; ++w)
      {
        words[w] = record[offset + w];
      }
      typename A::Type value;
      memcpy(&value, words, sizeof value);
      ForEachSlotOf(a, value, fn);
    }
  });
}

// The point arrays a backend holds, each a Buffer<its type>.
template <template <typename> class Buffer>
struct PointArrays
{
  Buffer<float> xyzFloat; // exactly one of the two, 3 values per point
  Buffer<double> xyzDouble;
  Buffer<std::uint32_t> records; // the attributes, layout.stride words per point
  PointRecordLayout layout;
};

// Plain pointers into PointArrays (or into a caller's positions): null
// where an array is absent.
struct PointArraysView
{
  std::size_t count = 0;
  const float* xyzFloat = nullptr;
  const double* xyzDouble = nullptr;
  const std::uint32_t* records = nullptr;
  PointRecordLayout layout;

  OCTORAY_HD Vec3d Position(std::size_t i) const
  {
    return xyzDouble ? Vec3d{ xyzDouble[3 * i], xyzDouble[3 * i + 1], xyzDouble[3 * i + 2] }
                     : Vec3d{ xyzFloat[3 * i], xyzFloat[3 * i + 1], xyzFloat[3 * i + 2] };
  }

  OCTORAY_HD const std::uint32_t* Record(std::size_t i) const { return records + i * layout.stride; }
};

// True when all three coordinates are finite.
OCTORAY_HD bool IsFinitePoint(const Vec3d& p)
{
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// Unit normal of a caller's normal; zero stays zero (it carries no direction).
OCTORAY_HD Vec3f UnitNormal(float x, float y, float z)
{
  const float len2 = x * x + y * y + z * z;
  if (!(len2 > 0.0f) || !std::isfinite(len2))
  {
    return Vec3f{ 0.0f, 0.0f, 0.0f };
  }
  const float inv = 1.0f / std::sqrt(len2);
  return Vec3f{ x * inv, y * inv, z * inv };
}
}
