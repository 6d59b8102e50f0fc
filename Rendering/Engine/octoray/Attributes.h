// The octree's per-node arrays, each declared once. Storage (HostOctree and
// both backends' state), views, allocation, copies to the host, the memory
// report and the tests' comparison of two octrees are loops over these
// lists, as pbrt-v4 declares its structure-of-arrays layouts once and
// NanoVDB makes the storage a template parameter. Adding an attribute is one
// line in OCTORAY_ATTRIBUTES plus the code that gives it a meaning: its
// input array in PointCloudView and whatever reads it.
#pragma once

#include "Morton.h"
#include "OctahedralNormal.h"
#include "Scalar16.h"
#include "Types.h"

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace octoray
{
// Arrays every node has, whatever the input: X(member, Name, Type,
// nodesPerEntry, fromDepth, label), in octrees of fromDepth levels and more.
//   key         the node's level-local Morton key (3 * level bits), its low
//               32 bits
//   keyHigh     its high 32 bits, in octrees deeper than 10 levels alone:
//               above, keys of 64 bits took 8 bytes a node where the keys of
//               every level fit 4, and the level phase, which then wrote
//               each node's key once and read it twice (a select, the
//               parent's loop), took 20 % longer at 100 M points
//               (Benchmarks/gpu/variants-node-keys.txt)
//   childMasks  each node's child mask (bit o set: the child in octant o
//               exists), eight nodes' to a word: node n's is byte n % 8 of
//               word n / 8 (the last word's spare bytes zero)
//   childBase   for each group of eight nodes, the global index of the first
//               node's first child
//   pointCount  points beneath the node
// Child and parent links are implicit. Children are stored level by level
// in the order of their parents, so node n's first child is 1 plus the
// children of every node before it: its group's childBase plus the bits of
// the masks before n in the same word (FirstChildOf, Octree.h). That is
// half a byte a node where a 32-bit link took 4. A node's parent is the node
// one level up whose key is this node's shifted by one octant
// (OctreeView::Find).
#define OCTORAY_NODE_TOPOLOGY(X)                                                                                      \
  X(key, Key, std::uint32_t, 1, 0, "keys")                                                                           \
  X(keyHigh, KeyHigh, std::uint32_t, 1, kWideKeyDepth, "keys' high words")                                           \
  X(childMasks, ChildMasks, std::uint64_t, 8, 0, "child masks")                                                      \
  X(childBase, ChildBase, std::uint32_t, 8, 0, "first children")                                                     \
  X(pointCount, PointCount, std::uint32_t, 1, 0, "point counts")

// The shallowest octree whose deepest keys (3 bits a level) pass 32 bits.
constexpr int kWideKeyDepth = 11;
static_assert(!KeysFitWord(kWideKeyDepth) && KeysFitWord(kWideKeyDepth - 1), "one word up to kWideKeyDepth");

// Node n's level-local key from its low and (where stored) high words.
OCTORAY_HD std::uint64_t NodeKey(const std::uint32_t* low, const std::uint32_t* high, std::size_t n)
{
  return (high ? std::uint64_t{ high[n] } << 32 : 0u) | low[n];
}

// Optional per-point attributes, each stored per node as the plain mean over
// the points beneath it, and only where the input had it:
// X(member, Name, Type, Input, label). Input says how the caller's arrays
// (PointCloudView) become the engine's: CopiedInput as given, the colour
// inputs as RGBA in the caller's precision (floats, HDR allowed, or bytes: a
// quarter of the memory, the means rounded to bytes), ScalarInput in 16 bits
// over the build's range (Scalar16.h), UnitInput clamped to 0..1 and rounded
// to Scalar16's unit steps (at most 7.6e-6 off, far below what a mirror
// weight shows in an 8-bit picture; means of those values stored as
// floats), so that its staged copy moves 2 bytes a point where the caller's
// floats take 4, UnitNormalInput scaled to unit length (OctreeDriver.h) and
// stored in one word (OctahedralNormal.h).
// The mean of unit normals is shorter than 1 where they disagree and zero
// where they cancel. Labels name the arrays in memory reports ("node
// colours", "point colours") and out-of-memory errors.
#define OCTORAY_ATTRIBUTES(X)                                                                                         \
  X(color, Color, Rgba, FloatColorInput, "colours")                                                                  \
  X(color8, Color8, Rgba8, ByteColorInput, "8-bit colours")                                                          \
  X(scalar, Scalar, Scalar16, ScalarInput, "scalars")                                                                \
  X(reflectivity, Reflectivity, float, UnitInput, "reflectivities")                                                  \
  X(refraction, Refraction, float, CopiedInput, "refraction indices")                                                \
  X(normal, Normal, OctNormal, UnitNormalInput, "normals")

struct CopiedInput;
struct ScalarInput;
struct UnitInput;
struct FloatColorInput;
struct ByteColorInput;
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
    kAllAttributes = (1u << kAttributeCount) - 1
};

