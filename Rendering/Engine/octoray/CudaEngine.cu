// The CUDA backend: the same per-point and per-node functions as the CPU
// backend (OctreeKernels.h) launched from kernels; CUB does the sorting,
// selection and reductions. A build fills a new device state and swaps it
// in only when it is complete, so a failure (bad input, out of memory)
// leaves the previous octree as it was.
#include "CudaEngine.h"

#include "DepthChoice.h"
#include "DepthSignature.h"
#include "Frame.h"
#include "OctreeKernels.h"

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_reduce.cuh>
#include <cub/device/device_select.cuh>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>

#include <chrono>
#include <cstring>
#include <limits>
#include <type_traits>

namespace octoray
{
namespace
{
constexpr int kBlock = 256;

unsigned Blocks(std::size_t n)
{
  return static_cast<unsigned>((n + kBlock - 1) / kBlock);
}

double SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct Bounds
{
  double lo[3], hi[3];
  unsigned long long firstBad; // index of the first non-finite point, or ~0
};

struct PointBounds
{
  PointArraysView pts;
  __device__ Bounds operator()(std::size_t i) const
  {
    double p[3];
    pts.Position(i, p);
    Bounds b;
    const bool finite = IsFinitePoint(p);
    for (int a = 0; a < 3; ++a)
    {
      b.lo[a] = finite ? p[a] : std::numeric_limits<double>::infinity();
      b.hi[a] = finite ? p[a] : -std::numeric_limits<double>::infinity();
    }
    b.firstBad = finite ? ~0ull : i;
    return b;
  }
};

struct MergeBounds
{
  __device__ Bounds operator()(const Bounds& x, const Bounds& y) const
  {
    Bounds b;
    for (int a = 0; a < 3; ++a)
    {
      b.lo[a] = fmin(x.lo[a], y.lo[a]);
      b.hi[a] = fmax(x.hi[a], y.hi[a]);
    }
    b.firstBad = x.firstBad < y.firstBad ? x.firstBad : y.firstBad;
    return b;
  }
};

// Sorted position i starts a run of equal (key >> shift).
struct IsRunStart
{
  const std::uint64_t* keys;
  int shift;
  __device__ bool operator()(std::uint32_t i) const
  {
    return i == 0 || (keys[i] >> shift) != (keys[i - 1] >> shift);
  }
};

__global__ void WidenColor8Kernel(const std::uint8_t* in, int components, std::size_t n, std::uint8_t* out)
{
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i < n)
  {
    for (int c = 0; c < 4; ++c)
    {
      out[4 * i + c] = c < components ? in[components * i + c] : 255;
    }
  }
}

__global__ void WidenColorFloatKernel(const float* in, int components, std::size_t n, Rgba* out)
{
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i < n)
  {
    const float* c = in + components * i;
    out[i] = Rgba{ c[0], c[1], c[2], components == 4 ? c[3] : 1.0f };
  }
}

__global__ void UnitNormalKernel(const float* in, std::size_t n, Vec3f* out)
{
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i < n)
  {
    out[i] = UnitNormal(in[3 * i], in[3 * i + 1], in[3 * i + 2]);
  }
}

// Full-depth keys, the (leaf key, index) pairs to sort, and the first point
// outside the cube (there should be none: the cube was fitted or checked).
__global__ void KeysKernel(PointArraysView pts, RootCube cube, int leafShift, std::uint64_t* pointKey,
  std::uint64_t* sortKey, std::uint32_t* sortIndex, unsigned long long* firstOutside)
{
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i < pts.count)
  {
    std::uint64_t key = 0;
    if (!ComputePointKey(pts, cube, i, key))
    {
      atomicMin(firstOutside, static_cast<unsigned long long>(i));
    }
    pointKey[i] = key;
    sortKey[i] = key >> leafShift;
    sortIndex[i] = static_cast<std::uint32_t>(i);
  }
}

__global__ void ShiftKernel(std::uint64_t* keys, std::size_t n, int shift)
{
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i < n)
  {
    keys[i] >>= shift;
  }
}

// Both DepthChoice histograms of sorted keys (full-depth after << toFull).
__global__ void NeighbourHistogramKernel(const std::uint64_t* sorted, std::size_t n, int toFull,
  unsigned long long* histograms)
{
  __shared__ unsigned int local[2 * kDepthHistogramBins];
  for (int b = threadIdx.x; b < 2 * kDepthHistogramBins; b += blockDim.x)
  {
    local[b] = 0;
  }
  __syncthreads();
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i < n)
  {
    const std::uint64_t k = sorted[i] << toFull;
    const int withPrev = i > 0 ? SharedLevels(sorted[i - 1] << toFull, k) : -1;
    const int withNext = i + 1 < n ? SharedLevels(k, sorted[i + 1] << toFull) : -1;
    if (i > 0)
    {
      atomicAdd(&local[withPrev + 1], 1u);
    }
    atomicAdd(&local[kDepthHistogramBins + (withPrev > withNext ? withPrev : withNext) + 1], 1u);
  }
  __syncthreads();
  for (int b = threadIdx.x; b < 2 * kDepthHistogramBins; b += blockDim.x)
  {
    if (local[b])
    {
      atomicAdd(&histograms[b], static_cast<unsigned long long>(local[b]));
    }
  }
}

__global__ void LeafKernel(OctreeView t, PointArraysView pts, const std::uint32_t* sortIndex,
  const std::uint64_t* sortKey, const std::uint32_t* starts, std::uint32_t leaves)
{
  const std::uint32_t j = blockIdx.x * blockDim.x + threadIdx.x;
  if (j < leaves)
  {
    ReduceLeaf(t, pts, sortIndex, t.levelBegin[t.depth] + j, sortKey[starts[j]], starts[j], starts[j + 1]);
  }
}

