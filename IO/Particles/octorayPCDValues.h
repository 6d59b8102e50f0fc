// PCD values into VTK's array types, without VTK: a field's values of the
// declared type (I, U, F of 1 to 8 bytes) converted to float or double, and
// packed rgb / rgba colours split into bytes. vtkPCDReader converts with
// these. Private to the module; not wrapped.
#ifndef octorayPCDValues_h
#define octorayPCDValues_h

#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

namespace octoray
{
namespace pcd
{
static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE floats are assumed");

// A float from a double, out-of-range values becoming +-infinity (a plain
// conversion of those is undefined behaviour).
template <typename Out>
inline Out Narrow(double v)
{
  if (std::is_same<Out, float>::value && std::isfinite(v) && std::fabs(v) > FLT_MAX)
  {
    return static_cast<Out>(v > 0 ? std::numeric_limits<float>::infinity()
                                  : -std::numeric_limits<float>::infinity());
  }
  return static_cast<Out>(v);
}

template <typename T, typename Out>
inline void GatherAs(const unsigned char* base, size_t stride, size_t n, Out* out, size_t outStride)
{
  for (size_t i = 0; i < n; ++i)
  {
    T v;
    std::memcpy(&v, base + i * stride, sizeof(T));
    if (std::is_same<T, double>::value)
    {
      out[i * outStride] = Narrow<Out>(static_cast<double>(v));
    }
    else
    {
      out[i * outStride] = static_cast<Out>(v);
    }
  }
}

// out[i * outStride] = value i, read at base + i * stride as the declared
// type (a field's values of n points, or one component of them).
template <typename Out>
inline void Gather(
  char type, int size, const unsigned char* base, size_t stride, size_t n, Out* out, size_t outStride)
{
  switch (type == 'F' ? size : type == 'I' ? -size : 16 + size)
  {
    case 4:
      GatherAs<float>(base, stride, n, out, outStride);
      break;
    case 8:
      GatherAs<double>(base, stride, n, out, outStride);
      break;
    case -1:
      GatherAs<int8_t>(base, stride, n, out, outStride);
      break;
    case -2:
      GatherAs<int16_t>(base, stride, n, out, outStride);
      break;
    case -4:
      GatherAs<int32_t>(base, stride, n, out, outStride);
      break;
    case -8:
      GatherAs<int64_t>(base, stride, n, out, outStride);
      break;
    case 17:
      GatherAs<uint8_t>(base, stride, n, out, outStride);
      break;
    case 18:
      GatherAs<uint16_t>(base, stride, n, out, outStride);
      break;
    case 20:
      GatherAs<uint32_t>(base, stride, n, out, outStride);
      break;
    case 24:
      GatherAs<uint64_t>(base, stride, n, out, outStride);
      break;
    default:
      break; // ParseHeader admits no other combination
  }
}

// Packed colours: the 4 bytes of an rgb / rgba value (float or uint32 in the
// file, the same bits) are 0xAARRGGBB as a little-endian uint32.
inline void UnpackColors(
  const unsigned char* base, size_t stride, size_t n, unsigned char* out, int components)
{
  for (size_t i = 0; i < n; ++i)
  {
    uint32_t v;
    std::memcpy(&v, base + i * stride, 4);
    unsigned char* o = out + i * static_cast<size_t>(components);
    o[0] = static_cast<unsigned char>(v >> 16);
    o[1] = static_cast<unsigned char>(v >> 8);
    o[2] = static_cast<unsigned char>(v);
    if (components == 4)
    {
      o[3] = static_cast<unsigned char>(v >> 24);
    }
  }
}

} // namespace pcd
} // namespace octoray

#endif
