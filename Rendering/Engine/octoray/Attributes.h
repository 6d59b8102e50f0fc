// The octree's per-node arrays, each declared once. Storage (HostOctree and
// both backends' state), views, allocation, copies to the host, the memory
// report and the tests' comparison of two octrees are loops over these
// lists, as pbrt-v4 declares its structure-of-arrays layouts once and
// NanoVDB makes the storage a template parameter. Adding an attribute is one
// line in OCTORAY_ATTRIBUTES plus the code that gives it a meaning: its
// input array in PointCloudView and whatever reads it.
#pragma once

#include "Types.h"

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace octoray
{
// Arrays every node has, whatever the input: X(member, Name, Type, label).
//   key         the node's level-local Morton key (3 * level bits)
//   childMask   bit o set: the child in octant o exists
//   firstChild  global index of the first child; kInvalidIndex for leaves
//   parent      kInvalidIndex for the root
//   pointCount  points beneath the node
#define OCTORAY_NODE_TOPOLOGY(X)                                                                                      \
  X(key, Key, std::uint64_t, "keys")                                                                                 \
  X(childMask, ChildMask, std::uint8_t, "child masks")                                                               \
  X(firstChild, FirstChild, std::uint32_t, "first children")                                                         \
  X(parent, Parent, std::uint32_t, "parents")                                                                        \
  X(pointCount, PointCount, std::uint32_t, "point counts")

// Optional per-point attributes, each stored per node as the plain mean over
// the points beneath it, and only where the input had it:
// X(member, Name, Type, Input, label). Input says how the caller's arrays
// (PointCloudView) become the engine's: CopiedInput as given, ColorInput
// widened to RGBA, UnitNormalInput scaled to unit length (OctreeDriver.h).
// The mean of unit normals is shorter than 1 where they disagree and zero
// where they cancel. Labels name the arrays in memory reports ("node
// colours", "point colours") and out-of-memory errors.
#define OCTORAY_ATTRIBUTES(X)                                                                                         \
  X(color, Color, Rgba, ColorInput, "colours")                                                                       \
  X(scalar, Scalar, float, CopiedInput, "scalars")                                                                   \
  X(reflectivity, Reflectivity, float, CopiedInput, "reflectivities")                                                \
  X(refraction, Refraction, float, CopiedInput, "refraction indices")                                                \
  X(normal, Normal, Vec3f, UnitNormalInput, "normals")

struct CopiedInput;
struct ColorInput;
struct UnitNormalInput;

enum AttributeIndex : int
{
#define OCTORAY_ENUMERATE(member, Name, ...) kAttribute##Name,
  OCTORAY_ATTRIBUTES(OCTORAY_ENUMERATE)
#undef OCTORAY_ENUMERATE
    kAttributeCount
};

// Which attributes a cloud carries (PointCloudView::Attributes) and so which
// an octree stores.
enum AttributeBits : unsigned
{
#define OCTORAY_BIT(member, Name, ...) kHas##Name = 1u << kAttribute##Name,
  OCTORAY_ATTRIBUTES(OCTORAY_BIT)
#undef OCTORAY_BIT
};

// An attribute value as floats, the slots of the vector in which build and
// update sum it (in double) and from which they store its mean: its floats
// in order, for any value made of floats alone (float, Rgba, Vec3f).
template <typename T>
struct AttributeValue
{
  static_assert(sizeof(T) % sizeof(float) == 0 && std::is_trivially_copyable<T>::value, "a value made of floats");
  static constexpr int kSlots = static_cast<int>(sizeof(T) / sizeof(float));

  OCTORAY_HD static void ToSlots(const T& value, float* v) { memcpy(v, &value, sizeof(T)); }
  OCTORAY_HD static T Mean(const double* sum, double inv)
  {
    float mean[kSlots];
    for (int k = 0; k < kSlots; ++k)
    {
      mean[k] = static_cast<float>(sum[k] * inv);
    }
    T value;
    memcpy(&value, mean, sizeof(T));
    return value;
  }
};

// The first slot of each attribute, and kSlotCount in all.
enum AttributeSlot : int
{
#define OCTORAY_SLOTS(member, Name, Type, ...)                                                                        \
  kSlot##Name, kSlot##Name##Last = kSlot##Name + AttributeValue<Type>::kSlots - 1,
  OCTORAY_ATTRIBUTES(OCTORAY_SLOTS)
#undef OCTORAY_SLOTS
    kSlotCount
};

// Descriptors that loops receive: the array's value type, index in its
// list (attributes), presence bit (0: always present), first slot, label,
// and Of(arrays), the array of that name in any of the structures declared
// from these lists.
template <int I>
struct TopologyArray;
template <int I>
struct Attribute;

enum TopologyIndex : int
{
#define OCTORAY_ENUMERATE(member, Name, ...) kTopology##Name,
  OCTORAY_NODE_TOPOLOGY(OCTORAY_ENUMERATE)
#undef OCTORAY_ENUMERATE
};

// Of(arrays): the member of that name in any structure declared from these lists.
#define OCTORAY_ARRAY_OF(member)                                                                                      \
  template <typename Arrays>                                                                                         \
  OCTORAY_HD static auto& Of(Arrays& arrays)                                                                         \
  {                                                                                                                  \
    return arrays.member;                                                                                            \
  }

#define OCTORAY_DESCRIBE_TOPOLOGY(member, Name, Type_, label)                                                        \
  template <>                                                                                                        \
  struct TopologyArray<kTopology##Name>                                                                              \
  {                                                                                                                  \
    using Type = Type_;                                                                                              \
    static constexpr unsigned kBit = 0;                                                                              \
    static constexpr const char* kLabel = label;                                                                     \
    OCTORAY_ARRAY_OF(member)                                                                                         \
  };
OCTORAY_NODE_TOPOLOGY(OCTORAY_DESCRIBE_TOPOLOGY)
#undef OCTORAY_DESCRIBE_TOPOLOGY

#define OCTORAY_DESCRIBE_ATTRIBUTE(member, Name, Type_, Input_, label)                                               \
  template <>                                                                                                        \
  struct Attribute<kAttribute##Name>                                                                                 \
  {                                                                                                                  \
    using Type = Type_;                                                                                              \
    using Input = Input_;                                                                                            \
    static constexpr int kIndex = kAttribute##Name;                                                                  \
    static constexpr unsigned kBit = kHas##Name;                                                                     \
    static constexpr int kSlot = kSlot##Name;                                                                        \
    static constexpr const char* kLabel = label;                                                                     \
    OCTORAY_ARRAY_OF(member)                                                                                         \
  };
OCTORAY_ATTRIBUTES(OCTORAY_DESCRIBE_ATTRIBUTE)
#undef OCTORAY_DESCRIBE_ATTRIBUTE
#undef OCTORAY_ARRAY_OF

// fn(descriptor) for each attribute, in the list's order. Also called from
// host-only code with host-only functions: nvcc is told not to check those
// instantiations for device use.
#if defined(__CUDACC__)
#pragma nv_exec_check_disable
#endif
template <typename Fn>
OCTORAY_HD void ForEachAttribute(Fn&& fn)
{
#define OCTORAY_CALL(member, Name, ...) fn(Attribute<kAttribute##Name>());
  OCTORAY_ATTRIBUTES(OCTORAY_CALL)
#undef OCTORAY_CALL
}

// fn(descriptor) for every node array: the topology, then the attributes.
template <typename Fn>
void ForEachNodeArray(Fn&& fn)
{
#define OCTORAY_CALL(member, Name, ...) fn(TopologyArray<kTopology##Name>());
  OCTORAY_NODE_TOPOLOGY(OCTORAY_CALL)
#undef OCTORAY_CALL
  ForEachAttribute(fn);
}

// Whether an octree of `attributes` (AttributeBits) has the array.
template <typename Descriptor>
constexpr bool Present(Descriptor, unsigned attributes)
{
  return Descriptor::kBit == 0 || (attributes & Descriptor::kBit) != 0;
}

// One member per node array, each a Buffer<its type>: HostOctree's vectors,
// a backend's buffers.
template <template <typename> class Buffer>
struct NodeArrays
{
#define OCTORAY_MEMBER(member, Name, Type, ...) Buffer<Type> member;
  OCTORAY_NODE_TOPOLOGY(OCTORAY_MEMBER)
  OCTORAY_ATTRIBUTES(OCTORAY_MEMBER)
#undef OCTORAY_MEMBER
};
}