__global__ void InnerKernel(OctreeView t, int level, const std::uint32_t* starts)
{
  const std::uint32_t j = blockIdx.x * blockDim.x + threadIdx.x;
  if (j < t.LevelSize(level))
  {
    const std::uint32_t c0 = t.levelBegin[level + 1] + starts[j];
    const std::uint32_t c1 = t.levelBegin[level + 1] + starts[j + 1];
    ReduceChildren(t, t.levelBegin[level] + j, t.key[c0] >> 3, c0, c1);
  }
}

// The first of n xyz triples with a NaN or infinite coordinate.
template <typename T>
__global__ void FirstNonFiniteKernel(const T* xyz, std::size_t n, unsigned long long* first)
{
  const std::size_t k = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (k < n)
  {
    const double p[3] = { double(xyz[3 * k]), double(xyz[3 * k + 1]), double(xyz[3 * k + 2]) };
    if (!IsFinitePoint(p))
    {
      atomicMin(first, static_cast<unsigned long long>(k));
    }
  }
}

template <typename T>
__global__ void ScatterPositionsKernel(const T* xyz, const std::uint32_t* indices, std::size_t moved, float* xyzFloat,
  double* xyzDouble)
{
  const std::size_t k = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (k < moved)
  {
    const std::size_t i = indices ? indices[k] : k;
    for (int a = 0; a < 3; ++a)
    {
      if (xyzDouble)
      {
        xyzDouble[3 * i + a] = static_cast<double>(xyz[3 * k + a]);
      }
      else
      {
        xyzFloat[3 * i + a] = static_cast<float>(xyz[3 * k + a]);
      }
    }
  }
}

// A point that changed leaf in an update (leaf keys before and after).
struct LeafMove
{
  std::uint32_t point;
  std::uint64_t from, to;
};

// New keys of moved points: lists those that left their leaf, and flags
// (first index) a point outside the cube.
__global__ void MovedKeysKernel(PointArraysView pts, RootCube cube, int leafShift, const std::uint32_t* indices,
  std::size_t moved, std::uint64_t* pointKey, LeafMove* moves, unsigned long long* changedLeaf,
  unsigned long long* firstOutside)
{
  const std::size_t k = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (k < moved)
  {
    const std::size_t i = indices ? indices[k] : k;
    std::uint64_t key = 0;
    if (!ComputePointKey(pts, cube, i, key))
    {
      atomicMin(firstOutside, static_cast<unsigned long long>(i));
      return;
    }
    if ((key >> leafShift) != (pointKey[i] >> leafShift))
    {
      const unsigned long long slot = atomicAdd(changedLeaf, 1ull);
      moves[slot] = LeafMove{ static_cast<std::uint32_t>(i), pointKey[i] >> leafShift, key >> leafShift };
    }
    pointKey[i] = key;
  }
}

// For each move, the depth+1 nodes on the path from its old leaf to the
// root (the point leaves them) and from its new leaf (it joins them), as
// (node, 2 * point + joins) records. A new leaf that does not exist means
// the topology changes: flagged, and its records point nowhere.
__global__ void PathRecordsKernel(OctreeView t, const LeafMove* moves, std::size_t count, std::uint32_t* recordNode,
  std::uint32_t* recordPoint, unsigned* topologyChanged)
{
  const std::size_t k = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (k >= count)
  {
    return;
  }
  const LeafMove m = moves[k];
  const std::size_t pathLength = static_cast<std::size_t>(t.depth) + 1;
  for (int joins = 0; joins < 2; ++joins)
  {
    std::uint32_t node = t.Find(t.depth, joins ? m.to : m.from);
    if (node == kInvalidIndex)
    {
      *topologyChanged = 1u;
    }
    const std::size_t base = (2 * k + joins) * pathLength;
    for (std::size_t step = 0; step < pathLength; ++step)
    {
      recordNode[base + step] = node;
      recordPoint[base + step] = 2u * m.point + static_cast<std::uint32_t>(joins);
      node = node == kInvalidIndex ? kInvalidIndex : t.parent[node];
    }
  }
}

struct IsRunStart32
{
  const std::uint32_t* keys;
  __device__ bool operator()(std::uint32_t i) const
  {
    return i == 0 || keys[i] != keys[i - 1];
  }
};

// Per node touched (a run of sorted records): would it empty?
__global__ void EmptiedNodesKernel(OctreeView t, const std::uint32_t* recordNode, const std::uint32_t* recordPoint,
  const std::uint32_t* starts, std::uint32_t runs, unsigned* emptied)
{
  const std::uint32_t r = blockIdx.x * blockDim.x + threadIdx.x;
  if (r >= runs || recordNode[starts[r]] == kInvalidIndex)
  {
    return;
  }
  long long dCount = 0;
  for (std::uint32_t j = starts[r]; j < starts[r + 1]; ++j)
  {
    dCount += (recordPoint[j] & 1u) ? 1 : -1;
  }
  if (static_cast<long long>(t.pointCount[recordNode[starts[r]]]) + dCount <= 0)
  {
    *emptied = 1u;
  }
}

// Per node touched: adjust its count and means by the points that left and
// joined it (the in-place update, as on the CPU).
__global__ void ApplyDeltasKernel(OctreeView t, PointArraysView pts, const std::uint32_t* recordNode,
  const std::uint32_t* recordPoint, const std::uint32_t* starts, std::uint32_t runs)
{
  const std::uint32_t r = blockIdx.x * blockDim.x + threadIdx.x;
  if (r >= runs)
  {
    return;
  }
  long long dCount = 0;
  double dSum[kSlotCount] = {};
  float v[kSlotCount] = {};
  for (std::uint32_t j = starts[r]; j < starts[r + 1]; ++j)
  {
    const bool joins = recordPoint[j] & 1u;
    dCount += joins ? 1 : -1;
    pts.Attributes(recordPoint[j] >> 1, v);
    for (int s = 0; s < kSlotCount; ++s)
    {
      dSum[s] += joins ? v[s] : -v[s];
    }
  }
  ApplyNodeDelta(t, recordNode[starts[r]], dCount, dSum);
}

