// The build and the update of the octree, written once for both backends
// against a small device interface, as pbrt-v4 writes its integrators once
// over ParallelFor and GPUParallelFor. A device (CpuDevice.h, CudaDevice.h)
// differs from the other only in where memory lives and how loops run:
//
//   Buffer<T>                         an owning array: Get(), Count(), Bytes(), Empty()
//   Reserve(buffer, n, what)          room for n, kept while it fits; `what` names it in an out-of-memory error
//   Release(buffer)
//   StageReduced(host, n, stride, what, identity, map, combine, result, prepareAlong, whenReduced)
//                                     a caller's array where loops read it (the array itself on the CPU, a copy
//                                     on CUDA), and combine over map(i, host) for every item i of `stride`
//                                     elements into result: on CUDA once the copy has landed;
//                                     prepareAlong(fills), called once its memory is taken, adds copies
//                                     (Prepare's) that go in the same pass; whenReduced(result, staged) runs
//                                     once this array has landed where those are still on their way (CUDA's
//                                     staged copy), else not at all
//   Prepare(host, n, what, fills)     room for another caller's array, whose copy it adds to fills (CUDA)
//   Adopt(staged, buffer, n)          a staged array becomes the buffer's content (copied, or taken over)
//   Upload, Download, ToHost, FillBytes   copies in and out, a memset
//   QueueToHost(data, n, what), WaitToHost(host, what)   a copy of n 64-bit words to the host that the host
//                                     waits for only in WaitToHost, queuing more work meanwhile
//   ForEach(name, n, fn)              fn(i) for i in [0, n); on CUDA the kernel `name` (FaultInjection.h), at
//                                     the blocks a multiprocessor fn asks for where it is Occupying (Config.h)
//   Reduce(n, identity, map, combine) combine over every map(i), returned to the host
//   Select(n, selected, out, count)   the i in [0, n) with selected(i), in order; their count into *count
//   CountNested(name, n, lists, firstList, tally, counts, side)   nested selections: i in [0, n) belongs to
//                                     every list from firstList(i) to lists - 1 (none where firstList(i) >=
//                                     lists); counts[f] += the items of first list f, and `tally` (a 32-bit
//                                     buffer) what PlaceNested needs; in the same pass, a SideHistogram
//                                     (Config.h), if given
//   PlaceNested(name, n, firstList, tally, counted, out)   the first out.count of the `counted` lists, in
//                                     order, into the NestedLists `out`: the last holds the items, list l <
//                                     out.count - 1 each item's place in list l + 1 (written only where out's
//                                     room holds them), and after its items each list the size of the next
//                                     (the last: n)
//   SortPairs(keys[2], values[2], n, bits, what)   stable; returns which of the two arrays holds the result
//                                     (64-bit keys with 32-bit values; 32-bit keys with 32- or 64-bit values)
//   SortPairsFrom(keys[2], valuesIn, valuesOut, n, bits, what)   the same, the values read from valuesIn (left as
//                                     it is) and written in sorted order to valuesOut
//   SortKeys(keys[2], n, bits, what)  the keys alone; stable, returns the same
//   Synchronize(what)                 waits for the loops so far; a fault among them is reported as `what`'s
//   Clock                             Mark(): a point in the order of the loops; Seconds(a, b) once waited for
//   ReleaseScratch()                  frees the device's own scratch (CUB's temporary storage)
//   CachedBytes(), TrimCache()        freed memory the device keeps for reuse; giving it back
//   Scope()                           makes the device current while the returned object lives
//   kBuildsAside                      whether a build fills a new state aside (each device says why)
//
// Loops capture what they use by value (OCTORAY_LAMBDA): views and plain
// pointers, never the state or a device. One algorithm per step on both
// backends, so they build the same octree node for node; where the host
// must see a result (a check, the level sizes) it is one copy, named below.
#pragma once

#include "DepthChoice.h"
#include "OctreeKernels.h"
#include "OctreeState.h"
#include "Validation.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <iterator>
#include <memory>
#include <string>
#include <type_traits>

namespace octoray
{
// The in-place update writes, sorts and reduces 2 (depth + 1) records per
// point that changed leaf, where the re-sort path sorts one key per point:
// past a sixteenth of the points (for a depth-7 octree, where the records
// then outnumber the points) the re-sort costs less, and the update takes it.
constexpr std::size_t kInPlaceUpdateShare = 16;

// Where loops report to the host, in DriverScratch::counters.
enum CounterSlot : int
{
  kCounterHistogram = 0,                                        // DepthChoice's two histograms
  kCounterFirst = kCounterHistogram + 2 * kDepthHistogramBins,  // first failing index; kNoIndex: none
  kCounterSelected,                                             // how many items the last Select kept
  kCounterTopology,                                             // set: the in-place update cannot be done
  kCounterSlots
};

inline double SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A caller's positions, staged where the device's loops read them.
template <class Device>
struct StagedPositions
{
  typename Device::template Staged<float> xyzFloat;
  typename Device::template Staged<double> xyzDouble;

