// octoray_bench_cuda: the CUDA backend measured against what the hardware
// allows, in one run on one GPU:
//  - octree build of 1 M / 10 M / 100 M points beside a bare CUB radix sort
//    of as many keys of 3 x depth bits with 32-bit indices (the build's
//    floor), and at depth 10 and less beside the sort the build runs there:
//    32-bit keys with the points' 8-byte records; the whole call from host
//    arrays beside the pinned copy of their bytes, and the device phases
//    of builds from the same arrays in device memory;
//  - update of 1% and 100% of 10 M points beside a full rebuild;
//  - primary rays and shadow + one-bounce rays at 1920x1080, depth 10 and 16;
//  - GPU bytes per point at depth 10 and 21, with the points kept for
//    updates and without them (the node arrays alone), and per array for
//    100 M points with every attribute;
//  - the upload of the caller's pageable arrays beside plain cudaMemcpy and
//    cudaHostRegister of the same arrays, beside the host's half of the
//    engine's staging alone and at once with the pinned copy, and beside
//    the engine's staged copy alone (--only build skips the rest);
//  - with --billion N: N points generated on the device, built without
//    their points, and traced at 1920x1080 (build time, bytes per point,
//    frame time);
//  - with --profile-build N: two builds of N points at depth 10 and nothing
//    else, for a profiler to list the build's kernels (gpu-check.sh profile-build).
// Times are medians of repeated runs after a warm-up; device work is timed
// with CUDA events (the sort) or synchronised wall clock (whole engine calls).
#include <octoray/Engine.h>
#include <octoray/Frame.h>
#include <octoray/Morton.h>
#include <octoray/CudaUpload.h>
#include <octoray/OctreeKernels.h>

#include "BenchScenes.h"
#include "CommandLine.h"

#include <cub/device/device_radix_sort.cuh>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

using namespace octoray;