// A premultiplied channel in [0,1] as a byte, as ChannelToByte on the host.
__device__ std::uint8_t DeviceChannelToByte(float v)
{
  v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
  return static_cast<std::uint8_t>(__fadd_rn(__fmul_rn(v, 255.0f), 0.5f));
}

template <typename F>
__global__ void RenderKernel(FrameConstants f, OctreeView tree, float* rgba, std::uint8_t* rgba8, float* depth,
  unsigned long long* secondaryRays)
{
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  if (x >= f.width)
  {
    return;
  }
  // Rows stride over the grid: a viewport taller than the grid's y limit
  // (65535 blocks) is still covered.
  std::size_t rays = 0;
  for (int y = blockIdx.y * blockDim.y + threadIdx.y; y < f.height; y += gridDim.y * blockDim.y)
  {
    const std::size_t i = static_cast<std::size_t>(y) * f.width + x;
    float pixel[4];
    RenderPixel<F>(f, tree, x, y, pixel, depth[i], rays);
    if (rgba8)
    {
      reinterpret_cast<uchar4*>(rgba8)[i] = make_uchar4(DeviceChannelToByte(pixel[0]),
        DeviceChannelToByte(pixel[1]), DeviceChannelToByte(pixel[2]), DeviceChannelToByte(pixel[3]));
    }
    else
    {
      reinterpret_cast<float4*>(rgba)[i] = make_float4(pixel[0], pixel[1], pixel[2], pixel[3]);
    }
  }
  if (rays)
  {
    atomicAdd(secondaryRays, static_cast<unsigned long long>(rays));
  }
}

template <typename T>
void Upload(DeviceMemoryPool& pool, DeviceBuffer<T>& buffer, const T* host, std::size_t n, const char* what)
{
  buffer.Reserve(pool, n, what);
  CudaCheck(cudaMemcpy(buffer.Get(), host, n * sizeof(T), cudaMemcpyHostToDevice), what);
}

template <typename T>
void Download(const DeviceBuffer<T>& buffer, std::vector<T>& host)
{
  host.resize(buffer.Count());
  if (!host.empty())
  {
    CudaCheck(cudaMemcpy(host.data(), buffer.Get(), host.size() * sizeof(T), cudaMemcpyDeviceToHost),
      "copy of the octree to the host");
  }
}
}

PointArraysView CudaEngine::DeviceState::Points() const
{
  PointArraysView v;
  v.count = count;
  v.xyzFloat = xyzFloat.Empty() ? nullptr : xyzFloat.Get();
  v.xyzDouble = xyzDouble.Empty() ? nullptr : xyzDouble.Get();
  v.color8 = color8.Empty() ? nullptr : color8.Get();
  v.colorFloat = colorFloat.Empty() ? nullptr : colorFloat.Get();
  v.scalar = scalar.Empty() ? nullptr : scalar.Get();
  v.reflectivity = reflectivity.Empty() ? nullptr : reflectivity.Get();
  v.refraction = refraction.Empty() ? nullptr : refraction.Get();
  v.normal = normal.Empty() ? nullptr : normal.Get();
  return v;
}

OctreeView CudaEngine::DeviceState::View() const
{
  OctreeView v;
  v.depth = depth;
  v.nodeCount = static_cast<std::uint32_t>(key.Count());
  std::memcpy(v.levelBegin, levelBegin, sizeof(levelBegin));
  v.attributes = attributes;
  v.cube = cube;
  v.key = key.Get();
  v.childMask = childMask.Get();
  v.firstChild = firstChild.Get();
  v.parent = parent.Get();
  v.pointCount = pointCount.Get();
  v.color = nodeColor.Empty() ? nullptr : nodeColor.Get();
  v.scalar = nodeScalar.Empty() ? nullptr : nodeScalar.Get();
  v.reflectivity = nodeReflectivity.Empty() ? nullptr : nodeReflectivity.Get();
  v.refraction = nodeRefraction.Empty() ? nullptr : nodeRefraction.Get();
  v.normal = nodeNormal.Empty() ? nullptr : nodeNormal.Get();
  return v;
}

CudaEngine::CudaEngine(int device)
{
  if (device < 0)
  {
    CudaCheck(cudaGetDevice(&device), "cudaGetDevice");
  }
  Device = device;
  cudaDeviceProp prop;
  CudaCheck(cudaGetDeviceProperties(&prop, device), "cudaGetDeviceProperties");
  DeviceName = prop.name;
  State = std::make_unique<DeviceState>();
}

CudaEngine::~CudaEngine()
{
  DestructionScope = std::make_unique<ScopedDevice>(Device);
}

std::string CudaEngine::Description() const
{
  int count = 0;
  cudaGetDeviceCount(&count);
  return "CUDA (" + DeviceName + (count > 1 ? ", device " + std::to_string(Device) : std::string()) + ")";
}

// DepthSignatureTerm of pixel i, for the reduction below.
struct DepthTerm
{
  const float* depth;
  __device__ std::uint64_t operator()(std::size_t i) const { return DepthSignatureTerm(depth[i], i); }
};

std::uint64_t CudaEngine::DeviceDepthSignature(const float* deviceDepth, std::size_t count)
{
  const ScopedDevice scope(Device);
  auto in = thrust::make_transform_iterator(thrust::counting_iterator<std::size_t>(0), DepthTerm{ deviceDepth });
  DeviceBuffer<std::uint64_t> sum;
  sum.Reserve(Pool, 1, "counters");
  std::size_t bytes = 0;
  CudaCheck(cub::DeviceReduce::Sum(nullptr, bytes, in, sum.Get(), count), "cub::DeviceReduce (depth signature)");
  CudaCheck(cub::DeviceReduce::Sum(CubTemp(bytes), bytes, in, sum.Get(), count), "cub::DeviceReduce (depth signature)");
  std::uint64_t result = 0;
  CudaCheck(cudaMemcpy(&result, sum.Get(), sizeof result, cudaMemcpyDeviceToHost), "depth signature");
  return result + count;
}