  PointArraysView View(std::size_t n) const
  {
    PointArraysView v;
    v.count = n;
    v.xyzFloat = xyzFloat.Get();
    v.xyzDouble = xyzDouble.Get();
    return v;
  }
};

// Work on a caller's positions once they have landed, with their bounds.
using WhenBounded = std::function<void(const Bounds&, const PointArraysView& positions)>;

// WhenBounded as Device::StageReduced's whenReduced of positions of type T
// (which holds whenBounded by reference: used within the staging call).
template <typename T>
std::function<void(const Bounds&, const T*)> WhenStagedBounded(const WhenBounded& whenBounded, std::size_t n)
{
  if (!whenBounded)
  {
    return nullptr;
  }
  return [&whenBounded, n](const Bounds& b, const T* xyz) {
    PointArraysView positions;
    positions.count = n;
    if constexpr (std::is_same<T, float>::value)
    {
      positions.xyzFloat = xyz;
    }
    else
    {
      positions.xyzDouble = xyz;
    }
    whenBounded(b, positions);
  };
}

// A caller's positions staged, with their bounds (PositionBounds, and the
// first non-finite point) reduced once they have landed: on CUDA, where
// attributes follow, while those are on their way. prepareAlong adds
// copies (Device::Prepare's) to make in the positions' pass, once their
// memory is taken, after the positions; whenBounded, if given, runs once
// the positions have landed, while those copies may still be on their way.
template <class Device>
StagedPositions<Device> StageBoundedPositions(Device& d, const float* xyzFloat, const double* xyzDouble,
  std::size_t n, const char* what, Bounds& bounds,
  const std::function<void(typename Device::Fills&)>& prepareAlong = nullptr, const WhenBounded& whenBounded = nullptr)
{
  Bounds fromFloat, fromDouble;
  StagedPositions<Device> staged{
    d.StageReduced(xyzFloat, xyzFloat ? 3 * n : 0, 3, what, EmptyBounds(), XyzPointBounds(), BoundsUnion(), fromFloat,
      xyzFloat ? prepareAlong : nullptr, WhenStagedBounded<float>(whenBounded, n)),
    d.StageReduced(xyzDouble, xyzDouble ? 3 * n : 0, 3, what, EmptyBounds(), XyzPointBounds(), BoundsUnion(),
      fromDouble, xyzFloat ? nullptr : prepareAlong, WhenStagedBounded<double>(whenBounded, n))
  };
  bounds = BoundsUnion()(fromFloat, fromDouble);
  return staged;
}

// The first index at which a device loop failed, in the scratch counter
// kCounterFirst: armed (filled with ones, kNoIndex) before the loop, each
// failure reported inside it, and read after it, alone (FirstFailedStep) or
// with the other counters in one copy.
struct FirstFailure
{
  std::uint64_t* slot;
  OCTORAY_HD void Report(std::size_t i) const { AtomicMin(slot, i); }
};

template <class Device>
FirstFailure ArmFirstFailure(Device& d, DriverScratch<Device>& scratch)
{
  std::uint64_t* slot = scratch.counters.Get() + kCounterFirst;
  d.FillBytes(slot, 1, 0xFF);
  return FirstFailure{ slot };
}

// Runs step(i) for every i in [0, n) as the loop `name` and returns the
// first i whose step failed (returned false), or kNoIndex. One copy to the
// host.
template <class Device, class Step>
std::uint64_t FirstFailedStep(Device& d, DriverScratch<Device>& scratch, const char* name, std::size_t n, Step step)
{
  const FirstFailure failure = ArmFirstFailure(d, scratch);
  d.ForEach(name, n, OCTORAY_LAMBDA(std::size_t i) {
    if (!step(i))
    {
      failure.Report(i);
    }
  });
  std::uint64_t result = kNoIndex;
  d.ToHost(failure.slot, 1, &result, name);
  return result;
}

// starts[r] = where the r-th run of equal keys among n sorted keys starts
// (the in-place update's records of one node), with n after the last run.
// `starts` has room for n + 1; the count goes to kCounterSelected.
template <class Device, typename Key>
void RunStarts(Device& d, DriverScratch<Device>& scratch, const Key* keys, std::size_t n, std::uint32_t* starts)
{
  d.Select(
    n + 1,
    OCTORAY_LAMBDA(std::size_t i) { return i == n || i == 0 || keys[i] != keys[i - 1]; },
    starts, scratch.counters.Get() + kCounterSelected);
}

// The bounds of positions where the device's loops read them, and the
// first non-finite point.
template <class Device>
Bounds PositionBounds(Device& d, const PointArraysView& pts)
{
  const float* xyzFloat = pts.xyzFloat;
  const double* xyzDouble = pts.xyzDouble;
  return d.Reduce(
    pts.count, EmptyBounds(),
    OCTORAY_LAMBDA(std::size_t i) {
      return xyzDouble ? XyzPointBounds()(i, xyzDouble) : XyzPointBounds()(i, xyzFloat);
    },
    BoundsUnion());
}

// A point of positions where the device's loops read them (the state's, or
// a caller's staged ones: the caller's own values, wherever the caller's
// memory is), read back for an error message.
template <class Device>
Vec3d ReadPosition(Device& d, const PointArraysView& positions, std::size_t i)
{
  if (positions.xyzDouble)
  {
    double p[3];
    d.ToHost(positions.xyzDouble + 3 * i, 3, p, "point positions");
    return Vec3d{ p[0], p[1], p[2] };
  }
  float p[3];
  d.ToHost(positions.xyzFloat + 3 * i, 3, p, "point positions");
  return Vec3d{ p[0], p[1], p[2] };
}

// The caller's float array an attribute is made from (colours given as
// 8-bit aside), and its length in values.
struct InputFloats
{
  const float* data;
  std::size_t count;
};

// One float per point: copied attributes and scalars (ScalarInput is one).
template <class A>
InputFloats InputFloatsOf(CopiedInput, A, const PointCloudView& points)
{
  return InputFloats{ A::Of(points), points.count };
}

template <class A>
InputFloats InputFloatsOf(UnitNormalInput, A, const PointCloudView& points)
{
  return InputFloats{ A::Of(points), 3 * points.count };
}

template <class A>
InputFloats InputFloatsOf(FloatColorInput, A, const PointCloudView& points)
{
  return InputFloats{ points.colorFloat, points.colorComponents * points.count };
}

template <class A>
InputFloats InputFloatsOf(ByteColorInput, A, const PointCloudView&)
{
  return InputFloats{ nullptr, 0 }; // staged as color8
}

// A caller's attribute arrays where the device's loops read them: as
// given, or (UnitInput) as Scalar16 codes, made as they are staged.
template <class Device>
struct StagedAttributes
{
  typename Device::template Staged<std::uint8_t> color8;
  typename Device::template Staged<float> values[kAttributeCount];
  typename Device::template Staged<std::uint16_t> unitCodes[kAttributeCount];
};

// Room for the attributes' staged arrays, whose copies (added to `fills`)
// go with the positions': one pass of the CUDA staging for all the arrays.
template <class Device>
StagedAttributes<Device> PrepareAttributes(Device& d, const PointCloudView& points, typename Device::Fills& fills)
{
  StagedAttributes<Device> staged;
  staged.color8 = d.Prepare(points.color8, points.colorComponents * points.count, "point colours", fills);
  ForEachAttribute([&](auto a) {
    using A = decltype(a);
    const InputFloats in = InputFloatsOf(typename A::Input(), a, points);
    const std::string label = std::string("point ") + A::kLabel;
    if constexpr (std::is_same<typename A::Input, UnitInput>::value)
    {
      staged.unitCodes[A::kIndex] = d.PrepareUnitCodes(in.data, in.count, label.c_str(), fills);
    }
    else
    {
      staged.values[A::kIndex] = d.Prepare(in.data, in.count, label.c_str(), fills);
    }
  });
  return staged;
}

// The record layout of a cloud's attributes: those it has, in the list's
// order, each a value of the type its nodes store.
inline PointRecordLayout RecordLayoutOf(const PointCloudView& points)
{
  PointRecordLayout layout;
  ForEachAttribute([&](auto a) {
    using A = decltype(a);
    if (!A::Input::template Present<A>(points))
    {
      return;
    }
    layout.offset[A::kIndex] = layout.stride;
    layout.stride += RecordWords(a);
  });
  return layout;
}

// The staged attribute arrays as plain pointers, for the record loop.
struct AttributeInputs
{
  const std::uint8_t* color8;
  const float* values[kAttributeCount];
  const std::uint16_t* unitCodes[kAttributeCount];
  int colorComponents;
  ScalarRange scalarRange;
};

// What each kind of attribute input stores in point i's words of the
// record (Attributes.h names the kind of each).
template <class A>
OCTORAY_HD void StoreInput(CopiedInput, A, const AttributeInputs& in, std::size_t i, std::uint32_t* records,
  const PointRecordLayout& layout)
{
  static_assert(std::is_same<typename A::Type, float>::value, "a copied attribute is stored as its float");
  StoreInRecord(records, layout, i, A::kIndex, in.values[A::kIndex][i]);
}

template <class A>
OCTORAY_HD void StoreInput(UnitInput, A, const AttributeInputs& in, std::size_t i, std::uint32_t* records,
  const PointRecordLayout& layout)
{
  static_assert(std::is_same<typename A::Type, float>::value, "a unit input is stored as the float of its code");
  StoreInRecord(records, layout, i, A::kIndex, UnitScalar(Scalar16{ in.unitCodes[A::kIndex][i] }));
}

template <class A>
OCTORAY_HD void StoreInput(ScalarInput, A, const AttributeInputs& in, std::size_t i, std::uint32_t* records,
  const PointRecordLayout& layout)
{
  StoreInRecord(records, layout, i, A::kIndex, EncodeUnitScalar(in.scalarRange.ToUnit(in.values[A::kIndex][i])));
}

template <class A>
OCTORAY_HD void StoreInput(UnitNormalInput, A, const AttributeInputs& in, std::size_t i, std::uint32_t* records,
  const PointRecordLayout& layout)
{
  const float* n = in.values[A::kIndex] + 3 * i;
  StoreInRecord(records, layout, i, A::kIndex, EncodeNormal(UnitNormal(n[0], n[1], n[2])));
}

// Colours become RGBA in their own precision; a missing alpha is opaque.
template <class A>
OCTORAY_HD void StoreInput(FloatColorInput, A, const AttributeInputs& in, std::size_t i, std::uint32_t* records,
  const PointRecordLayout& layout)
{
  const int cc = in.colorComponents;
  const float* c = in.values[A::kIndex] + cc * i;
  StoreInRecord(records, layout, i, A::kIndex, Rgba{ c[0], c[1], c[2], cc == 4 ? c[3] : 1.0f });
}

template <class A>
OCTORAY_HD void StoreInput(ByteColorInput, A, const AttributeInputs& in, std::size_t i, std::uint32_t* records,
  const PointRecordLayout& layout)
{
  const int cc = in.colorComponents;
  const std::uint8_t* c = in.color8 + cc * i;
  StoreInRecord(records, layout, i, A::kIndex, Rgba8{ c[0], c[1], c[2], cc == 4 ? c[3] : std::uint8_t(255) });
}

// The state's point records from the staged arrays: one loop writes each
// point's whole record.
template <class Device, class Points>
void IngestAttributes(Device& d, const PointCloudView& points, const StagedAttributes<Device>& staged,
  const ScalarRange& scalarRange, Points& s)
{
  const PointRecordLayout layout = s.layout; // set by the build before its sort, whose shape depends on it
  d.Reserve(s.records, points.count * layout.stride, "point attributes");
  if (layout.stride == 0)
  {
    return;
  }
  AttributeInputs in{ staged.color8.Get(), {}, {}, points.colorComponents, scalarRange };
  ForEachAttribute([&](auto a) {
    in.values[a.kIndex] = staged.values[a.kIndex].Get();
    in.unitCodes[a.kIndex] = staged.unitCodes[a.kIndex].Get();
  });
  std::uint32_t* records = s.records.Get();
  d.ForEach("PointRecordsKernel", points.count, OCTORAY_LAMBDA(std::size_t i) {
    ForEachAttribute([&](auto a) {
      if (layout.offset[decltype(a)::kIndex] >= 0)
      {
        StoreInput(typename decltype(a)::Input(), a, in, i, records, layout);
      }
    });
  });
}

// The range of the staged scalars' finite values (Scalar16.h); none: 0 to 0.
template <class Device>
ScalarRange FiniteScalarRange(Device& d, const float* scalar, std::size_t n)
{
  constexpr float inf = std::numeric_limits<float>::infinity();
  const ScalarRange r = d.Reduce(
    n, ScalarRange{ inf, -inf },
    OCTORAY_LAMBDA(std::size_t i) {
      const float x = scalar[i];
      return std::isfinite(x) ? ScalarRange{ x, x } : ScalarRange{ inf, -inf };
    },
    OCTORAY_LAMBDA(const ScalarRange& a, const ScalarRange& b) {
      return ScalarRange{ a.lo < b.lo ? a.lo : b.lo, a.hi > b.hi ? a.hi : b.hi };
    });
  return r.lo <= r.hi ? r : ScalarRange{};
}

// The cube a build uses: fitted to the bounds `b` of the staged positions,
// or the caller's fixed one, which must hold them all. Checked before
// anything is replaced, so that a refused build leaves the octree as it
// was; errors name the first offending point with its coordinates as the
// caller gave them.
template <class Device>
RootCube CheckedCube(Device& d, DriverScratch<Device>& scratch, const PointArraysView& staged, const Bounds& b,
  const BuildOptions& options)
{
  if (b.firstBad != kNoIndex)
  {
    throw Error(NonFinitePointMessage(b.firstBad, ReadPosition(d, staged, b.firstBad)));
  }
  if (!options.fixedCube)
  {
    return RootCube::FromBounds(b.lo, b.hi);
  }
  // Every point is inside when both corners of the bounds are.
  const RootCube cube = options.cube;
  if (!cube.Contains(b.lo) || !cube.Contains(b.hi))
  {
    const std::uint64_t first = FirstFailedStep(d, scratch, "OutsideCubeKernel", staged.count,
      OCTORAY_LAMBDA(std::size_t i) { return cube.Contains(staged.Position(i)); });
    throw Error(OutsideCubeMessage(first, ReadPosition(d, staged, first)));
  }
  return cube;
}

// The state's points sorted by their leaf keys, the leaf level and the
// newNode histogram that gives every level's node count.
struct SortedPoints
{
  SortedKeys keys;
  std::uint32_t* spare; // a 32-bit array the sort left free (n + 1 entries): room for run starts
  int depth;              // the leaf level: the sort's, or one the automatic depth chose above it (keys.keyShift)
  std::size_t placedRoom; // the levels' run starts placed with the sort, the inner levels' where they fit this
                          // room (PlaceLevelStarts); 0: not placed
  std::uint64_t histogram[2 * kDepthHistogramBins];
};

static_assert(SortedKeys::Narrow(kProvisionalDepth), "the provisional sort has 32-bit keys");

// Where one of a build's sorts began, where its keys were made and where
// its levels' run starts were counted, as marks on the build's clock (-1:
// the sort did not run).
struct SortMarks
{
  int begin = -1;
  int keys = -1;
  int counted = -1;
};

// Where the keys kernel writes each point's leaf key, and its index where
// the records do not travel with the keys.
struct SortInput
{
  std::uint64_t* wideKey;
  std::uint32_t* narrowKey;
  std::uint32_t* index;