// An attribute value summed as Slots floats, from whose means the node's
// value is made: a value made of floats alone (float, Rgba, Vec3f) is its
// floats in order, its mean stored as computed; a value stored Rounded is
// summed as the floats its ToFloats gives and stored as FromFloats of
// their means (8-bit colours alike, as whole bytes: below). A rounded
// leaf's mean is rounded once; an inner node's is the count-weighted mean
// of its children's rounded ones, rounded again (the bounds below). Being
// rounded, such a mean cannot be adjusted by the points that leave and
// join a node (an update's in-place path): the rounding would be carried
// into the new mean, multiplied where a node loses most of its points.
template <typename T, int Slots, bool Rounded>
struct FloatSlotsValue
{
  static constexpr int kSlots = Slots;
  static constexpr bool kRounded = Rounded;
  using Slot = float;

  OCTORAY_HD static void ToSlots(const T& value, float* v)
  {
    if constexpr (Rounded)
    {
      ToFloats(value, v);
    }
    else
    {
      memcpy(v, &value, sizeof(T));
    }
  }
  template <typename Real>
  OCTORAY_HD static T Mean(const Real* sum, double inv)
  {
    float mean[Slots];
    for (int k = 0; k < Slots; ++k)
    {
      mean[k] = static_cast<float>(sum[k] * inv);
    }
    T value;
    if constexpr (Rounded)
    {
      FromFloats(mean, value);
    }
    else
    {
      memcpy(&value, mean, sizeof(T));
    }
    return value;
  }
};

// An attribute value as its slots (Slot: float, or whole bytes), the
// entries of the sums in which build and update add it up (SlotSums below)
// and from which they store its mean: its floats, for any value made of
// floats alone; scalars, normals and 8-bit colours below.
template <typename T>
struct AttributeValue : FloatSlotsValue<T, static_cast<int>(sizeof(T) / sizeof(float)), false>
{
  static_assert(sizeof(T) % sizeof(float) == 0 && std::is_trivially_copyable<T>::value, "a value made of floats");
};

// Scalars: their unit values, stored as codes (Scalar16.h); the points'
// values are rounded too (ScalarErrorBound).
OCTORAY_HD void ToFloats(const Scalar16& value, float* v)
{
  v[0] = UnitScalar(value);
}
OCTORAY_HD void FromFloats(const float* v, Scalar16& value)
{
  value = EncodeUnitScalar(v[0]);
}

// Normals: three floats, stored on the octahedron (NormalErrorBound).
OCTORAY_HD void ToFloats(const OctNormal& value, float* v)
{
  const Vec3f n = DecodeNormal(value);
  v[0] = n.x, v[1] = n.y, v[2] = n.z;
}
OCTORAY_HD void FromFloats(const float* v, OctNormal& value)
{
  value = EncodeNormal(Vec3f{ v[0], v[1], v[2] });
}

// 8-bit colours, stored rounded as the others above: their channels are
// summed as whole bytes (a leaf's in 64-bit integers: SlotSums) and the mean
// rounded to the nearest byte (halves up). A leaf's sums are exact, in any
// order, and a byte needs no conversion to add, where as a float in [0,1]
// summed in double each channel of each point took two. The leaf loop was
// little faster for it on an H100, 174 us at 10 M points against 177
// (Benchmarks/gpu/variants-unkept-keys.txt): the conversions were not what
// bounds it.
template <>
struct AttributeValue<Rgba8>
{
  static constexpr int kSlots = 4;
  static constexpr bool kRounded = true;
  using Slot = std::uint32_t;

  OCTORAY_HD static void ToSlots(const Rgba8& c, std::uint32_t* v)
  {
    v[0] = c.r, v[1] = c.g, v[2] = c.b, v[3] = c.a;
  }
  template <typename Sum>
  OCTORAY_HD static Rgba8 Mean(const Sum* sum, double inv)
  {
    std::uint8_t mean[4];
    for (int k = 0; k < 4; ++k)
    {
      const double byte = static_cast<double>(sum[k]) * inv;
      mean[k] = static_cast<std::uint8_t>((byte < 255.0 ? byte : 255.0) + 0.5);
    }
    return Rgba8{ mean[0], mean[1], mean[2], mean[3] };
  }
};
template <>
struct AttributeValue<Scalar16> : FloatSlotsValue<Scalar16, 1, true>
{
};
template <>
struct AttributeValue<OctNormal> : FloatSlotsValue<OctNormal, 3, true>
{
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

// The sums of a node's slots, each slot's value times a weight (a child's
// point count, 1 for a point, -1 for a point that leaves). Floats add up in
// Real: double for a leaf's points and an update's changes, float for an
// inner node's children (OctreeKernels.h). Whole bytes beside double sums
// add up in 64-bit integers, exact in any order (a weight of -1 wraps, and
// the sum comes right modulo 2^64); beside float sums in float, as the
// children's other slots: in 64-bit integers the inner loop held 48
// registers on an H100 where it holds 40, five blocks a multiprocessor
// instead of six. Of the entries, only those of the slots added to live.
template <typename Real>
struct SlotSums
{
  using Whole = typename std::conditional<std::is_same<Real, double>::value, std::uint64_t, float>::type;
  Real real[kSlotCount] = {};
  Whole whole[kSlotCount] = {};