DeviceImage CudaEngine::LastDeviceImage() const
{
  DeviceImage image;
  if (ImageWidth > 0)
  {
    image.width = ImageWidth;
    image.height = ImageHeight;
    image.device = Device;
    image.rgba = ImageIs8Bit ? nullptr : ImageRgba.Get();
    image.rgba8 = ImageIs8Bit ? ImageRgba8.Get() : nullptr;
    image.depth = ImageDepth.Get();
  }
  return image;
}

void* CudaEngine::CubTemp(std::size_t bytes)
{
  CubScratch.Reserve(Pool, bytes, "CUB temporary storage");
  return CubScratch.Get();
}

BuildStats CudaEngine::Build(const PointCloudView& points, const BuildOptions& options)
{
  const ScopedDevice scope(Device);
  ValidateCloud(points);
  ValidateDepth(options.depth);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t n = points.count;

  // Everything goes into a new state; it replaces the current one at the end.
  auto next = std::make_unique<DeviceState>();
  DeviceState& s = *next;
  s.count = n;
  s.attributes = points.Attributes();
  if (points.xyzFloat)
  {
    Upload(Pool, s.xyzFloat, points.xyzFloat, 3 * n, "point positions");
  }
  else
  {
    Upload(Pool, s.xyzDouble, points.xyzDouble, 3 * n, "point positions");
  }
  const int cc = points.colorComponents;
  if (points.color8)
  {
    DeviceBuffer<std::uint8_t> raw;
    Upload(Pool, raw, points.color8, cc * n, "point colours");
    s.color8.Reserve(Pool, 4 * n, "point colours");
    OCTORAY_LAUNCH(WidenColor8Kernel, Blocks(n), kBlock, raw.Get(), cc, n, s.color8.Get());
    CudaCheck(cudaDeviceSynchronize(), "WidenColor8Kernel");
  }
  else if (points.colorFloat)
  {
    DeviceBuffer<float> raw;
    Upload(Pool, raw, points.colorFloat, cc * n, "point colours");
    s.colorFloat.Reserve(Pool, n, "point colours");
    OCTORAY_LAUNCH(WidenColorFloatKernel, Blocks(n), kBlock, raw.Get(), cc, n, s.colorFloat.Get());
    CudaCheck(cudaDeviceSynchronize(), "WidenColorFloatKernel");
  }
  if (points.scalar)
  {
    Upload(Pool, s.scalar, points.scalar, n, "point scalars");
  }
  if (points.reflectivity)
  {
    Upload(Pool, s.reflectivity, points.reflectivity, n, "point reflectivities");
  }
  if (points.refraction)
  {
    Upload(Pool, s.refraction, points.refraction, n, "point refraction indices");
  }
  if (points.normal)
  {
    DeviceBuffer<float> raw;
    Upload(Pool, raw, points.normal, 3 * n, "point normals");
    s.normal.Reserve(Pool, n, "point normals");
    OCTORAY_LAUNCH(UnitNormalKernel, Blocks(n), kBlock, raw.Get(), n, s.normal.Get());
    CudaCheck(cudaDeviceSynchronize(), "UnitNormalKernel");
  }

  double lo[3], hi[3];
  DataBounds(s, lo, hi);
  RootCube cube = RootCube::FromBounds(lo, hi);
  if (options.fixedCube)
  {
    cube = options.cube;
    std::uint32_t cell[3];
    if (!cube.GridCell(lo[0], lo[1], lo[2], cell) || !cube.GridCell(hi[0], hi[1], hi[2], cell))
    {
      // Name the first point outside, as the CPU backend does.
      for (std::size_t i = 0; i < n; ++i)
      {
        const double p[3] = { points.Coordinate(i, 0), points.Coordinate(i, 1), points.Coordinate(i, 2) };
        if (!cube.GridCell(p[0], p[1], p[2], cell))
        {
          throw Error(OutsideCubeMessage(i, p));
        }
      }
    }
  }
  BuildStats stats = BuildFromState(s, cube, options.depth);
  State = std::move(next);
  DiscardedByUpdate = false;
  stats.bytes = Memory().Total();
  stats.seconds = SecondsSince(start);
  return stats;
}

void CudaEngine::DataBounds(const DeviceState& s, double lo[3], double hi[3])
{
  const PointArraysView pts = s.Points();
  auto in = thrust::make_transform_iterator(thrust::counting_iterator<std::size_t>(0), PointBounds{ pts });
  Bounds identity;
  for (int a = 0; a < 3; ++a)
  {
    identity.lo[a] = std::numeric_limits<double>::infinity();
    identity.hi[a] = -std::numeric_limits<double>::infinity();
  }
  identity.firstBad = ~0ull;
  DeviceBuffer<Bounds> out;
  out.Reserve(Pool, 1, "bounds");
  std::size_t tempBytes = 0;
  CudaCheck(cub::DeviceReduce::Reduce(nullptr, tempBytes, in, out.Get(), s.count, MergeBounds(), identity),
    "cub::DeviceReduce (bounds)");
  CudaCheck(cub::DeviceReduce::Reduce(CubTemp(tempBytes), tempBytes, in, out.Get(), s.count, MergeBounds(), identity),
    "cub::DeviceReduce (bounds)");
  Bounds b;
  CudaCheck(cudaMemcpy(&b, out.Get(), sizeof(Bounds), cudaMemcpyDeviceToHost), "bounds");
  if (b.firstBad != ~0ull)
  {
    double p[3];
    if (!s.xyzDouble.Empty())
    {
      CudaCheck(cudaMemcpy(p, s.xyzDouble.Get() + 3 * b.firstBad, sizeof(p), cudaMemcpyDeviceToHost), "point");
    }
    else
    {
      float f[3];
      CudaCheck(cudaMemcpy(f, s.xyzFloat.Get() + 3 * b.firstBad, sizeof(f), cudaMemcpyDeviceToHost), "point");
      p[0] = f[0], p[1] = f[1], p[2] = f[2];
    }
    throw Error(NonFinitePointMessage(b.firstBad, p));
  }
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = b.lo[a];
    hi[a] = b.hi[a];
  }
}