namespace
{
double Median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The median of `runs` calls of a measure that times itself.
double MedianOfRuns(int runs, const std::function<double()>& seconds)
{
  std::vector<double> t;
  for (int r = 0; r < runs; ++r)
  {
    t.push_back(seconds());
  }
  return Median(t);
}

double TimeMedian(int repeats, const std::function<void()>& work)
{
  work(); // warm-up: allocations, module load
  std::vector<double> t;
  for (int r = 0; r < repeats; ++r)
  {
    const auto start = std::chrono::steady_clock::now();
    work();
    cudaDeviceSynchronize();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return Median(t);
}

// Gaussian clusters with colours and reflectivity: a cloud like scanned or
// simulated data, not uniform noise.
using Cloud = bench::ColouredCloud;

Cloud MakeCloud(std::size_t n, std::uint64_t seed)
{
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Cloud c;
  c.xyz.resize(3 * n);
  c.rgb.resize(3 * n);
  c.reflectivity.resize(n);
  const float centres[8][3] = { { 0, 0, 0 }, { 4, 1, -2 }, { -3, 3, 1 }, { 2, -4, 3 }, { -2, -2, -3 }, { 3, 3, 3 },
    { -4, 0, 2 }, { 0, 4, -4 } };
  for (std::size_t i = 0; i < n; ++i)
  {
    const int k = static_cast<int>(i & 7);
    const float s = 0.3f + 0.2f * k;
    for (int a = 0; a < 3; ++a)
    {
      c.xyz[3 * i + a] = centres[k][a] + s * g(rng);
      c.rgb[3 * i + a] = static_cast<std::uint8_t>(60 + 25 * k + 20 * a);
    }
    c.reflectivity[i] = k == 0 ? 0.5f : 0.0f;
  }
  return c;
}

// CUB's radix sort of n random keys of `bits` bits, each with a value
// (none where Value is void), on the device: the median of 10 timed runs.
template <typename Key, typename Value>
double SortSeconds(std::size_t n, int bits)
{
  constexpr bool kPairs = !std::is_void<Value>::value;
  using V = std::conditional_t<kPairs, Value, unsigned char>;
  std::vector<Key> keys(n);
  std::mt19937_64 rng(7);
  for (std::size_t i = 0; i < n; ++i)
  {
    keys[i] = static_cast<Key>(rng() >> (64 - bits));
  }
  Key *k0, *k1;
  V *v0 = nullptr, *v1 = nullptr;
  cudaMalloc(&k0, n * sizeof(Key));
  cudaMalloc(&k1, n * sizeof(Key));
  if (kPairs)
  {
    cudaMalloc(&v0, n * sizeof(V));
    cudaMalloc(&v1, n * sizeof(V));
    std::vector<V> values(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      values[i] = static_cast<V>(i);
    }
    cudaMemcpy(v0, values.data(), n * sizeof(V), cudaMemcpyHostToDevice);
  }
  cub::DoubleBuffer<Key> kb(k0, k1);
  cub::DoubleBuffer<V> vb(v0, v1);
  auto sort = [&](void* temp, std::size_t& bytes) {
    return kPairs ? cub::DeviceRadixSort::SortPairs(temp, bytes, kb, vb, n, 0, bits)
                  : cub::DeviceRadixSort::SortKeys(temp, bytes, kb, n, 0, bits);
  };
  std::size_t bytes = 0;
  sort(nullptr, bytes);
  void* temp;
  cudaMalloc(&temp, bytes);
  cudaEvent_t start, stop;
  cudaEventCreate(&start);
  cudaEventCreate(&stop);
  std::vector<double> times;
  for (int r = 0; r < 11; ++r)
  {
    cudaMemcpy(kb.Current(), keys.data(), n * sizeof(Key), cudaMemcpyHostToDevice);
    cudaEventRecord(start);
    sort(temp, bytes);
    cudaEventRecord(stop);
    cudaEventSynchronize(stop);
    float ms = 0;
    cudaEventElapsedTime(&ms, start, stop);
    if (r > 0)
    {
      times.push_back(ms * 1e-3);
    }
  }
  cudaFree(temp);
  cudaFree(k0);
  cudaFree(k1);
  cudaFree(v0);
  cudaFree(v1);
  return Median(times);
}

// The sort the build cannot beat, issue 16's floor: CUB's radix sort of n
// random 64-bit keys of `bits` bits with 32-bit indices.
double SortFloorSeconds(std::size_t n, int bits)
{
  return SortSeconds<std::uint64_t, std::uint32_t>(n, bits);
}

// The sort the build runs on the benchmark's cloud where its leaf keys fit
// 32 bits (depth 10 and less): each key with its point's record of two
// words, colours and reflectivity (SortedKeys, OctreeKernels.h); 0 deeper,
// where it sorts the floor's pairs.
double BuildSortSeconds(std::size_t n, int depth)
{
  return SortedKeys::Narrow(depth) ? SortSeconds<std::uint32_t, std::uint64_t>(n, 3 * depth) : 0.0;
}

// A caller's host array the build reads; of unit values (the
// reflectivity: Attributes.h's UnitInput), whose codes the staging lands,
// half its bytes.
struct HostArray
{
  void* data;
  std::size_t bytes;
  bool unitCodes = false;

  std::size_t StagedBytes() const { return unitCodes ? bytes / 2 : bytes; }
  // The engine's staging's part for it, landing at `to`.
  octoray::cuda::CopyPart Part(void* to) const
  {
    octoray::cuda::CopyPart part{ to, data, StagedBytes(), "staged copy peer" };
    part.unitCodes = unitCodes;
    return part;
  }
};

// The cloud's arrays as the build reads them, in the order it copies them.
std::array<HostArray, 3> InputArrays(Cloud& c)
{
  return { HostArray{ c.xyz.data(), c.xyz.size() * sizeof(float) }, HostArray{ c.rgb.data(), c.rgb.size() },
    HostArray{ c.reflectivity.data(), c.reflectivity.size() * sizeof(float), true } };
}

// The parts of the engine's staged copy of the arrays, landing end to end
// from `device` (null: the host's half alone).
std::vector<octoray::cuda::CopyPart> StagedParts(Cloud& c, void* device)
{
  std::vector<octoray::cuda::CopyPart> parts;
  char* to = static_cast<char*>(device);
  for (const HostArray& a : InputArrays(c))
  {
    parts.push_back(a.Part(to));
    to += device ? a.StagedBytes() : 0;
  }
  return parts;
}

// The bytes of all the cloud's arrays: as the caller holds them, or as the
// staging lands them.
enum class Held
{
  ByCaller,
  Landed
};
std::size_t TotalBytes(Cloud& c, Held held)
{
  std::size_t total = 0;
  for (const HostArray& a : InputArrays(c))
    total += held == Held::Landed ? a.StagedBytes() : a.bytes;
  return total;
}

// The copy a whole build call from host arrays cannot beat: every input
// array the build reads, as one block of pinned host memory copied to the
// device. Seconds() times one copy; 0 where the memory cannot be had.
class PinnedCopy
{
public:
  explicit PinnedCopy(Cloud& c)
    : Bytes(TotalBytes(c, Held::ByCaller))
  {
    if (cudaMallocHost(&Host, Bytes) != cudaSuccess || cudaMalloc(&Device, Bytes) != cudaSuccess)
    {
      cudaGetLastError();
      return;
    }
    std::memset(Host, 1, Bytes); // pages touched before timing
  }
  ~PinnedCopy()
  {
    cudaFree(Device);
    cudaFreeHost(Host);
  }
  PinnedCopy(const PinnedCopy&) = delete;
  PinnedCopy& operator=(const PinnedCopy&) = delete;

  double Megabytes() const { return Bytes / 1e6; }
  double Seconds()
  {
    if (!Host || !Device)
    {
      return 0.0;
    }
    const auto t0 = std::chrono::steady_clock::now();
    cudaMemcpy(Device, Host, Bytes, cudaMemcpyHostToDevice);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

private:
  std::size_t Bytes;
  void* Host = nullptr;
  void* Device = nullptr;
};

// The host's half of the engine's staging alone (CudaUpload.h): the
// caller's arrays, laid end to end, cut and dealt to the threads as the
// staging does it (StagingPieces.h), copied piece by piece into each
// thread's two page-locked buffers in turn (the reflectivity as its
// codes, FillPiece); no DMA. No upload through such buffers takes less
// than the longer of this and a pinned copy of what they hold.
class HostHalfOfStaging
{
public:
  HostHalfOfStaging()
    : Threads(std::min(octoray::cuda::kMaxStagingThreads, DefaultThreadCount()))
    , Buffers(2 * Threads.Chunks(), nullptr)
  {
    for (void*& b : Buffers)
    {
      if (cudaMallocHost(&b, octoray::cuda::kStagingPiece) != cudaSuccess)
      {
        cudaGetLastError();
        b = nullptr;
      }
    }
  }
  ~HostHalfOfStaging()
  {
    for (void* b : Buffers)
    {
      cudaFreeHost(b);
    }
  }
  HostHalfOfStaging(const HostHalfOfStaging&) = delete;
  HostHalfOfStaging& operator=(const HostHalfOfStaging&) = delete;

  int ThreadCount() const { return Threads.Chunks(); }
  double Seconds(Cloud& c)
  {
    if (std::count(Buffers.begin(), Buffers.end(), nullptr))
    {
      return 0.0;
    }
    const std::vector<octoray::cuda::CopyPart> parts = StagedParts(c, nullptr);
    const octoray::cuda::StagingRun run = octoray::cuda::RunOf(parts);
    const auto t0 = std::chrono::steady_clock::now();
    octoray::cuda::PieceDealer dealer(octoray::cuda::CutPieces(run, Threads.Chunks()));
    Threads.Run(Threads.Chunks(), [&](std::size_t thread, std::size_t, int) {
      dealer.Take([&](const octoray::cuda::Piece& piece, int b) {
        octoray::cuda::FillPiece(parts[piece.array], piece.offset, piece.bytes, Buffers[2 * thread + b]);
      });
    });
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

private:
  ChunkWorkers Threads;
  std::vector<void*> Buffers; // two a thread
};

// The host's half of the staging and the pinned copy run at once, the
// longer of the two timed: both read the host's memory (the first also
// writes it), so each slows the other. A staged upload takes at least this.
double HostHalfBesidePinnedCopy(HostHalfOfStaging& half, PinnedCopy& copy, Cloud& c)
{
  const auto t0 = std::chrono::steady_clock::now();
  std::thread dma([&] { copy.Seconds(); });
  half.Seconds(c);
  dma.join();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The engine's staged copy alone (CudaUpload.h's HostStaging) of the input
// arrays in one pass, as a build copies them, nothing queued on its pieces:
// the median of 5 after a warm-up copy (TimeMedian); 0 where the device
// memory cannot be had.
double StagedCopySeconds(Cloud& c)
{
  void* device = nullptr;
  if (cudaMalloc(&device, TotalBytes(c, Held::Landed)) != cudaSuccess)
  {
    cudaGetLastError();
    return 0.0;
  }
  const std::vector<octoray::cuda::CopyPart> parts = StagedParts(c, device);
  octoray::cuda::HostStaging staging;
  const double seconds = TimeMedian(5, [&] { staging.Copy(parts); });
  cudaFree(device);
  return seconds;
}

// Builds before the timed ones. The engine's memory pool grows over the
// first builds of a size, a build filling its new octree beside the one it
// replaces: at 10 M points the node arrays' reservations took 0.17-0.25 ms
// of the host in the first four builds (the device waiting for them) and
// 0.02 ms from the fifth on (Benchmarks/gpu/variants-levels-order.txt).
// The timed builds are what rebuilding at one size costs.
constexpr int kWarmUpBuilds = 4;

// The cloud's arrays in device memory, as a CUDA simulation would hand
// them over: a build from them copies them on the device and then sorts,
// with nothing on its way to overlap, so that its phases are the device's
// own time, which the build's goal against the sort is about. (From host
// arrays, the keys and the sort run while the attributes upload, and share
// the device with the staged copy.)
class DeviceCloud
{
public:
  explicit DeviceCloud(Cloud& c)
  {
    const std::array<HostArray, 3> arrays = InputArrays(c);
    for (std::size_t a = 0; a < Arrays.size(); ++a)
    {
      const HostArray& host = arrays[a];
      if (cudaMalloc(&Arrays[a], host.bytes) != cudaSuccess ||
        cudaMemcpy(Arrays[a], host.data, host.bytes, cudaMemcpyHostToDevice) != cudaSuccess)
      {
        cudaGetLastError();
        Complete = false;
      }
    }
    Points = c.View();
    Points.xyzFloat = static_cast<const float*>(Arrays[0]);
    Points.color8 = static_cast<const std::uint8_t*>(Arrays[1]);
    Points.reflectivity = static_cast<const float*>(Arrays[2]);
  }
  ~DeviceCloud()
  {
    for (void* a : Arrays)
    {
      cudaFree(a);
    }
  }
  DeviceCloud(const DeviceCloud&) = delete;
  DeviceCloud& operator=(const DeviceCloud&) = delete;

  bool Ok() const { return Complete; }
  const PointCloudView& View() const { return Points; }

private:
  std::array<void*, 3> Arrays{};
  PointCloudView Points;
  bool Complete = true;
};

// The medians of builds' own upload and phase times (one build's may be a
// stray), with the last build's node count.
BuildStats MedianPhases(const std::vector<BuildStats>& stats)
{
  BuildStats median = stats.back();
  for (double BuildStats::*phase :
    { &BuildStats::uploadSeconds, &BuildStats::keySeconds, &BuildStats::sortSeconds, &BuildStats::levelSeconds })
  {
    std::vector<double> times;
    for (const BuildStats& s : stats)
    {
      times.push_back(s.*phase);
    }
    median.*phase = Median(times);
  }
  return median;
}

// A build's whole call against the pinned copy, measured pair by pair
// (build, then copy, `repeats` times after the warm-up builds): the medians of
// each and the median of the pairs' ratios, which a drift of the host's
// copy speed moves less than it moves either median (both halves of a pair
// copy through the same host at nearly the same time). `phases` holds the
// builds' MedianPhases.
struct PairedBuild
{
  double seconds = 0.0;
  double copySeconds = 0.0;
  double ratio = 0.0;
  BuildStats phases;
};

PairedBuild TimeBuildAgainstCopy(int repeats, PinnedCopy& copy, const std::function<BuildStats()>& build)
{
  for (int w = 0; w < kWarmUpBuilds; ++w)
  {
    build();
  }
  std::vector<double> builds, copies, ratios;
  std::vector<BuildStats> stats;
  for (int r = 0; r < repeats; ++r)
  {
    const auto start = std::chrono::steady_clock::now();
    stats.push_back(build());
    cudaDeviceSynchronize();
    builds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    copies.push_back(copy.Seconds());
    ratios.push_back(copies.back() > 0 ? builds.back() / copies.back() : 0.0);
  }
  return PairedBuild{ Median(builds), Median(copies), Median(ratios), MedianPhases(stats) };
}

// The same input arrays copied as a caller's pageable arrays go without the
// engine's staging: plain cudaMemcpy (what the engine did before), and
// page-locked in place with cudaHostRegister, copied, unregistered.
// Medians of 3; 0 where the call failed.
struct UploadPeers
{
  double pageable = 0.0;
  double registered = 0.0;
  double hostStaging = 0.0; // HostHalfOfStaging, median of 5
  double hostBesideCopy = 0.0; // HostHalfBesidePinnedCopy, median of 5
  double staged = 0.0;         // StagedCopySeconds
};

UploadPeers MeasureUploadPeers(Cloud& c)
{
  void* device = nullptr;
  UploadPeers peers;
  if (cudaMalloc(&device, TotalBytes(c, Held::ByCaller)) != cudaSuccess)
    return peers;
  auto copyAll = [&](bool registerFirst) {
    char* to = static_cast<char*>(device);
    bool ok = true;
    for (const HostArray& a : InputArrays(c))
    {
      if (registerFirst)
        ok = ok && cudaHostRegister(a.data, a.bytes, cudaHostRegisterDefault) == cudaSuccess;
      ok = ok && cudaMemcpy(to, a.data, a.bytes, cudaMemcpyHostToDevice) == cudaSuccess;
      if (registerFirst)
        ok = ok && cudaHostUnregister(a.data) == cudaSuccess;
      to += a.bytes;
    }
    return ok;
  };
  for (bool registerFirst : { false, true })
  {
    std::vector<double> times;
    bool ok = true;
    for (int r = 0; r < 3 && ok; ++r)
    {
      const auto t0 = std::chrono::steady_clock::now();
      ok = copyAll(registerFirst);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    cudaGetLastError();
    (registerFirst ? peers.registered : peers.pageable) = ok ? Median(times) : 0.0;
  }
  cudaFree(device);
  return peers;
}

// Gaussian clusters like MakeCloud's, generated on the device from a fixed
// seed (a counter-based hash, so every point is the same on every run):
// xyz float and 8-bit RGB, written to device arrays.
__device__ std::uint64_t SplitMix64(std::uint64_t x)
{
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

__global__ void ClusteredPointsKernel(std::size_t n, std::uint64_t seed, float* xyz, std::uint8_t* rgb)
{
  const std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
  if (i >= n)
    return;
  const float centres[8][3] = { { 0, 0, 0 }, { 4, 1, -2 }, { -3, 3, 1 }, { 2, -4, 3 }, { -2, -2, -3 }, { 3, 3, 3 },
    { -4, 0, 2 }, { 0, 4, -4 } };
  const int k = static_cast<int>(i & 7);
  const float s = 0.3f + 0.2f * k;
  for (int a = 0; a < 3; ++a)
  {
    // Box-Muller from two 24-bit uniforms of one hash.
    const std::uint64_t h = SplitMix64(seed ^ (3 * i + a) * 0xD1B54A32D192ED03ull);
    const float u1 = (float((h >> 40) & 0xFFFFFF) + 1.0f) * (1.0f / 16777217.0f);
    const float u2 = float((h >> 16) & 0xFFFFFF) * (1.0f / 16777216.0f);
    xyz[3 * i + a] = centres[k][a] + s * sqrtf(-2.0f * logf(u1)) * cospif(2.0f * u2);
    rgb[3 * i + a] = static_cast<std::uint8_t>(60 + 25 * k + 20 * a);
  }
}

RenderSettings Camera(const HostOctree& t, int w, int h)
{
  return bench::CubeCamera(t.cube, w, h);
}

// Device time of one frame, picture left on the device (as the VTK mapper
// draws it), from RenderStats: the median of 9 after a warm-up. `last`: the
// last frame's statistics (its ray counts).
double FrameSeconds(Engine& engine, const RenderSettings& s, RenderStats& last)
{
  Image image;
  std::vector<double> frames;
  for (int r = 0; r < 10; ++r)
  {
    last = engine.Render(s, image);
    if (r)
      frames.push_back(last.seconds);
  }
  return Median(frames);
}

// The full light model of the render figures: Phong, one directional
// light with shadows, one mirror bounce.
void AddShadowsAndBounce(RenderSettings& s)
{
  s.shade = ShadeMode::Phong;
  Light sun;
  sun.position[0] = 1, sun.position[1] = -1, sun.position[2] = 2, sun.position[3] = 0;
  s.lights.push_back(sun);
  s.shadows = true;
  s.maxBounces = 1;
}

struct Record
{
  std::string name;
  std::size_t n;
  int depth;
  double seconds;
  std::string peer;
  double peerSeconds;
  // Further figures of the same measurement, written as extra members
  // (the report reads them; see BenchUtil.h's Record::extra).
  std::vector<std::pair<std::string, double>> extra = {};
};

// GPU bytes per point, and per array, of n clustered points with every
// attribute (8-bit colours, scalars, reflectivity, normals), depth 10,
// without the points: a static scene that a transfer function colours and
// lights use. Each array as the engine's memory report names it.
void ReportEveryAttribute(Engine& engine, std::size_t n, std::vector<Record>& records)
{
  Cloud c = MakeCloud(n, 2);
  std::vector<float> scalar(n), normal(3 * n);
  for (std::size_t i = 0; i < n; ++i)
  {
    scalar[i] = c.xyz[3 * i] * 100.0f; // a ramp across the clusters, in HU-like units
    const float* p = &c.xyz[3 * i];
    for (int a = 0; a < 3; ++a)
    {
      normal[3 * i + a] = p[a]; // radial from the origin
    }
  }
  PointCloudView v = c.View();
  v.scalar = scalar.data();
  v.normal = normal.data();
  BuildOptions o;
  o.depth = 10;
  o.keepPoints = false;
  const BuildStats stats = engine.Build(v, o);
  const MemoryReport memory = engine.Memory();
  std::printf("every attribute (8-bit colours, scalars, reflectivity, normals), n=%zu depth=10, points not kept: "
              "%zu nodes, %.2f GPU bytes/point in arrays, %.2f with the allocator's cache; per array:",
    n, stats.nodes, double(memory.ArrayBytes()) / n, double(memory.Total()) / n);
  Record r{ "gpu bytes per point, every attribute", n, 10, double(memory.ArrayBytes()) / n, "", 0,
    { { "total_bytes_per_point", double(memory.Total()) / n }, { "nodes", double(stats.nodes) } } };
  for (const auto& [name, bytes] : memory.arrays)
  {
    std::printf(" %s %.2f;", name.c_str(), double(bytes) / n);
    r.extra.push_back({ name, double(bytes) / n });
  }
  std::printf("\n");
  records.push_back(r);
}
}

// n points generated on the device (ClusteredPointsKernel) and built
// from there at depth 10 without their points, then traced at 1920x1080:
// the first build (allocations included, one run), the bytes held, and the
// frame times. Throws where the device cannot hold them.
void MeasureDevicePoints(std::size_t n, std::vector<Record>& records)
{
  float* xyz = nullptr;
  std::uint8_t* rgb = nullptr;
  if (cudaMalloc(&xyz, 3 * n * sizeof(float)) != cudaSuccess || cudaMalloc(&rgb, 3 * n) != cudaSuccess)
  {
    cudaGetLastError();
    cudaFree(xyz);
    throw std::runtime_error("no room on the device for the generated points");
  }
  ClusteredPointsKernel<<<static_cast<unsigned>((n + 255) / 256), 256>>>(n, 1, xyz, rgb);
  if (cudaDeviceSynchronize() != cudaSuccess)
    throw std::runtime_error(std::string("generating the points failed: ") + cudaGetErrorString(cudaGetLastError()));
  PointCloudView v;
  v.count = n;
  v.xyzFloat = xyz;
  v.color8 = rgb;
  v.colorComponents = 3;
  auto engine = CreateEngine(Backend::CUDA);
  BuildOptions o;
  o.depth = 10;
  o.keepPoints = false;
  const auto start = std::chrono::steady_clock::now();
  const BuildStats build = engine->Build(v, o);
  cudaDeviceSynchronize();
  const double buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  cudaFree(xyz);
  cudaFree(rgb);
  const double bytesPerPoint = double(engine->Memory().Total()) / n;
  size_t freeBytes = 0, totalBytes = 0;
  cudaMemGetInfo(&freeBytes, &totalBytes);
  RenderSettings s = bench::CubeCamera(build.cube, 1920, 1080);
  s.maxBounces = 0;
  s.copyToHost = false;
  RenderStats stats;
  const double primary = FrameSeconds(*engine, s, stats);
  AddShadowsAndBounce(s);
  const double full = FrameSeconds(*engine, s, stats);
  std::printf("device-generated %zu points, depth 10, points not kept: build %.1f ms (upload %.1f, keys %.1f, sort "
              "%.1f, levels %.1f ms), %zu nodes, %.2f GPU bytes/point (%.2f GB; %.1f of %.1f GB free after); "
              "1920x1080 primary %.3f ms (%.0f frames/s), Phong + shadows + 1 bounce %.3f ms (%.0f frames/s)\n",
    n, buildSeconds * 1e3, build.uploadSeconds * 1e3, build.keySeconds * 1e3, build.sortSeconds * 1e3,
    build.levelSeconds * 1e3, build.nodes, bytesPerPoint, engine->Memory().Total() / 1e9, freeBytes / 1e9,
    totalBytes / 1e9, primary * 1e3, 1.0 / primary, full * 1e3, 1.0 / full);
  records.push_back({ "device points build", n, 10, buildSeconds, "", 0,
    { { "nodes", double(build.nodes) }, { "bytes_per_point", bytesPerPoint }, { "sort_seconds", build.sortSeconds },
      { "level_seconds", build.levelSeconds } } });
  records.push_back({ "device points primary 1920x1080", n, 10, primary, "", 0 });
  records.push_back({ "device points shadows+bounce 1920x1080", n, 10, full, "", 0 });
}

int Run(int argc, char** argv);

int main(int argc, char** argv)
{
  try
  {
    return Run(argc, argv);
  }
  catch (const std::exception& e)
  {
    std::printf("error: %s\n", e.what());
    return 1;
  }
}

// The usage, printed for --help or -h and after a wrong argument.
constexpr const char* kUsage =
    "usage: octoray_bench_cuda [--json out.json] [--small] [--only all|build|render] [--billion N] "
    "[--profile-build N]\n";

// Two builds of n points at depth 10 and nothing else, for a profiler's
// list of the build's kernels; the first fills the allocator's pool.
void ProfileBuild(Engine& engine, std::size_t n)
{
  const Cloud c = MakeCloud(n, 1);
  BuildOptions o;
  o.depth = 10;
  for (int b = 0; b < 2; ++b)
  {
    const BuildStats last = engine.Build(c.View(), o);
    std::printf("build %d of n=%zu depth=10: upload %.3f, keys %.3f, sort %.3f, levels %.3f ms\n", b + 1, n,
      last.uploadSeconds * 1e3, last.keySeconds * 1e3, last.sortSeconds * 1e3, last.levelSeconds * 1e3);
  }
}

// The upload of a cloud's pageable host arrays, and what it is measured
// against: the pinned copy of the same bytes and the upload's peers. The
// host half's threads and buffers stay while the cloud's builds run.
struct UploadOf
{
  PinnedCopy pinned;
  HostHalfOfStaging hostHalf;
  double pinnedSeconds = 0;
  UploadPeers peers;

  explicit UploadOf(Cloud& c)
    : pinned(c)
  {
    pinnedSeconds = MedianOfRuns(5, [this] { return pinned.Seconds(); });
    peers = MeasureUploadPeers(c);
    peers.hostStaging = MedianOfRuns(5, [&] { return hostHalf.Seconds(c); });
    peers.hostBesideCopy = MedianOfRuns(5, [&] { return HostHalfBesidePinnedCopy(hostHalf, pinned, c); });
    peers.staged = StagedCopySeconds(c);
    std::printf("upload of %zu points' %.0f MB from pageable host arrays: pinned copy %.3f ms, plain cudaMemcpy "
                "%.3f ms, cudaHostRegister + copy %.3f ms, the host's half of the staging on %d threads %.3f ms, "
                "that and the pinned copy at once %.3f ms, the engine's staged copy alone %.3f ms (landing %.0f MB: "
                "the reflectivity as 16-bit codes)\n",
      c.xyz.size() / 3, pinned.Megabytes(), pinnedSeconds * 1e3, peers.pageable * 1e3, peers.registered * 1e3,
      hostHalf.ThreadCount(), peers.hostStaging * 1e3, peers.hostBesideCopy * 1e3, peers.staged * 1e3,
      TotalBytes(c, Held::Landed) / 1e6);
  }
};

// Builds of cloud c at `depth`: from host arrays, each paired with the
// pinned copy, and from device arrays (the device phases), beside the sort
// floor; then without the points kept.
void MeasureBuild(Engine& engine, Cloud& c, UploadOf& upload, const DeviceCloud& onDevice, int depth,
  std::vector<Record>& records)
{
  const std::size_t n = c.xyz.size() / 3;
  BuildOptions o;
  o.depth = depth;
  const int repeats = 7;
  // From device arrays first: the memory below is a build's from host arrays.
  std::vector<BuildStats> fromDevice;
  for (int r = 0; onDevice.Ok() && r < kWarmUpBuilds + repeats; ++r)
  {
    const BuildStats stats = engine.Build(onDevice.View(), o);
    if (r >= kWarmUpBuilds)
    {
      fromDevice.push_back(stats);
    }
  }
  const PairedBuild paired = TimeBuildAgainstCopy(repeats, upload.pinned, [&] { return engine.Build(c.View(), o); });
  const BuildStats& whole = paired.phases; // medians
  const BuildStats phases = fromDevice.empty() ? whole : MedianPhases(fromDevice);
  const double t = paired.seconds;
  const double floor = SortFloorSeconds(n, 3 * depth);
  const double buildSort = BuildSortSeconds(n, depth);
  const double bytesPerPoint = double(engine.Memory().Total()) / n;
  const double arrayBytesPerPoint = double(engine.Memory().ArrayBytes()) / n;
  // Without the points kept for updates: what a static scene holds.
  BuildOptions lean = o;
  lean.keepPoints = false;
  const double leanSeconds = TimeMedian(repeats, [&] { engine.Build(c.View(), lean); });
  const double leanBytesPerPoint = double(engine.Memory().Total()) / n;
  const UploadPeers& peers = upload.peers;
  std::printf("build n=%zu depth=%d: %.3f ms (upload %.3f, keys %.3f, sort %.3f, levels %.3f ms; from device "
              "arrays keys %.3f, sort %.3f, levels %.3f ms), bare CUB "
              "sort %.3f ms (of 32-bit keys with 8-byte records %.3f ms), ratio %.2f, %zu nodes, %.1f GPU "
              "bytes/point (%.1f in arrays, the rest the allocator's cache); pinned copy of its %.0f MB input "
              "%.3f ms beside it, "
              "whole call %.2fx that (median of the pairs); without the points %.3f ms, %.1f GPU bytes/point\n",
    n, depth, t * 1e3, whole.uploadSeconds * 1e3, whole.keySeconds * 1e3, whole.sortSeconds * 1e3,
    whole.levelSeconds * 1e3, phases.keySeconds * 1e3, phases.sortSeconds * 1e3, phases.levelSeconds * 1e3,
    floor * 1e3, buildSort * 1e3, t / floor, whole.nodes, bytesPerPoint, arrayBytesPerPoint,
    upload.pinned.Megabytes(), paired.copySeconds * 1e3, paired.ratio, leanSeconds * 1e3, leanBytesPerPoint);
  records.push_back({ "octree build", n, depth, t, "cub radix sort", floor,
    { { "upload_seconds", whole.uploadSeconds }, { "key_seconds", phases.keySeconds },
      { "sort_seconds", phases.sortSeconds }, { "level_seconds", phases.levelSeconds },
      { "host_input_key_seconds", whole.keySeconds }, { "host_input_sort_seconds", whole.sortSeconds },
      { "host_input_level_seconds", whole.levelSeconds }, { "build_sort_seconds", buildSort },
      { "nodes", double(whole.nodes) }, { "pinned_upload_seconds", paired.copySeconds },
      { "call_over_pinned_copy", paired.ratio }, { "pageable_upload_seconds", peers.pageable },
      { "registered_upload_seconds", peers.registered }, { "host_staging_copy_seconds", peers.hostStaging },
      { "host_staging_beside_copy_seconds", peers.hostBesideCopy }, { "staged_copy_seconds", peers.staged },
      { "lean_seconds", leanSeconds }, { "warm_up_builds", double(kWarmUpBuilds) } } });
  records.push_back({ "gpu bytes per point", n, depth, bytesPerPoint, "", 0,
    { { "array_bytes_per_point", arrayBytesPerPoint }, { "lean_bytes_per_point", leanBytesPerPoint } } });
}

// Builds of each size at depths 10, 16 and 21 against the sort floor and
// the pinned copy; returns the 10 M-point cloud for the updates and the
// rendering.
Cloud MeasureBuilds(Engine& engine, const std::vector<std::size_t>& sizes, std::vector<Record>& records)
{
  Cloud ten;
  for (std::size_t n : sizes)
  {
    Cloud c = MakeCloud(n, 1);
    UploadOf upload(c);
    const DeviceCloud onDevice(c);
    // Depth 21 at 100 M points would hold ~1e9 nodes (every point its own
    // chain below level ~9): 18 GB of colours alone. Measured up to 10 M.
    for (int depth : { 10, 16, 21 })
    {
      if (depth < 21 || n <= 10000000)
      {
        MeasureBuild(engine, c, upload, onDevice, depth, records);
      }
    }
    if (n == 10000000)
    {
      ten = c;
    }
  }
  return ten;
}

// Update of 1% and 100% of the points against a rebuild, at depth 10.
void MeasureUpdates(Engine& engine, const Cloud& cloud, std::vector<Record>& records)
{
  BuildOptions o;
  o.depth = 10;
  const std::size_t n = cloud.xyz.size() / 3;
  const double rebuild = TimeMedian(5, [&] { engine.Build(cloud.View(), o); });
  for (double fraction : { 0.01, 1.0 })
  {
    const std::size_t moved = static_cast<std::size_t>(n * fraction);
    std::vector<std::uint32_t> idx(moved);
    std::vector<float> xyz(3 * moved);
    std::mt19937_64 rng(3);
    // Distinct points spread over the cloud (the engine refuses duplicates).
    const std::size_t stride = n / moved;
    for (std::size_t k = 0; k < moved; ++k)
    {
      idx[k] = static_cast<std::uint32_t>(k * stride + rng() % stride);
    }
    std::vector<double> times;
    UpdateStats last;
    for (int r = 0; r < 6; ++r)
    {
      engine.Build(cloud.View(), o);
      // A small contraction towards the origin (inside the clusters' box):
      // every point moves, none leaves the root cube.
      const float factor = r % 2 ? 0.9995f : 0.999f;
      for (std::size_t k = 0; k < moved; ++k)
        for (int a = 0; a < 3; ++a)
          xyz[3 * k + a] = cloud.xyz[3 * idx[k] + a] * factor;
      PositionsView p;
      p.count = moved;
      p.xyzFloat = xyz.data();
      p.indices = fraction < 1 ? idx.data() : nullptr;
      cudaDeviceSynchronize();
      const auto start = std::chrono::steady_clock::now();
      last = engine.Update(p);
      cudaDeviceSynchronize();
      if (r > 0)
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    const double t = Median(times);
    std::printf("update %.0f%% of %zu: %.3f ms (%s, %zu left their leaf), rebuild %.3f ms, ratio %.2f\n",
      fraction * 100, n, t * 1e3, ToString(last.path), last.changedLeaf, rebuild * 1e3, t / rebuild);
    records.push_back({ fraction < 1 ? "update 1%" : "update 100%", n, 10, t, "rebuild", rebuild });
  }
}

// Primary rays, and Phong + shadows + one bounce, at 1920x1080 at depths 10
// and 16.
void MeasureRendering(Engine& engine, const Cloud& cloud, std::vector<Record>& records)
{
  for (int depth : { 10, 16 })
  {
    BuildOptions o;
    o.depth = depth;
    engine.Build(cloud.View(), o);
    HostOctree t;
    engine.CopyToHost(t);
    RenderSettings s = Camera(t, 1920, 1080);
    s.maxBounces = 0;
    Image image;
    RenderStats stats;
    const double withCopy = TimeMedian(9, [&] { stats = engine.Render(s, image); });
    std::size_t hit = 0;
    for (std::size_t i = 0; i < image.depth.size(); ++i)
      hit += image.depth[i] < 1;
    s.copyToHost = false;
    const double primary = FrameSeconds(engine, s, stats);
    std::printf("render depth %d, primary: %.3f ms on the device, %.0f Mrays/s; %.3f ms with the copy to the host; "
                "%.1f%% of pixels hit\n",
      depth, primary * 1e3, 1920.0 * 1080 / primary / 1e6, withCopy * 1e3, 100.0 * hit / (1920.0 * 1080));
    records.push_back({ "render primary 1920x1080", cloud.xyz.size() / 3, depth, primary, "", 0 });
    AddShadowsAndBounce(s);
    const double full = FrameSeconds(engine, s, stats);
    const double rays = double(stats.primaryRays + stats.secondaryRays);
    std::printf("render depth %d, Phong + shadows + 1 bounce: %.3f ms, %.0f Mrays/s (%zu secondary rays)\n", depth,
      full * 1e3, rays / full / 1e6, stats.secondaryRays);
    records.push_back({ "render shadows+bounce 1920x1080", cloud.xyz.size() / 3, depth, full, "", 0 });
    // The clusters have no normals: lit by normals fitted to their voxels
    // (RenderSettings::estimateNormals), which the first such frame makes.
    s.estimateNormals = true;
    const double estimation = engine.Render(s, image).normalSeconds;
    const double byEstimated = FrameSeconds(engine, s, stats);
    std::printf("render depth %d, normals estimated from the voxels in %.3f ms (%zu nodes); Phong + shadows + 1 "
                "bounce by them: %.3f ms, %.0f Mrays/s\n",
      depth, estimation * 1e3, t.NodeCount(), byEstimated * 1e3,
      double(stats.primaryRays + stats.secondaryRays) / byEstimated / 1e6);
    records.push_back({ "normal estimation", cloud.xyz.size() / 3, depth, estimation, "", 0,
      { { "nodes", double(t.NodeCount()) } } });
    records.push_back(
      { "render shadows+bounce estimated normals 1920x1080", cloud.xyz.size() / 3, depth, byEstimated, "", 0 });
  }
}

// The thesis's table 2 again (2015, GTX Titan): clouds like a thresholded
// slice stack (grid points inside an ellipsoid, slice by slice), depth 7,
// 800x600 rays. Thesis figures, for all five sizes: build 0.02-6.1 s
// (almost all allocation), ray tracing 24-45 ms per image, 2.4-2.5 GB.
// A fresh engine, so that buffers kept from larger builds do not count in
// its memory.
void MeasureThesisTable(std::vector<Record>& records)
{
  auto engine = CreateEngine(Backend::CUDA);
  std::printf("thesis table 2 (depth 7, 800x600): points, build ms, trace ms/image, GPU MB\n");
  for (std::size_t n : bench::ThesisTable2Counts())
  {
    const Cloud c = bench::ThesisSliceStack(n);
    const std::size_t count = c.xyz.size() / 3;
    BuildOptions o;
    o.depth = 7;
    const double build = TimeMedian(7, [&] { engine->Build(c.View(), o); });
    HostOctree t;
    engine->CopyToHost(t);
    RenderSettings s = Camera(t, 800, 600);
    s.shade = ShadeMode::Phong;
    s.copyToHost = false;
    Image image;
    std::vector<double> frames;
    for (int r = 0; r < 10; ++r)
    {
      const RenderStats stats = engine->Render(s, image);
      if (r)
        frames.push_back(stats.seconds);
    }
    const double trace = Median(frames);
    std::printf("  %zu points: build %.2f ms, trace %.3f ms/image, %.1f MB\n", count, build * 1e3, trace * 1e3,
      engine->Memory().Total() / 1e6);
    records.push_back({ "thesis table 2 build", count, 7, build, "", 0,
      { { "bytes", double(engine->Memory().Total()) } } });
    records.push_back({ "thesis table 2 trace 800x600", count, 7, trace, "", 0 });
  }
}

// The records as a JSON list, the report's input.
void WriteRecords(const std::string& json, const std::vector<Record>& records)
{
  std::ofstream out(json);
  out << "[\n";
  for (std::size_t i = 0; i < records.size(); ++i)
  {
    const Record& r = records[i];
    out << "  {\"name\": \"" << r.name << "\", \"backend\": \"CUDA\", \"n\": " << r.n << ", \"depth\": " << r.depth
        << ", \"seconds\": " << r.seconds << ", \"peer\": \"" << r.peer << "\", \"peer_seconds\": " << r.peerSeconds;
    for (const auto& e : r.extra)
      out << ", \"" << e.first << "\": " << e.second;
    out << "}" << (i + 1 < records.size() ? "," : "") << "\n";
  }
  out << "]\n";
}

int Run(int argc, char** argv)
{
  std::string json;
  std::string only = "all"; // or "build" or "render": that section alone
  bool small = false;       // 1 M and 10 M points, not 100 M
  std::size_t billion = 0;
  std::size_t profileBuild = 0; // points: two builds at depth 10 alone, for a profiler's kernel list
  CommandLine options;
  options.Text("--json", json)
    .Flag("--small", small)
    .Choice("--only", only, { "all", "build", "render" })
    .Count("--billion", billion)
    .Count("--profile-build", profileBuild);
  if (const std::optional<int> stop = options.ParseOrStop(argc, argv, kUsage))
  {
    return *stop;
  }
  const std::vector<std::size_t> sizes =
    small ? std::vector<std::size_t>{ 1000000, 10000000 } : std::vector<std::size_t>{ 1000000, 10000000, 100000000 };
  const bool builds = only != "render", rendering = only != "build";
  std::string why;
  if (!CudaAvailable(&why))
  {
    std::printf("no usable GPU: %s\n", why.c_str());
    return 0;
  }
  auto engine = CreateEngine(Backend::CUDA);
  std::printf("device: %s\n", engine->Description().c_str());
  if (profileBuild)
  {
    ProfileBuild(*engine, profileBuild);
    return 0;
  }
  std::vector<Record> records;
  Cloud ten = builds ? MeasureBuilds(*engine, sizes, records) : MakeCloud(10000000, 1);
  if (builds && !small)
  {
    // Memory with every attribute a lit scene of scalars and colours uses.
    ReportEveryAttribute(*engine, 100000000, records);
  }
  if (builds)
  {
    MeasureUpdates(*engine, ten, records);
  }
  if (rendering)
  {
    MeasureRendering(*engine, ten, records);
  }
  engine.reset();
  if (builds)
  {
    MeasureThesisTable(records);
  }
  if (billion)
  {
    ten = Cloud();
    try
    {
      MeasureDevicePoints(billion, records);
    }
    catch (const std::exception& e)
    {
      std::printf("device-generated %zu points: %s\n", billion, e.what());
    }
  }
  if (!json.empty())
  {
    WriteRecords(json, records);
  }
  return 0;
}