  template <typename Weight>
  OCTORAY_HD void Add(int k, float x, Weight weight)
  {
    real[k] += x * static_cast<Real>(weight);
  }
  template <typename Weight>
  OCTORAY_HD void Add(int k, std::uint32_t x, Weight weight)
  {
    whole[k] += static_cast<Whole>(x) * static_cast<Whole>(weight);
  }
  // The entries of the slots of attribute a, as its Mean reads them.
  template <class A>
  OCTORAY_HD auto Of(A) const
  {
    if constexpr (std::is_same<typename AttributeValue<typename A::Type>::Slot, float>::value)
    {
      return real + A::kSlot;
    }
    else
    {
      return whole + A::kSlot;
    }
  }
};

// The largest difference between a node's stored 8-bit colour channel at
// `level` and the exact mean of its points' channels: half a step (of 1/255)
// at the leaves, half a step more for each level up.
OCTORAY_HD constexpr double ColourErrorBound(int depth, int level)
{
  return 0.5 * (depth - level + 1) / 255.0;
}

// The largest distance between a node's stored normal at `level` and the
// exact mean of its points' unit normals: the points' own rounding (each
// stored as its code, OctahedralNormal.h), a rounding at the leaves, one
// more for each level up.
OCTORAY_HD constexpr double NormalErrorBound(int depth, int level)
{
  return kOctDirectionError + (depth - level + 1) * kOctVectorError;
}

// The largest difference between a node's decoded scalar at `level` and the
// exact mean of its points' scalars (finite ones, in the build's `range`):
// half a step for the points' codes, the leaf's mean and each level up, and
// the float rounding of decoding.
inline double ScalarErrorBound(const ScalarRange& range, int depth, int level)
{
  return (depth - level + 2) * range.HalfStep() + range.DecodingError();
}

// The attributes (AttributeBits) whose node means are stored rounded.
#define OCTORAY_ROUNDED_BIT(member, Name, Type, ...) (AttributeValue<Type>::kRounded ? kHas##Name : 0u) |
constexpr unsigned kRoundedAttributes = OCTORAY_ATTRIBUTES(OCTORAY_ROUNDED_BIT) 0u;
#undef OCTORAY_ROUNDED_BIT

// Descriptors that loops receive: the array's value type, index in its
// list (attributes), presence bit (0: always present), the depth from which
// octrees have it, first slot, label,
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

#define OCTORAY_DESCRIBE_TOPOLOGY(member, Name, Type_, nodesPerEntry, fromDepth, label)                              \
  template <>                                                                                                        \
  struct TopologyArray<kTopology##Name>                                                                              \
  {                                                                                                                  \
    using Type = Type_;                                                                                              \
    static constexpr unsigned kBit = 0;                                                                              \
    static constexpr int kFromDepth = fromDepth;                                                                     \
    static constexpr std::size_t kNodesPerEntry = nodesPerEntry;                                                     \
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
    static constexpr int kFromDepth = 0;                                                                             \
    static constexpr int kSlot = kSlot##Name;                                                                        \
    static constexpr std::size_t kNodesPerEntry = 1;                                                                 \
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

// fn(slot, value) for each slot of a value of attribute a (a descriptor),
// the value a float or a whole byte (AttributeValue::Slot). `value` is a
// copy of the stored one: ToSlots's memcpy straight from an array reads it
// a byte at a time.
template <class A, typename Fn>
OCTORAY_HD void ForEachSlotOf(A, const typename A::Type& value, Fn&& fn)
{
  using Value = AttributeValue<typename A::Type>;
  typename Value::Slot v[Value::kSlots];
  Value::ToSlots(value, v);
  for (int k = 0; k < Value::kSlots; ++k)
  {
    fn(A::kSlot + k, v[k]);
  }
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

// Entries of the array in an octree of `nodes` nodes (of those present).
template <typename Descriptor>
constexpr std::size_t EntriesFor(Descriptor, std::size_t nodes)
{
  return (nodes + Descriptor::kNodesPerEntry - 1) / Descriptor::kNodesPerEntry;
}

// Whether an octree of `attributes` (AttributeBits) and `depth` has the array.
template <typename Descriptor>
constexpr bool Present(Descriptor, unsigned attributes, int depth)
{
  return (Descriptor::kBit == 0 || (attributes & Descriptor::kBit) != 0) && depth >= Descriptor::kFromDepth;
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