BuildStats CudaEngine::BuildFromState(DeviceState& s, const RootCube& cube, int requestedDepth)
{
  const std::size_t n = s.count;
  const PointArraysView pts = s.Points();
  BuildStats stats;
  stats.points = n;

  auto phase = std::chrono::steady_clock::now();
  s.pointKey.Reserve(Pool, n, "point keys");
  for (auto* b : { &SortKey[0], &SortKey[1] })
  {
    b->Reserve(Pool, n, "sort keys");
  }
  for (auto* b : { &SortIndex[0], &SortIndex[1] })
  {
    b->Reserve(Pool, n, "sort indices");
  }
  DeviceBuffer<unsigned long long> flags;
  flags.Reserve(Pool, 2 * kDepthHistogramBins, "counters");
  CudaCheck(cudaMemset(flags.Get(), 0xFF, sizeof(unsigned long long)), "cudaMemset");
  const int fullShift = requestedDepth > 0 ? 3 * (kMaxLevel - requestedDepth) : 0;
  OCTORAY_LAUNCH(KeysKernel, Blocks(n), kBlock, pts, cube, fullShift, s.pointKey.Get(), SortKey[0].Get(), SortIndex[0].Get(),
    flags.Get());
  unsigned long long firstOutside = 0;
  CudaCheck(cudaMemcpy(&firstOutside, flags.Get(), sizeof(firstOutside), cudaMemcpyDeviceToHost), "KeysKernel");
  if (firstOutside != ~0ull)
  {
    double p[3] = { 0, 0, 0 };
    throw Error(OutsideCubeMessage(firstOutside, p));
  }
  stats.keySeconds = SecondsSince(phase);

  phase = std::chrono::steady_clock::now();
  int depth = requestedDepth;
  const int sortBits = depth > 0 ? 3 * depth : 3 * kMaxLevel;
  cub::DoubleBuffer<std::uint64_t> keys(SortKey[0].Get(), SortKey[1].Get());
  cub::DoubleBuffer<std::uint32_t> values(SortIndex[0].Get(), SortIndex[1].Get());
  std::size_t tempBytes = 0;
  CudaCheck(cub::DeviceRadixSort::SortPairs(nullptr, tempBytes, keys, values, n, 0, sortBits),
    "cub::DeviceRadixSort");
  CudaCheck(cub::DeviceRadixSort::SortPairs(CubTemp(tempBytes), tempBytes, keys, values, n, 0, sortBits),
    "cub::DeviceRadixSort");
  std::uint64_t* sortedKey = keys.Current();
  std::uint32_t* sortedIndex = values.Current();

  // Node counts of every level (and, for an automatic depth, the depth) from
  // one histogram of neighbouring keys.
  unsigned long long histograms[2 * kDepthHistogramBins];
  auto histogram = [&](int toFull) {
    CudaCheck(cudaMemset(flags.Get(), 0, 2 * kDepthHistogramBins * sizeof(unsigned long long)), "cudaMemset");
    OCTORAY_LAUNCH(NeighbourHistogramKernel, Blocks(n), kBlock, sortedKey, n, toFull, flags.Get());
    CudaCheck(cudaMemcpy(histograms, flags.Get(), sizeof(histograms), cudaMemcpyDeviceToHost),
      "NeighbourHistogramKernel");
  };
  if (depth == 0)
  {
    histogram(0);
    depth = ChooseDepthFromHistograms(reinterpret_cast<std::uint64_t*>(histograms),
      reinterpret_cast<std::uint64_t*>(histograms + kDepthHistogramBins));
    OCTORAY_LAUNCH(ShiftKernel, Blocks(n), kBlock, sortedKey, n, 3 * (kMaxLevel - depth));
  }
  histogram(3 * (kMaxLevel - depth));
  stats.sortSeconds = SecondsSince(phase);

  phase = std::chrono::steady_clock::now();
  s.depth = depth;
  s.cube = cube;
  std::memset(s.levelBegin, 0, sizeof(s.levelBegin));
  unsigned long long distinct = 1;
  for (int l = 0; l <= kMaxLevel; ++l)
  {
    // Keys that share fewer than l levels with their predecessor start a node.
    if (l > 0)
    {
      distinct += histograms[l]; // bin l-1
    }
    s.levelBegin[l + 1] = s.levelBegin[l] + (l <= depth ? static_cast<std::uint32_t>(distinct) : 0);
  }
  const std::size_t nodes = s.levelBegin[depth + 1];
  s.key.Reserve(Pool, nodes, "node keys");
  s.childMask.Reserve(Pool, nodes, "node child masks");
  s.firstChild.Reserve(Pool, nodes, "node first children");
  s.parent.Reserve(Pool, nodes, "node parents");
  s.pointCount.Reserve(Pool, nodes, "node point counts");
  auto optional = [&](auto& buffer, unsigned bit, const char* what) {
    if (s.attributes & bit)
    {
      buffer.Reserve(Pool, nodes, what);
    }
    else
    {
      buffer.Release();
    }
  };
  optional(s.nodeColor, kHasColor, "node colours");
  optional(s.nodeScalar, kHasScalar, "node scalars");
  optional(s.nodeReflectivity, kHasReflectivity, "node reflectivities");
  optional(s.nodeRefraction, kHasRefraction, "node refraction indices");
  optional(s.nodeNormal, kHasNormal, "node normals");
  const OctreeView view = s.View();

  Starts.Reserve(Pool, n + 1, "run starts");
  DeviceBuffer<int> selected;
  selected.Reserve(Pool, 1, "counters");
  auto runStarts = [&](const std::uint64_t* levelKeys, std::size_t count, int shift, std::uint32_t expected) {
    auto in = thrust::counting_iterator<std::uint32_t>(0);
    std::size_t bytes = 0;
    CudaCheck(cub::DeviceSelect::If(nullptr, bytes, in, Starts.Get(), selected.Get(), count, IsRunStart{ levelKeys, shift }),
      "cub::DeviceSelect (run starts)");
    CudaCheck(cub::DeviceSelect::If(CubTemp(bytes), bytes, in, Starts.Get(), selected.Get(), count,
                IsRunStart{ levelKeys, shift }),
      "cub::DeviceSelect (run starts)");
    const std::uint32_t end = static_cast<std::uint32_t>(count);
    CudaCheck(cudaMemcpy(Starts.Get() + expected, &end, sizeof(end), cudaMemcpyHostToDevice), "run starts");
  };
  runStarts(sortedKey, n, 0, view.LevelSize(depth));
  OCTORAY_LAUNCH(LeafKernel, Blocks(view.LevelSize(depth)), kBlock, view, pts, sortedIndex, sortedKey, Starts.Get(),
    view.LevelSize(depth));
  for (int l = depth - 1; l >= 0; --l)
  {
    runStarts(view.key + view.levelBegin[l + 1], view.LevelSize(l + 1), 3, view.LevelSize(l));
    OCTORAY_LAUNCH(InnerKernel, Blocks(view.LevelSize(l)), kBlock, view, l, Starts.Get());
  }
  const std::uint32_t none = kInvalidIndex;
  CudaCheck(cudaMemcpy(view.parent, &none, sizeof(none), cudaMemcpyHostToDevice), "root parent");
  CudaCheck(cudaDeviceSynchronize(), "octree build");
  stats.levelSeconds = SecondsSince(phase);

  stats.depth = depth;
  stats.cube = cube;
  stats.nodes = nodes;
  for (int l = 0; l <= depth; ++l)
  {
    stats.nodesPerLevel.push_back(view.LevelSize(l));
  }
  return stats;
}