  OCTORAY_HD void Enter(std::size_t i, std::uint64_t leafKey) const
  {
    if (narrowKey)
    {
      narrowKey[i] = static_cast<std::uint32_t>(leafKey);
    }
    else
    {
      wideKey[i] = leafKey;
    }
    if (index)
    {
      index[i] = static_cast<std::uint32_t>(i);
    }
  }
};

// Reserves the key and index arrays of a sort (32-bit keys where they fit:
// SortedKeys) and releases those it does not use.
template <class Device>
SortInput ReserveSortInput(Device& d, DriverScratch<Device>& scratch, std::size_t n, bool narrow, bool indexed)
{
  for (int b = 0; b < 2; ++b)
  {
    if (narrow)
    {
      d.Release(scratch.sortKey[b]);
      d.Reserve(scratch.narrowKey[b], n + 1, "sort keys");
    }
    else
    {
      d.Release(scratch.narrowKey[b]);
      d.Reserve(scratch.sortKey[b], n, "sort keys");
    }
    if (indexed)
    {
      d.Reserve(scratch.sortIndex[b], n + 1, "sort indices");
    }
    else
    {
      d.Release(scratch.sortIndex[b]);
    }
  }
  if (indexed) // the records stay where they are (SortedKeys)
  {
    d.Release(scratch.sortRecords);
  }
  return SortInput{ narrow ? nullptr : scratch.sortKey[0].Get(), narrow ? scratch.narrowKey[0].Get() : nullptr,
    indexed ? scratch.sortIndex[0].Get() : nullptr };
}

// Sorts the n 32-bit keys of `bits` bits with the points' records of
// `stride` words (none, one or two) that travel with them, into the sort's
// record array (the state's records stay as they are); returns the sorted
// keys and the key array the sort left free.
template <class Device>
SortedKeys SortNarrowKeys(Device& d, DriverScratch<Device>& scratch, const PointArraysView& pts, int bits,
  std::uint32_t*& spare)
{
  const std::size_t n = pts.count;
  const int stride = pts.layout.stride;
  std::uint32_t* keys[2] = { scratch.narrowKey[0].Get(), scratch.narrowKey[1].Get() };
  int result = 0;
  std::uint32_t* sortedRecords = nullptr;
  if (stride == 0)
  {
    d.Release(scratch.sortRecords);
    result = d.SortKeys(keys, n, bits, "point keys");
  }
  else
  {
    d.Reserve(scratch.sortRecords, n * stride, "sort records");
    const std::uint32_t* records = pts.records;
    sortedRecords = scratch.sortRecords.Get();
    if (stride == 1)
    {
      result = d.SortPairsFrom(keys, records, sortedRecords, n, bits, "point keys and records");
    }
    else
    {
      static_assert(sizeof(std::uint64_t) == 2 * sizeof(std::uint32_t), "a record of two words is one value");
      result = d.SortPairsFrom(keys, reinterpret_cast<const std::uint64_t*>(records),
        reinterpret_cast<std::uint64_t*>(sortedRecords), n, bits, "point keys and records");
    }
  }
  spare = keys[1 - result];
  return SortedKeys{ nullptr, keys[result], nullptr, sortedRecords, 0 };
}

// Sorts the n keys of `bits` bits in `keyBuffers` (32- or 64-bit) with
// their points' indices; returns the sorted keys and the index array the
// sort left free.
template <class Device, class KeyBuffer>
SortedKeys SortKeysWithIndices(Device& d, DriverScratch<Device>& scratch, KeyBuffer (&keyBuffers)[2],
  std::size_t n, int bits, std::uint32_t*& spare)
{
  using Key = std::remove_pointer_t<decltype(keyBuffers[0].Get())>;
  Key* keys[2] = { keyBuffers[0].Get(), keyBuffers[1].Get() };
  std::uint32_t* values[2] = { scratch.sortIndex[0].Get(), scratch.sortIndex[1].Get() };
  const int result = d.SortPairs(keys, values, n, bits, "point keys");
  spare = values[1 - result];
  SortedKeys sorted{ nullptr, nullptr, values[result], nullptr, 0 };
  if constexpr (sizeof(Key) == sizeof(std::uint32_t))
  {
    sorted.narrowKey = keys[result];
  }
  else
  {
    sorted.wideKey = keys[result];
  }
  return sorted;
}

// Sorts the leaf keys of `bits` bits that the keys kernel entered into
// `input`: with the records that travel with them where it holds no
// indices, else with the indices; returns the sorted keys and the array
// the sort left free.
template <class Device>
SortedKeys SortLeafKeys(Device& d, DriverScratch<Device>& scratch, const PointArraysView& pts, const SortInput& input,
  int bits, std::uint32_t*& spare)
{
  if (!input.index)
  {
    return SortNarrowKeys(d, scratch, pts, bits, spare);
  }
  if (input.narrowKey)
  {
    return SortKeysWithIndices(d, scratch, scratch.narrowKey, pts.count, bits, spare);
  }
  return SortKeysWithIndices(d, scratch, scratch.sortKey, pts.count, bits, spare);
}

// fn(words) with the sorted keys as the sort stored them: 32-bit words
// where the leaf keys fit them, else 64-bit (SortedKeys).
template <typename Fn>
void WithKeyWords(const SortedKeys& keys, Fn&& fn)
{
  if (keys.narrowKey)
  {
    fn(keys.narrowKey);
  }
  else
  {
    fn(keys.wideKey);
  }
}

// The levels' run starts of the n sorted points at `depth` (keys shifted
// right by `shift` bits), counted for PlaceLevelStarts: every level's size
// goes to the newNode histogram `counts` (DepthChoice.h's FirstNewLevels is
// each key's bin, and the first key's 0, which NodesAtLevel leaves out),
// and `side`'s histogram in the same pass.
template <class Device, typename Key, typename Side = NoSideHistogram>
void CountLevelStarts(Device& d, DriverScratch<Device>& scratch, const Key* keys, std::size_t n, int depth, int shift,
  std::uint64_t* counts, Side side = {})
{
  d.CountNested("LevelCountKernel", n, depth + 1, FirstNewLevels<Key>{ keys, depth, shift }, scratch.levelTally,
    counts, side);
}

// Every level's run starts, as CountLevelStarts counted them on the keys
// as the sort left them, `shift` bits (shift / 3 levels) deeper than
// `depth`: a level's run starts are the same whatever the depth below it.
// The leaves' first points go in `leafStarts` (n + 1 entries), the inner
// levels' first children end to end in scratch.levelStarts, level l's from
// levelBegin[l] + l on, where they fit the room it has (NestedLists);
// returns that room.
template <class Device, typename Key>
std::size_t PlaceLevelStarts(Device& d, DriverScratch<Device>& scratch, const Key* keys, std::size_t n, int depth,
  int shift, std::uint32_t* leafStarts)
{
  const int counted = depth + shift / 3 + 1;
  NestedLists out;
  out.count = depth + 1;
  out.last = leafStarts;
  out.packed = scratch.levelStarts.Get();
  out.packedRoom = scratch.levelStarts.Bytes() / sizeof(std::uint32_t);
  d.PlaceNested("LevelStartsKernel", n, FirstNewLevels<Key>{ keys, depth, shift }, scratch.levelTally, counted,
    out);
  return out.packedRoom;
}

// Whether the level lists' entries of n points at `depth`, at most n a
// level, can be numbered in 32 bits before the host has checked the node
// count (SetLevelBegins): where they can, the lists are placed while the
// host reads the level sizes.
inline bool LevelListsFitWord(std::size_t n, int depth)
{
  return n <= kInvalidIndex / static_cast<std::size_t>(depth + 1);
}

// Queues the sort of the points `pts` by their keys at `sortDepth`
// (kMaxLevel: full depth): the keys, computed from the positions, the
// sort, and the levels' run starts counted (CountLevelStarts), their sizes
// in the newNode histogram. Records that fit travel with the keys
// (SortedKeys::RecordsTravel); where a record layout is given but its
// records have not landed (pts.records null), the points' indices do,
// through which the leaf loop reads the records (SortedKeys). chooseDepth:
// in the same pass, the alone histogram, which the automatic depth reads
// with the newNode one; else the run starts placed where they fit.
template <class Device>
SortedPoints QueueSort(Device& d, DriverScratch<Device>& scratch, const PointArraysView& pts, const RootCube& cube,
  int sortDepth, bool chooseDepth, const FirstFailure& outside, typename Device::Clock& clock, SortMarks& marks)
{
  marks.begin = clock.Mark();
  const std::size_t n = pts.count;
  const bool narrow = SortedKeys::Narrow(sortDepth);
  const int stride = pts.layout.stride;
  const bool travel = SortedKeys::RecordsTravel(sortDepth, stride) && (stride == 0 || pts.records);
  const SortInput input = ReserveSortInput(d, scratch, n, narrow, !travel);
  // Only the bits down to sortDepth need sorting. The keys are computed
  // from the positions each time, not kept: kept full-depth keys took 8
  // bytes a point, and without writing them this kernel took 73 us at 10 M
  // points against 84, 703 against 836 at 100 M, on an H100; 57 and 567
  // with the keys made at their depth (ComputeLeafKey;
  // Benchmarks/gpu/variants-unkept-keys.txt).
  const RootCube::CellMap grid = cube.Grid();
  d.ForEach("KeysKernel", n, OCTORAY_LAMBDA(std::size_t i) {
    std::uint64_t key = 0;
    if (!ComputeLeafKey(pts, grid, i, sortDepth, key))
    {
      outside.Report(i);
    }
    input.Enter(i, key);
  });
  marks.keys = clock.Mark();

  SortedPoints sorted;
  sorted.depth = sortDepth;
  sorted.keys = SortLeafKeys(d, scratch, pts, input, 3 * sortDepth, sorted.spare);
  std::uint64_t* counters = scratch.counters.Get();
  d.FillBytes(counters + kCounterHistogram, 2 * kDepthHistogramBins, 0);
  // The sorted keys as the sort left them: leaf keys of sortDepth (keyShift 0).
  sorted.placedRoom = 0;
  WithKeyWords(sorted.keys, [&](const auto* keys) {
    using Key = std::remove_const_t<std::remove_pointer_t<decltype(keys)>>;
    std::uint64_t* newNode = counters + kCounterHistogram;
    if (chooseDepth)
    {
      const SideHistogram<kDepthHistogramBins, LoneLevels<Key>> alone{ { keys, n, sortDepth },
        newNode + kDepthHistogramBins };
      CountLevelStarts(d, scratch, keys, n, sortDepth, 0, newNode, alone);
    }
    else
    {
      CountLevelStarts(d, scratch, keys, n, sortDepth, 0, newNode);
    }
  });
  // The histograms and the key check on their way to the host (ReadHistogram).
  static_assert(kCounterFirst == kCounterHistogram + 2 * kDepthHistogramBins, "one copy: histograms, key check");
  d.QueueToHost(counters + kCounterHistogram, 2 * kDepthHistogramBins + 1, "the level sizes");
  // Meanwhile the device places the levels' run starts where the room the
  // last build left holds them. Placed after the host had read the level
  // sizes, at 10 M points they waited 0.04 ms for it, at 100 M 0.5 ms, while
  // the host reserved the node arrays (Benchmarks/gpu/variants-nested-levels.txt).
  if (!chooseDepth && LevelListsFitWord(n, sortDepth))
  {
    WithKeyWords(sorted.keys, [&](const auto* keys) {
      sorted.placedRoom = PlaceLevelStarts(d, scratch, keys, n, sortDepth, 0, sorted.spare);
    });
  }
  marks.counted = clock.Mark();
  return sorted;
}

// The histogram of a queued sort, and the key check of its keys, as
// QueueSort sent them to the host. A point outside the cube is an error
// naming it.
template <class Device>
void ReadHistogram(Device& d, OctreeState<Device>& s, SortedPoints& sorted)
{
  std::uint64_t report[2 * kDepthHistogramBins + 1];
  d.WaitToHost(report, "the level sizes");
  if (report[2 * kDepthHistogramBins] != kNoIndex)
  {
    const std::size_t outside = report[2 * kDepthHistogramBins];
    throw Error(OutsideCubeMessage(outside, ReadPosition(d, s.Points(), outside)));
  }
  std::copy_n(report, 2 * kDepthHistogramBins, sorted.histogram);
}

// A build's sort, queued (QueueBuildSort) from the positions alone,
// while the points' records may still be on their way, and finished
// (FinishBuild) once they are in the state: its sorts' marks on `clock`,
// the automatic depth's in the order it sorts.
template <class Device>
struct QueuedBuild
{
  typename Device::Clock clock;
  SortMarks marks[kMostAutomaticSorts];
  FirstFailure outside;
  int requestedDepth;
  SortedPoints sorted;
};

// Queues the sort of the points `pts` inside `cube` at the requested
// depth, or, for the automatic one (requestedDepth 0), kProvisionalDepth
// (DepthChoice.h).
template <class Device>
void QueueBuildSort(Device& d, DriverScratch<Device>& scratch, const PointArraysView& pts, const RootCube& cube,
  int requestedDepth, QueuedBuild<Device>& q)
{
  // The cube holds every point (fitted or checked): a point outside is a
  // bug, read after the sort with the histogram.
  q.outside = ArmFirstFailure(d, scratch);
  q.requestedDepth = requestedDepth;
  const bool chooseDepth = requestedDepth == 0;
  q.sorted = QueueSort(d, scratch, pts, cube, chooseDepth ? kProvisionalDepth : requestedDepth, chooseDepth,
    q.outside, q.clock, q.marks[0]);
}

// The state's points sorted as QueueBuildSort queued, with every level's
// node count; for the automatic depth, where the levels down to the sort's
// depth do not settle the depth rule, sorted again deeper (NextSortDepth),
// with the points' indices (64-bit keys). One copy brings each sort's
// histograms.
template <class Device>
void FinishSort(Device& d, DriverScratch<Device>& scratch, OctreeState<Device>& s, const RootCube& cube,
  QueuedBuild<Device>& q)
{
  SortedPoints& sorted = q.sorted;
  ReadHistogram(d, s, sorted);
  if (q.requestedDepth != 0)
  {
    return;
  }
  int depth = ChooseDepthWithin(sorted.histogram, sorted.histogram + kDepthHistogramBins, sorted.depth);
  for (int next = 1; depth == 0; ++next) // full depth settles the rule
  {
    const int sortDepth = NextSortDepth(sorted.histogram, s.count, sorted.depth);
    sorted = QueueSort(d, scratch, s.Points(), cube, sortDepth, true, q.outside, q.clock, q.marks[next]);
    ReadHistogram(d, s, sorted);
    depth = ChooseDepthWithin(sorted.histogram, sorted.histogram + kDepthHistogramBins, sortDepth);
  }
  // The leaf keys: the sorted keys (at sorted.depth) without their bits below the depth.
  sorted.keys.keyShift += 3 * (sorted.depth - depth);
  sorted.depth = depth;
}

// levelBegin[l]: the first node of level l, from the newNode histogram;
// levelBegin[depth + 1] on: the node count. Nodes are numbered in 32 bits
// (kInvalidIndex the last number, "none"): a deep octree of a sparse cloud,
// every point a chain of nodes of its own, can pass that, which is an error
// before anything is reserved.
inline void SetLevelBegins(const std::uint64_t newNode[kDepthHistogramBins], int depth,
  std::uint32_t levelBegin[kMaxLevel + 2])
{
  std::uint64_t begin = 0;
  for (int l = 0; l <= kMaxLevel + 1; ++l)
  {
    levelBegin[l] = static_cast<std::uint32_t>(begin);
    begin += l <= depth ? NodesAtLevel(newNode, l) : 0;
    if (begin > kInvalidIndex)
    {
      throw Error("octoray: an octree of depth " + std::to_string(depth) + " over these points would hold " +
        std::to_string(begin) + " nodes or more, past the 32-bit node index; choose a shallower depth");
    }
  }
}

// Each level's run starts (PlaceLevelStarts): the leaves' in the array the
// sort left free, the inner levels' in scratch.levelStarts. Placed with the
// sort where the room they had was enough, else here.
template <class Device>
NestedLists LevelStarts(Device& d, DriverScratch<Device>& scratch, const OctreeState<Device>& s,
  const SortedPoints& sorted)
{
  const int depth = s.depth;
  const std::size_t innerEntries = s.levelBegin[depth] + static_cast<std::size_t>(depth);
  if (innerEntries > sorted.placedRoom)
  {
    d.Reserve(scratch.levelStarts, innerEntries, "level starts");
    WithKeyWords(sorted.keys, [&](const auto* words) {
      PlaceLevelStarts(d, scratch, words, s.count, depth, sorted.keys.keyShift, sorted.spare);
    });
  }
  NestedLists lists;
  lists.count = depth + 1;
  lists.last = sorted.spare;
  lists.packed = scratch.levelStarts.Get();
  lists.packedRoom = innerEntries;
  return lists;
}

// The nodes from the sorted points and each level's run starts: leaves,
// then each level from the one below, the few small ones near the root
// together (Device::ReduceSmallLevels). Neither the points' records nor the
// nodes hold attributes outside Possible: the loops of kLeanAttributes ask
// for kLeanLoopBlocks blocks a multiprocessor, to which their registers fit.
template <unsigned Possible, class Device>
void ReduceNodes(Device& d, const OctreeView& view, const PointArraysView& pts, const SortedKeys& keys,
  const NestedLists& starts)
{
  constexpr int kBlocks = Possible == kLeanAttributes ? kLeanLoopBlocks : kLoopBlocks;
  const std::uint32_t leafBegin = view.levelBegin[view.depth];
  const std::uint32_t* leafStarts = starts.last;
  d.ForEach("LeafKernel", view.LevelSize(view.depth), BlocksPerMultiprocessor<kBlocks>(OCTORAY_LAMBDA(std::size_t j) {
    ReduceLeaf<Possible>(view, pts, keys, leafBegin + static_cast<std::uint32_t>(j), leafStarts[j], leafStarts[j + 1]);
  }));
  const InnerLevels<Possible> levels{ view };
  int l = view.depth - 1;
  for (; l >= 0 && levels.Children(l) > Device::kSmallLevelItems; --l)
  {
    const std::uint32_t* children = starts.List(l, view.levelBegin[l]);
    d.ForEach("InnerKernel", view.LevelSize(l), BlocksPerMultiprocessor<kBlocks>(OCTORAY_LAMBDA(std::size_t j) {
      levels.Reduce(l, static_cast<std::uint32_t>(j), children[j], children[j + 1]);
    }));
  }
  if (l >= 0)
  {
    d.ReduceSmallLevels("SmallLevelsKernel", l, levels, starts);
  }
}

// The node arrays from the sorted points: leaves, then each level from the
// one below, its nodes the runs of equal parent keys. The level sizes are
// known from the histogram, and every level's run starts come from one pass
// over the sorted points (PlaceLevelStarts), so nothing returns to the host
// per level.
template <class Device>
void LinkLevels(Device& d, DriverScratch<Device>& scratch, OctreeState<Device>& s, const SortedPoints& sorted,
  const RootCube& cube)
{
  const int depth = sorted.depth;
  s.depth = depth;
  s.cube = cube;
  const SortedKeys keys = sorted.keys;
  SetLevelBegins(sorted.histogram, depth, s.levelBegin);
  const std::size_t nodes = s.levelBegin[depth + 1];
  // Where the sort did not place the run starts (the automatic depth's),
  // the device places them while the host reserves the node arrays.
  const NestedLists starts = LevelStarts(d, scratch, s, sorted);
  ForEachNodeArray([&](auto a) {
    const std::string what = MemoryReport::NodeArray(a.kLabel);
    if (Present(a, s.attributes, depth))
    {
      d.Reserve(a.Of(s.nodes), EntriesFor(a, nodes), what.c_str());
    }
    else
    {
      d.Release(a.Of(s.nodes));
    }
  });
  // The last word of masks may have bytes of no node: zero, so that they
  // count no children.
  if (nodes)
  {
    d.FillBytes(s.nodes.childMasks.Get() + (nodes - 1) / 8, 1, 0);
  }
  const OctreeView view = s.View();
  const PointArraysView pts = s.Points();
  if (((s.attributes | pts.layout.Attributes()) & ~kLeanAttributes) == 0)
  {
    ReduceNodes<kLeanAttributes>(d, view, pts, keys, starts);
  }
  else
  {
    ReduceNodes<kAllAttributes>(d, view, pts, keys, starts);
  }
}

// The octree of a queued build (QueueBuildSort) of the state's points:
// the sort finished and the levels. The phases' times are the device's
// (Device::Clock).
template <class Device>
BuildStats FinishBuild(Device& d, DriverScratch<Device>& scratch, OctreeState<Device>& s, const RootCube& cube,
  QueuedBuild<Device>& q)
{
  BuildStats stats;
  stats.points = s.count;
  FinishSort(d, scratch, s, cube, q);
  const int levelsBegin = q.clock.Mark();
  LinkLevels(d, scratch, s, q.sorted, cube);
  const int levelsEnd = q.clock.Mark();
  d.Synchronize("octree build");
  for (const SortMarks& m : q.marks)
  {
    if (m.begin >= 0)
    {
      stats.keySeconds += q.clock.Seconds(m.begin, m.keys);
      stats.sortSeconds += q.clock.Seconds(m.keys, m.counted);
    }
  }
  stats.levelSeconds = q.clock.Seconds(levelsBegin, levelsEnd);
  stats.depth = s.depth;
  stats.cube = cube;
  stats.nodes = s.levelBegin[s.depth + 1];
  for (int l = 0; l <= s.depth; ++l)
  {
    stats.nodesPerLevel.push_back(s.levelBegin[l + 1] - s.levelBegin[l]);
  }
  return stats;
}

// Keys, sort and levels of the state's points inside `cube`: the octree.
template <class Device>
BuildStats BuildLevels(
  Device& d, DriverScratch<Device>& scratch, OctreeState<Device>& s, const RootCube& cube, int requestedDepth)
{
  QueuedBuild<Device> q;
  QueueBuildSort(d, scratch, s.Points(), cube, requestedDepth, q);
  return FinishBuild(d, scratch, s, cube, q);
}

// What only updates read, freed once the nodes are built without
// BuildOptions::keepPoints: the point copy, the sort's buffers, the
// counters and the device's scratch (the next build or update reserves
// them again).
template <class Device>
void ReleasePoints(Device& d, DriverScratch<Device>& scratch, OctreeState<Device>& s)
{
  d.Release(s.points.xyzFloat);
  d.Release(s.points.xyzDouble);
  d.Release(s.points.records);
  DriverScratch<Device>::ForEachScratchBuffer(scratch, [&](auto& buffer) { d.Release(buffer); });
  d.Release(scratch.counters);
  d.ReleaseScratch();
}

// A build's input staged where the device's loops read it, and its cube
// checked (CheckedCube) before anything of the state changes.
template <class Device>
struct StagedInput
{
  StagedPositions<Device> positions;
  StagedAttributes<Device> attributes;
  RootCube cube;
  double cubeSeconds = 0.0; // the host's time in the cube's check
  bool sortQueued = false;  // during the attributes' upload, into the QueuedBuild
};

// Stages a build's points. Where the attributes are still on their way
// once the positions have landed (CUDA's staged copy of a caller's host
// arrays), the cube is checked then and the keys and the sort of the
// positions are queued into `queued`, with the points' indices, to run
// meanwhile; the leaf loop reads the records through them (SortedKeys). At
// 10 M points on an H200 the whole call took 1.61-1.65 times the pinned
// copy against 1.70-1.77 with the sort after the copy, at 100 M 1.34-1.36
// against 1.38-1.42 (Benchmarks/gpu/variants-sort-during-upload.txt).
template <class Device>
StagedInput<Device> StageInput(Device& d, DriverScratch<Device>& scratch, const PointCloudView& points,
  const BuildOptions& options, const PointRecordLayout& layout, QueuedBuild<Device>& queued)
{
  StagedInput<Device> in;
  const auto checkCube = [&](const Bounds& b, const PointArraysView& positions) {
    const auto checked = std::chrono::steady_clock::now();
    in.cube = CheckedCube(d, scratch, positions, b, options);
    in.cubeSeconds = SecondsSince(checked);
  };
  Bounds bounds;
  in.positions = StageBoundedPositions(
    d, points.xyzFloat, points.xyzDouble, points.count, "point positions", bounds,
    [&](typename Device::Fills& fills) { in.attributes = PrepareAttributes(d, points, fills); },
    [&](const Bounds& b, const PointArraysView& positions) {
      checkCube(b, positions);
      PointArraysView keyed = positions;
      keyed.layout = layout;
      QueueBuildSort(d, scratch, keyed, in.cube, options.depth, queued);
      in.sortQueued = true;
    });
  if (!in.sortQueued)
  {
    checkCube(bounds, in.positions.View(points.count));
  }
  return in;
}

// Engine::Build: checks the input, makes it the point state (`current`, or
// a new one that replaces it once complete where the device builds aside)
// and builds the octree.
template <class Device>
BuildStats BuildOctree(Device& d, DriverScratch<Device>& scratch, std::unique_ptr<OctreeState<Device>>& current,
  const PointCloudView& points, const BuildOptions& options)
{
  ValidateCloud(points);
  ValidateDepth(options.depth);
  const std::size_t n = points.count;
  d.Reserve(scratch.counters, kCounterSlots, "counters");
  const PointRecordLayout layout = RecordLayoutOf(points); // the sort's shape depends on it
  const auto phase = std::chrono::steady_clock::now();
  QueuedBuild<Device> queued;
  StagedInput<Device> staged = StageInput(d, scratch, points, options, layout, queued);

  std::unique_ptr<OctreeState<Device>> fresh;
  OctreeState<Device>& s = Device::kBuildsAside ? *(fresh = std::make_unique<OctreeState<Device>>()) : *current;
  s.count = n;
  s.attributes = points.Attributes();
  s.keepPoints = options.keepPoints;
  s.points.layout = layout;
  d.Adopt(std::move(staged.positions.xyzFloat), s.points.xyzFloat, 3 * n);
  d.Adopt(std::move(staged.positions.xyzDouble), s.points.xyzDouble, 3 * n);
  const float* scalar = staged.attributes.values[kAttributeScalar].Get();
  s.scalarRange = scalar ? FiniteScalarRange(d, scalar, n) : ScalarRange{};
  IngestAttributes(d, points, staged.attributes, s.scalarRange, s.points);
  staged.attributes = StagedAttributes<Device>(); // freed before the build trims the device's cache
  // The host's time in the copies (the keys and the sort queued among
  // them where they overlap it), not in the cube's check after them.
  const double uploadSeconds = SecondsSince(phase) - (staged.sortQueued ? 0.0 : staged.cubeSeconds);
  if (!staged.sortQueued) // the records travel with the keys
  {
    QueueBuildSort(d, scratch, s.Points(), staged.cube, options.depth, queued);
  }
  BuildStats stats = FinishBuild(d, scratch, s, staged.cube, queued);
  stats.uploadSeconds = uploadSeconds;
  stats.keySeconds += staged.cubeSeconds;
  if (!s.keepPoints)
  {
    ReleasePoints(d, scratch, s);
  }
  if (fresh)
  {
    current = std::move(fresh);
  }
  if (!options.keepPoints)
  {
    d.TrimCache(); // a static scene: only its nodes stay
  }
  return stats;
}

// The in-place update of the moves listed (changed of them, indices into
// the moved points' fromLeaf and toLeaf): counts and means adjusted along
// both paths of each. False, with nothing changed, when a node would appear
// or empty. Copies to the host: the two checks and the run count.
template <class Device>
bool UpdateInPlace(Device& d, DriverScratch<Device>& scratch, OctreeState<Device>& s, const std::uint32_t* moves,
  std::size_t changed, const std::uint32_t* indices, const std::uint64_t* fromLeaf, const std::uint64_t* toLeaf)
{
  const OctreeView view = s.View();
  const PointArraysView pts = s.Points();
  const std::size_t pathRecords = 2 * (static_cast<std::size_t>(s.depth) + 1);
  const std::size_t records = changed * pathRecords;
  typename Device::template Buffer<std::uint32_t> node[2], point[2];
  for (int b = 0; b < 2; ++b)
  {
    d.Reserve(node[b], records, "update records");
    d.Reserve(point[b], records + 1, "update records");
  }
  std::uint64_t* flag = scratch.counters.Get() + kCounterTopology;
  d.FillBytes(flag, 1, 0);
  std::uint32_t* recordNode = node[0].Get();
  std::uint32_t* recordPoint = point[0].Get();
  d.ForEach("PathRecordsKernel", changed, OCTORAY_LAMBDA(std::size_t c) {
    const std::uint32_t k = moves[c];
    const std::uint32_t i = indices ? indices[k] : k;
    if (!WritePathRecords(view, i, fromLeaf[k], toLeaf[k], c * pathRecords, recordNode, recordPoint))
    {
      AtomicRaise(flag);
    }
  });
  std::uint64_t blocked = 0;
  d.ToHost(flag, 1, &blocked, "PathRecordsKernel");
  if (blocked)
  {
    return false;
  }
  std::uint32_t* keys[2] = { node[0].Get(), node[1].Get() };
  std::uint32_t* values[2] = { point[0].Get(), point[1].Get() };
  const int result = d.SortPairs(keys, values, records, 32, "update records");
  const std::uint32_t* byNode = keys[result];
  const std::uint32_t* pointOf = values[result];
  std::uint32_t* starts = values[1 - result];
  RunStarts(d, scratch, byNode, records, starts);
  std::uint64_t runs = 0;
  d.ToHost(scratch.counters.Get() + kCounterSelected, 1, &runs, "run starts");
  --runs; // the end of the last run
  d.ForEach("EmptiedNodesKernel", runs, OCTORAY_LAMBDA(std::size_t r) {
    if (WouldEmpty(view, byNode, pointOf, starts[r], starts[r + 1]))
    {
      AtomicRaise(flag);
    }
  });
  d.ToHost(flag, 1, &blocked, "EmptiedNodesKernel");
  if (blocked)
  {
    return false;
  }
  d.ForEach("ApplyDeltasKernel", runs,
    OCTORAY_LAMBDA(std::size_t r) { ApplyRecords(view, pts, byNode, pointOf, starts[r], starts[r + 1]); });
  d.Synchronize("ApplyDeltasKernel");
  return true;
}

// An update's new positions and their indices where the device's loops
// read them, the indices staged in the positions' pass.
template <class Device>
struct StagedMoves
{
  StagedPositions<Device> xyz;
  typename Device::template Staged<std::uint32_t> indices; // none: the moves are the points, in order
};

// Stages an update's moves. Of the positions' bounds only the first
// non-finite point counts, an error here, before the first write to the
// state, so that a bad position changes nothing.
template <class Device>
StagedMoves<Device> StageMoves(Device& d, const PositionsView& positions)
{
  const std::size_t moved = positions.count;
  typename Device::template Staged<std::uint32_t> indices;
  Bounds bounds;
  StagedPositions<Device> xyz = StageBoundedPositions(d, positions.xyzFloat, positions.xyzDouble, moved,
    "update positions", bounds, [&](typename Device::Fills& fills) {
      indices = d.Prepare(positions.indices, positions.indices ? moved : 0, "update indices", fills);
    });
  const std::uint64_t bad = bounds.firstBad;
  if (bad != kNoIndex)
  {
    throw Error(NonFinitePointMessage(positions.indices ? positions.indices[bad] : bad, positions.Position(bad)));
  }
  return StagedMoves<Device>{ std::move(xyz), std::move(indices) };
}

// What the moves did to the leaves: the first point that left the cube
// (kNoIndex: none) and how many moves changed leaf.
struct MovedLeaves
{
  std::uint64_t firstOutside;
  std::size_t changed;
};

// Writes the `moved` new positions `to` (of the points `indices`, or of
// every point in order) into the state, with each move's leaf before it in
// from[k] and after it in into[k], and the moves that changed leaf, in
// order, in changedMoves. One copy to the host.
template <class Device>
MovedLeaves MoveLeaves(Device& d, DriverScratch<Device>& scratch, OctreeState<Device>& s, const PointArraysView& to,
  const std::uint32_t* indices, std::uint64_t* from, std::uint64_t* into, std::uint32_t* changedMoves)
{
  const std::size_t moved = to.count;
  const PointArraysView pts = s.Points();
  const RootCube::CellMap grid = s.cube.Grid();
  const int depth = s.depth;
  float* xyzFloat = s.points.xyzFloat.Get();
  double* xyzDouble = s.points.xyzDouble.Get();
  // A point's old leaf from the position it leaves, read before the new one
  // is written (every stored point lies inside the cube).
  d.ForEach("ScatterPositionsKernel", moved, OCTORAY_LAMBDA(std::size_t k) {
    const std::size_t i = indices ? indices[k] : k;
    ComputeLeafKey(pts, grid, i, depth, from[k]);
    const Vec3d p = to.Position(k);
    for (int a = 0; a < 3; ++a)
    {
      if (xyzDouble)
      {
        xyzDouble[3 * i + a] = p[a];
      }
      else
      {
        xyzFloat[3 * i + a] = static_cast<float>(p[a]);
      }
    }
  });
  // The new leaves from the positions as stored (floats, where they are).
  const FirstFailure outside = ArmFirstFailure(d, scratch);
  d.ForEach("MovedKeysKernel", moved, OCTORAY_LAMBDA(std::size_t k) {
    const std::size_t i = indices ? indices[k] : k;
    std::uint64_t key = 0;
    const bool inside = ComputeLeafKey(pts, grid, i, depth, key);
    into[k] = inside ? key : from[k];
    if (!inside)
    {
      outside.Report(i);
    }
  });
  d.Select(moved, OCTORAY_LAMBDA(std::size_t k) { return from[k] != into[k]; }, changedMoves,
    scratch.counters.Get() + kCounterSelected);
  std::uint64_t report[2]; // kCounterFirst, kCounterSelected
  d.ToHost(outside.slot, 2, report, "MovedKeysKernel");
  return MovedLeaves{ report[0], static_cast<std::size_t>(report[1]) };
}

// Engine::Update on a built state (the caller validated `positions`). Sets
// `writing` before its first write to the state.
template <class Device>
UpdateStats UpdateOctree(Device& d, DriverScratch<Device>& scratch, OctreeState<Device>& s,
  const PositionsView& positions, bool& writing)
{
  const auto start = std::chrono::steady_clock::now();
  const std::size_t moved = positions.count;
  UpdateStats stats;
  stats.moved = moved;
  d.Reserve(scratch.counters, kCounterSlots, "counters");
  const StagedMoves<Device> staged = StageMoves(d, positions);
  const std::uint32_t* indices = staged.indices.Get();
  typename Device::template Buffer<std::uint64_t> fromLeaf, toLeaf;
  typename Device::template Buffer<std::uint32_t> changedMoves;
  d.Reserve(fromLeaf, moved, "update moves");
  d.Reserve(toLeaf, moved, "update moves");
  d.Reserve(changedMoves, moved, "update moves");
  std::uint64_t* from = fromLeaf.Get();
  std::uint64_t* into = toLeaf.Get();
  writing = true;
  const MovedLeaves leaves =
    MoveLeaves(d, scratch, s, staged.xyz.View(moved), indices, from, into, changedMoves.Get());
  const std::size_t changed = leaves.changed;
  if (leaves.firstOutside != kNoIndex)
  {
    // A point left the cube: rebuild around the new bounds, at the same depth.
    const Bounds b = PositionBounds(d, s.Points());
    BuildLevels(d, scratch, s, RootCube::FromBounds(b.lo, b.hi), s.depth);
    stats.changedLeaf = moved;
    stats.path = UpdateStats::Path::NewCube;
  }
  else if (changed == 0)
  {
    stats.path = UpdateStats::Path::Unchanged;
  }
  else if (changed <= s.count / kInPlaceUpdateShare && !(s.attributes & kRoundedAttributes) &&
    UpdateInPlace(d, scratch, s, changedMoves.Get(), changed, indices, from, into))
  {
    stats.changedLeaf = changed;
    stats.path = UpdateStats::Path::InPlace;
  }
  else
  {
    // Nodes appear or empty, too many points moved for the in-place path,
    // or the nodes hold rounded means (Attributes.h) that it cannot adjust:
    // the keys computed and sorted again, the levels rebuilt in place.
    BuildLevels(d, scratch, s, s.cube, s.depth);
    stats.changedLeaf = changed;
    stats.path = UpdateStats::Path::Relevel;
  }
  stats.seconds = SecondsSince(start);
  return stats;
}
}