UpdateStats CudaEngine::Update(const PositionsView& positions)
{
  const ScopedDevice scope(Device);
  if (State->count == 0 && DiscardedByUpdate)
  {
    throw Error("octoray: update after a failed update discarded the octree; build again");
  }
  ValidateUpdate(positions, State->count);
  // An update writes into the octree it updates. When it fails after the
  // first write (a refused launch, out of memory), points and nodes may
  // disagree and no picture drawn from them could be trusted, so the octree
  // is dropped (its memory freed) and the caller is told to build again.
  bool writing = false;
  try
  {
    return UpdateState(*State, positions, writing);
  }
  catch (const Error& e)
  {
    if (!writing)
    {
      throw;
    }
    State = std::make_unique<DeviceState>();
    DiscardedByUpdate = true;
    throw Error(std::string(e.what()) + " (the update had begun: the octree was discarded; build again)");
  }
}

UpdateStats CudaEngine::UpdateState(DeviceState& s, const PositionsView& positions, bool& writing)
{
  const auto start = std::chrono::steady_clock::now();
  const std::size_t moved = positions.count;
  UpdateStats stats;
  stats.moved = moved;

  DeviceBuffer<std::uint32_t> indices;
  if (positions.indices)
  {
    Upload(Pool, indices, positions.indices, moved, "update indices");
  }
  float* xyzFloat = s.xyzFloat.Empty() ? nullptr : s.xyzFloat.Get();
  double* xyzDouble = s.xyzDouble.Empty() ? nullptr : s.xyzDouble.Get();
  // The new positions are checked on the device before any is written, so
  // that a non-finite one is refused with nothing changed.
  auto checkAndScatter = [&](auto* host) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(host)>>;
    DeviceBuffer<T> xyz;
    Upload(Pool, xyz, host, 3 * moved, "update positions");
    DeviceBuffer<unsigned long long> firstBad;
    firstBad.Reserve(Pool, 1, "counters");
    CudaCheck(cudaMemset(firstBad.Get(), 0xFF, sizeof(unsigned long long)), "cudaMemset");
    OCTORAY_LAUNCH(FirstNonFiniteKernel, Blocks(moved), kBlock, xyz.Get(), moved, firstBad.Get());
    unsigned long long bad = 0;
    CudaCheck(cudaMemcpy(&bad, firstBad.Get(), sizeof(bad), cudaMemcpyDeviceToHost), "FirstNonFiniteKernel");
    if (bad != ~0ull)
    {
      const double p[3] = { double(host[3 * bad]), double(host[3 * bad + 1]), double(host[3 * bad + 2]) };
      throw Error(NonFinitePointMessage(positions.indices ? positions.indices[bad] : bad, p));
    }
    writing = true;
    OCTORAY_LAUNCH(ScatterPositionsKernel, Blocks(moved), kBlock, xyz.Get(), indices.Get(), moved, xyzFloat, xyzDouble);
    CudaCheck(cudaDeviceSynchronize(), "ScatterPositionsKernel");
  };
  if (positions.xyzDouble)
  {
    checkAndScatter(positions.xyzDouble);
  }
  else
  {
    checkAndScatter(positions.xyzFloat);
  }

  const int leafShift = 3 * (kMaxLevel - s.depth);
  DeviceBuffer<unsigned long long> counters;
  counters.Reserve(Pool, 2, "counters");
  const unsigned long long init[2] = { 0ull, ~0ull };
  CudaCheck(cudaMemcpy(counters.Get(), init, sizeof(init), cudaMemcpyHostToDevice), "counters");
  DeviceBuffer<LeafMove> moves;
  moves.Reserve(Pool, moved, "update moves");
  OCTORAY_LAUNCH(MovedKeysKernel, Blocks(moved), kBlock, s.Points(), s.cube, leafShift, indices.Get(), moved, s.pointKey.Get(),
    moves.Get(), counters.Get(), counters.Get() + 1);
  unsigned long long result[2];
  CudaCheck(cudaMemcpy(result, counters.Get(), sizeof(result), cudaMemcpyDeviceToHost), "MovedKeysKernel");

  if (result[1] != ~0ull)
  {
    double lo[3], hi[3];
    DataBounds(s, lo, hi);
    BuildFromState(s, RootCube::FromBounds(lo, hi), s.depth);
    stats.changedLeaf = moved;
    stats.path = UpdateStats::Path::NewCube;
  }
  else if (result[0] == 0)
  {
    stats.path = UpdateStats::Path::Unchanged;
  }
  else if (result[0] <= s.count / 16 && UpdateInPlace(s, moves.Get(), result[0]))
  {
    stats.changedLeaf = result[0];
    stats.path = UpdateStats::Path::InPlace;
  }
  else
  {
    // Nodes appear or empty (or too many points moved for the in-place
    // path to pay): rebuild keys, sort and levels in the same buffers.
    stats.changedLeaf = result[0];
    BuildFromState(s, s.cube, s.depth);
    stats.path = UpdateStats::Path::Relevel;
  }
  stats.seconds = SecondsSince(start);
  return stats;
}

RenderStats CudaEngine::Render(const RenderSettings& settings, Image& image)
{
  const ScopedDevice scope(Device);
  ImageWidth = ImageHeight = 0; // no picture until this one is complete
  const DeviceState& s = *State;
  if (s.count == 0)
  {
    throw Error(DiscardedByUpdate ? "octoray: render after a failed update discarded the octree; build again"
                                  : "octoray: render before any build");
  }
  const auto start = std::chrono::steady_clock::now();
  const OctreeView view = s.View();
  FrameConstants frame = MakeFrame(settings, s.cube, view.reflectivity != nullptr || view.refraction != nullptr);
  const std::size_t pixels = static_cast<std::size_t>(settings.width) * settings.height;
  if (frame.transfer)
  {
    Upload(Pool, Transfer, settings.transfer.table.data(), settings.transfer.table.size(), "transfer function");
    frame.transfer = Transfer.Get();
  }
  if (settings.deviceDepthBuffer)
  {
    if (frame.depthBuffer)
    {
      throw Error("octoray: a depth buffer in host and in device memory at once");
    }
    frame.depthBuffer = settings.deviceDepthBuffer;
  }
  else if (frame.depthBuffer)
  {
    Upload(Pool, DepthIn, settings.depthBuffer.data(), pixels, "depth buffer");
    frame.depthBuffer = DepthIn.Get();
  }
  if (settings.rgba8)
  {
    ImageRgba8.Reserve(Pool, 4 * pixels, "image colours");
  }
  else
  {
    ImageRgba.Reserve(Pool, 4 * pixels, "image colours");
  }
  ImageDepth.Reserve(Pool, pixels, "image depth");
  RayCounter.Reserve(Pool, 1, "counters");
  DeviceBuffer<unsigned long long>& counter = RayCounter;
  CudaCheck(cudaMemset(counter.Get(), 0, sizeof(unsigned long long)), "cudaMemset");
  const dim3 block(16, 8);
  const unsigned rows = (settings.height + block.y - 1) / block.y;
  const dim3 grid((settings.width + block.x - 1) / block.x, rows < 65535u ? rows : 65535u);
  DispatchFeatures(frame, [&](auto features) {
    RenderKernel<decltype(features)><<<LaunchGrid("RenderKernel", grid), block>>>(frame, view, settings.rgba8 ? nullptr : ImageRgba.Get(),
      settings.rgba8 ? ImageRgba8.Get() : nullptr, ImageDepth.Get(), counter.Get());
  });
  CudaCheckLaunch("RenderKernel");
  CudaCheck(cudaDeviceSynchronize(), "RenderKernel");
  RenderStats stats;
  stats.primaryRays = pixels;
  unsigned long long secondary = 0;
  CudaCheck(cudaMemcpy(&secondary, counter.Get(), sizeof(secondary), cudaMemcpyDeviceToHost), "RenderKernel");
  stats.secondaryRays = secondary;
  stats.seconds = SecondsSince(start);
  image.width = ImageWidth = settings.width;
  image.height = ImageHeight = settings.height;
  ImageIs8Bit = settings.rgba8;
  if (settings.copyToHost)
  {
    const auto copy = std::chrono::steady_clock::now();
    if (settings.rgba8)
    {
      Download(ImageRgba8, image.rgba8);
      image.rgba.clear();
    }
    else
    {
      Download(ImageRgba, image.rgba);
      image.rgba8.clear();
    }
    Download(ImageDepth, image.depth);
    stats.copySeconds = SecondsSince(copy);
  }
  else
  {
    image.rgba.clear();
    image.rgba8.clear();
    image.depth.clear();
  }
  return stats;
}

bool CudaEngine::UpdateInPlace(DeviceState& s, const void* deviceMoves, std::size_t changed)
{
  const LeafMove* moves = static_cast<const LeafMove*>(deviceMoves);
  const OctreeView view = s.View();
  const std::size_t records = 2 * changed * (static_cast<std::size_t>(s.depth) + 1);
  DeviceBuffer<std::uint32_t> node[2], point[2];
  for (int b = 0; b < 2; ++b)
  {
    node[b].Reserve(Pool, records, "update records");
    point[b].Reserve(Pool, records, "update records");
  }
  DeviceBuffer<unsigned> flags;
  flags.Reserve(Pool, 2, "counters");
  CudaCheck(cudaMemset(flags.Get(), 0, 2 * sizeof(unsigned)), "cudaMemset");
  OCTORAY_LAUNCH(PathRecordsKernel, Blocks(changed), kBlock, view, moves, changed, node[0].Get(), point[0].Get(), flags.Get());
  unsigned topologyChanged = 0;
  CudaCheck(cudaMemcpy(&topologyChanged, flags.Get(), sizeof(unsigned), cudaMemcpyDeviceToHost), "PathRecordsKernel");
  if (topologyChanged)
  {
    return false;
  }
  // Records grouped by node; the stable sort keeps each node's sums in a
  // fixed order, so repeated updates give the same bits.
  cub::DoubleBuffer<std::uint32_t> keys(node[0].Get(), node[1].Get());
  cub::DoubleBuffer<std::uint32_t> values(point[0].Get(), point[1].Get());
  std::size_t bytes = 0;
  CudaCheck(cub::DeviceRadixSort::SortPairs(nullptr, bytes, keys, values, records), "cub::DeviceRadixSort (update)");
  CudaCheck(cub::DeviceRadixSort::SortPairs(CubTemp(bytes), bytes, keys, values, records),
    "cub::DeviceRadixSort (update)");
  Starts.Reserve(Pool, records + 1, "run starts");
  DeviceBuffer<int> selected;
  selected.Reserve(Pool, 1, "counters");
  auto in = thrust::counting_iterator<std::uint32_t>(0);
  CudaCheck(cub::DeviceSelect::If(nullptr, bytes, in, Starts.Get(), selected.Get(), records,
              IsRunStart32{ keys.Current() }),
    "cub::DeviceSelect (update)");
  CudaCheck(cub::DeviceSelect::If(CubTemp(bytes), bytes, in, Starts.Get(), selected.Get(), records,
              IsRunStart32{ keys.Current() }),
    "cub::DeviceSelect (update)");
  int runs = 0;
  CudaCheck(cudaMemcpy(&runs, selected.Get(), sizeof(int), cudaMemcpyDeviceToHost), "cub::DeviceSelect (update)");
  const std::uint32_t end = static_cast<std::uint32_t>(records);
  CudaCheck(cudaMemcpy(Starts.Get() + runs, &end, sizeof(end), cudaMemcpyHostToDevice), "run starts");
  OCTORAY_LAUNCH(EmptiedNodesKernel, Blocks(runs), kBlock, view, keys.Current(), values.Current(), Starts.Get(), runs,
    flags.Get() + 1);
  unsigned emptied = 0;
  CudaCheck(cudaMemcpy(&emptied, flags.Get() + 1, sizeof(unsigned), cudaMemcpyDeviceToHost), "EmptiedNodesKernel");
  if (emptied)
  {
    return false;
  }
  OCTORAY_LAUNCH(ApplyDeltasKernel, Blocks(runs), kBlock, view, s.Points(), keys.Current(), values.Current(), Starts.Get(), runs);
  CudaCheck(cudaDeviceSynchronize(), "ApplyDeltasKernel");
  return true;
}

void CudaEngine::CopyToHost(HostOctree& out) const
{
  const ScopedDevice scope(Device);
  const DeviceState& s = *State;
  out.depth = s.depth;
  out.cube = s.cube;
  out.attributes = s.attributes;
  out.levelBegin.assign(s.levelBegin, s.levelBegin + kMaxLevel + 2);
  Download(s.key, out.key);
  Download(s.childMask, out.childMask);
  Download(s.firstChild, out.firstChild);
  Download(s.parent, out.parent);
  Download(s.pointCount, out.pointCount);
  Download(s.nodeColor, out.color);
  Download(s.nodeScalar, out.scalar);
  Download(s.nodeReflectivity, out.reflectivity);
  Download(s.nodeRefraction, out.refraction);
  Download(s.nodeNormal, out.normal);
}

MemoryReport CudaEngine::Memory() const
{
  const DeviceState& s = *State;
  MemoryReport m;
  m.Add("node keys", s.key.Bytes());
  m.Add("node child masks", s.childMask.Bytes());
  m.Add("node first children", s.firstChild.Bytes());
  m.Add("node parents", s.parent.Bytes());
  m.Add("node point counts", s.pointCount.Bytes());
  m.Add("node colours", s.nodeColor.Bytes());
  m.Add("node scalars", s.nodeScalar.Bytes());
  m.Add("node reflectivities", s.nodeReflectivity.Bytes());
  m.Add("node refraction indices", s.nodeRefraction.Bytes());
  m.Add("node normals", s.nodeNormal.Bytes());
  m.Add("point positions", s.xyzFloat.Bytes() + s.xyzDouble.Bytes());
  m.Add("point colours", s.color8.Bytes() + s.colorFloat.Bytes());
  m.Add("point scalars", s.scalar.Bytes());
  m.Add("point reflectivities", s.reflectivity.Bytes());
  m.Add("point refraction indices", s.refraction.Bytes());
  m.Add("point normals", s.normal.Bytes());
  m.Add("point keys", s.pointKey.Bytes());
  m.Add("sort buffers", SortKey[0].Bytes() + SortKey[1].Bytes() + SortIndex[0].Bytes() + SortIndex[1].Bytes() +
      Starts.Bytes() + CubScratch.Bytes());
  return m;
}

bool CudaDeviceUsable(std::string* why)
{
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess || count == 0)
  {
    cudaGetLastError();
    if (why)
    {
      *why = status != cudaSuccess ? std::string(cudaGetErrorString(status)) : "no CUDA device";
    }
    return false;
  }
  return true;
}

int CudaDevices()
{
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess)
  {
    cudaGetLastError();
    return 0;
  }
  return count;
}

std::unique_ptr<Engine> CreateCudaEngine(int device)
{
  return std::make_unique<CudaEngine>(device);
}
}
