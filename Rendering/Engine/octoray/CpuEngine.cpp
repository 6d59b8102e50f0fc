// The CPU backend: the reference for the CUDA one and the fallback where no
// GPU is usable. Loops run the shared per-point and per-node functions over
// std::thread chunks; sorting is a multi-threaded LSD radix sort.
#include "CpuEngine.h"

#include "DepthChoice.h"
#include "Frame.h"
#include "OctreeKernels.h"
#include "Parallel.h"
#include "RadixSort.h"
#include "Validation.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace octoray
{
namespace
{
double SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template <typename T>
std::size_t Bytes(const std::vector<T>& v)
{
  return v.capacity() * sizeof(T);
}

// Starts of the runs of equal (key >> shift) in sorted keys, plus n at the end.
void RunStarts(const std::uint64_t* keys, std::size_t n, int shift, int threads, std::vector<std::uint32_t>& starts)
{
  const int chunks = n < 65536 ? 1 : threads;
  std::vector<std::size_t> perChunk(chunks + 1, 0);
  auto isStart = [&](std::size_t i) { return i == 0 || (keys[i] >> shift) != (keys[i - 1] >> shift); };
  ParallelChunks(n, chunks, [&](std::size_t begin, std::size_t end, int c) {
    std::size_t count = 0;
    for (std::size_t i = begin; i < end; ++i)
    {
      count += isStart(i);
    }
    perChunk[c + 1] = count;
  });
  std::partial_sum(perChunk.begin(), perChunk.end(), perChunk.begin());
  starts.resize(perChunk[chunks] + 1);
  ParallelChunks(n, chunks, [&](std::size_t begin, std::size_t end, int c) {
    std::size_t out = perChunk[c];
    for (std::size_t i = begin; i < end; ++i)
    {
      if (isStart(i))
      {
        starts[out++] = static_cast<std::uint32_t>(i);
      }
    }
  });
  starts.back() = static_cast<std::uint32_t>(n);
}
}

CpuEngine::CpuEngine()
  : Threads(DefaultThreadCount())
{
}

std::string CpuEngine::Description() const
{
  return "CPU (" + std::to_string(Threads) + (Threads == 1 ? " thread)" : " threads)");
}

void CpuEngine::SetThreadCount(int threads)
{
  Threads = threads > 0 ? threads : DefaultThreadCount();
}

PointArraysView CpuEngine::PointsView() const
{
  PointArraysView v;
  v.count = Count;
  v.xyzFloat = XyzFloat.empty() ? nullptr : XyzFloat.data();
  v.xyzDouble = XyzDouble.empty() ? nullptr : XyzDouble.data();
  v.color8 = Color8.empty() ? nullptr : Color8.data();
  v.colorFloat = ColorFloat.empty() ? nullptr : ColorFloat.data();
  v.scalar = Scalar.empty() ? nullptr : Scalar.data();
  v.reflectivity = Reflectivity.empty() ? nullptr : Reflectivity.data();
  v.refraction = Refraction.empty() ? nullptr : Refraction.data();
  v.normal = Normal.empty() ? nullptr : Normal.data();
  return v;
}

BuildStats CpuEngine::Build(const PointCloudView& points, const BuildOptions& options)
{
  ValidateCloud(points);
  ValidateDepth(options.depth);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t n = points.count;

  // Bounds, and the first non-finite point, before anything is replaced.
  constexpr double inf = std::numeric_limits<double>::infinity();
  struct ChunkBounds
  {
    double lo[3] = { inf, inf, inf };
    double hi[3] = { -inf, -inf, -inf };
    std::size_t firstBad = std::numeric_limits<std::size_t>::max();
  };
  // One entry per thread; a small input may use fewer chunks.
  std::vector<ChunkBounds> chunkBounds(Threads);
  ParallelChunks(n, Threads, [&](std::size_t begin, std::size_t end, int c) {
    ChunkBounds b;
    for (std::size_t i = begin; i < end; ++i)
    {
      const double p[3] = { points.Coordinate(i, 0), points.Coordinate(i, 1), points.Coordinate(i, 2) };
      if (!IsFinitePoint(p))
      {
        b.firstBad = i;
        break;
      }
      for (int a = 0; a < 3; ++a)
      {
        b.lo[a] = std::min(b.lo[a], p[a]);
        b.hi[a] = std::max(b.hi[a], p[a]);
      }
    }
    chunkBounds[c] = b;
  });
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = std::numeric_limits<double>::infinity();
    hi[a] = -std::numeric_limits<double>::infinity();
  }
  for (const ChunkBounds& b : chunkBounds)
  {
    if (b.firstBad != std::numeric_limits<std::size_t>::max())
    {
      const double p[3] = { points.Coordinate(b.firstBad, 0), points.Coordinate(b.firstBad, 1),
        points.Coordinate(b.firstBad, 2) };
      throw Error(NonFinitePointMessage(b.firstBad, p));
    }
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], b.lo[a]);
      hi[a] = std::max(hi[a], b.hi[a]);
    }
  }

  if (options.fixedCube)
  {
    // Checked before anything is replaced, like the coordinates.
    std::uint32_t cell[3];
    if (!options.cube.GridCell(lo[0], lo[1], lo[2], cell) || !options.cube.GridCell(hi[0], hi[1], hi[2], cell))
    {
      for (std::size_t i = 0; i < n; ++i)
      {
        const double p[3] = { points.Coordinate(i, 0), points.Coordinate(i, 1), points.Coordinate(i, 2) };
        if (!options.cube.GridCell(p[0], p[1], p[2], cell))
        {
          throw Error(OutsideCubeMessage(i, p));
        }
      }
    }
  }

  // The input is good: take a copy of it as the new point state.
  Count = n;
  XyzFloat.clear();
  XyzDouble.clear();
  if (points.xyzFloat)
  {
    XyzFloat.assign(points.xyzFloat, points.xyzFloat + 3 * n);
  }
  else
  {
    XyzDouble.assign(points.xyzDouble, points.xyzDouble + 3 * n);
  }
  Color8.clear();
  ColorFloat.clear();
  const int cc = points.colorComponents;
  if (points.color8)
  {
    Color8.resize(4 * n);
    ParallelFor(n, Threads, [&](std::size_t i) {
      for (int c = 0; c < 4; ++c)
      {
        Color8[4 * i + c] = c < cc ? points.color8[cc * i + c] : 255;
      }
    });
  }
  else if (points.colorFloat)
  {
    ColorFloat.resize(n);
    ParallelFor(n, Threads, [&](std::size_t i) {
      const float* c = points.colorFloat + cc * i;
      ColorFloat[i] = Rgba{ c[0], c[1], c[2], cc == 4 ? c[3] : 1.0f };
    });
  }
  auto copyOptional = [n](const float* src, std::vector<float>& dst) {
    dst.clear();
    if (src)
    {
      dst.assign(src, src + n);
    }
  };
  copyOptional(points.scalar, Scalar);
  copyOptional(points.reflectivity, Reflectivity);
  copyOptional(points.refraction, Refraction);
  Normal.clear();
  if (points.normal)
  {
    Normal.resize(n);
    ParallelFor(n, Threads, [&](std::size_t i) {
      Normal[i] = UnitNormal(points.normal[3 * i], points.normal[3 * i + 1], points.normal[3 * i + 2]);
    });
  }
  Attributes = points.Attributes();

  BuildStats stats =
    BuildFromPointState(options.fixedCube ? options.cube : RootCube::FromBounds(lo, hi), options.depth);
  stats.seconds = SecondsSince(start);
  return stats;
}

BuildStats CpuEngine::BuildFromPointState(const RootCube& cube, int requestedDepth)
{
  const std::size_t n = Count;
  const PointArraysView pts = PointsView();
  BuildStats stats;
  stats.points = n;

  auto phase = std::chrono::steady_clock::now();
  PointKey.resize(n);
  ParallelFor(n, Threads, [&](std::size_t i) {
    if (!ComputePointKey(pts, cube, i, PointKey[i]))
    {
      double p[3];
      pts.Position(i, p);
      throw Error(OutsideCubeMessage(i, p));
    }
  });
  stats.keySeconds = SecondsSince(phase);

  phase = std::chrono::steady_clock::now();
  SortedKey.resize(n);
  SortedIndex.resize(n);
  int depth = requestedDepth;
  if (depth > 0)
  {
    // Only the leaf level's 3*depth bits need sorting.
    const int shift = 3 * (kMaxLevel - depth);
    ParallelFor(n, Threads, [&](std::size_t i) {
      SortedKey[i] = PointKey[i] >> shift;
      SortedIndex[i] = static_cast<std::uint32_t>(i);
    });
    RadixSortPairs(SortedKey.data(), SortedIndex.data(), n, 3 * depth, Threads, ScratchKey, ScratchIndex);
  }
  else
  {
    ParallelFor(n, Threads, [&](std::size_t i) {
      SortedKey[i] = PointKey[i];
      SortedIndex[i] = static_cast<std::uint32_t>(i);
    });
    RadixSortPairs(SortedKey.data(), SortedIndex.data(), n, 3 * kMaxLevel, Threads, ScratchKey, ScratchIndex);
    depth = ChooseDepth();
    const int shift = 3 * (kMaxLevel - depth);
    ParallelFor(n, Threads, [&](std::size_t i) { SortedKey[i] >>= shift; });
  }
  stats.sortSeconds = SecondsSince(phase);

  phase = std::chrono::steady_clock::now();
  BuildLevels(cube, depth);
  stats.levelSeconds = SecondsSince(phase);

  stats.depth = depth;
  stats.cube = cube;
  stats.nodes = Tree.NodeCount();
  for (int l = 0; l <= depth; ++l)
  {
    stats.nodesPerLevel.push_back(Tree.levelBegin[l + 1] - Tree.levelBegin[l]);
  }
  stats.bytes = Memory().Total();
  return stats;
}

int CpuEngine::ChooseDepth() const
{
  const std::size_t n = Count;
  std::vector<std::uint64_t> histograms(static_cast<std::size_t>(Threads) * 2 * kDepthHistogramBins, 0);
  ParallelChunks(n, Threads, [&](std::size_t begin, std::size_t end, int c) {
    std::uint64_t* newNode = histograms.data() + c * 2 * kDepthHistogramBins;
    std::uint64_t* alone = newNode + kDepthHistogramBins;
    for (std::size_t i = begin; i < end; ++i)
    {
      int newNodeBin, aloneBin;
      DepthHistogramBins(SortedKey.data(), n, i, newNodeBin, aloneBin);
      ++newNode[newNodeBin + 1];
      ++alone[aloneBin + 1];
    }
  });
  std::uint64_t newNode[kDepthHistogramBins] = {}, alone[kDepthHistogramBins] = {};
  for (int c = 0; c < Threads; ++c)
  {
    for (int b = 0; b < kDepthHistogramBins; ++b)
    {
      newNode[b] += histograms[(c * 2) * kDepthHistogramBins + b];
      alone[b] += histograms[(c * 2 + 1) * kDepthHistogramBins + b];
    }
  }
  newNode[0] = 0; // the first key is counted by the rule itself
  return ChooseDepthFromHistograms(newNode, alone);
}

void CpuEngine::BuildLevels(const RootCube& cube, int depth)
{
  const std::size_t n = Count;
  // Keys and run starts of every level, leaves first: level l's nodes are
  // the runs of equal (key >> 3) among level l+1's keys.
  std::vector<std::vector<std::uint64_t>> levelKeys(depth + 1);
  std::vector<std::vector<std::uint32_t>> runStarts(depth + 1);
  RunStarts(SortedKey.data(), n, 0, Threads, runStarts[depth]);
  for (int l = depth; l >= 0; --l)
  {
    if (l < depth)
    {
      RunStarts(levelKeys[l + 1].data(), levelKeys[l + 1].size(), 3, Threads, runStarts[l]);
    }
    const std::uint64_t* below = l == depth ? SortedKey.data() : levelKeys[l + 1].data();
    const int shift = l == depth ? 0 : 3;
    const std::size_t nodes = runStarts[l].size() - 1;
    levelKeys[l].resize(nodes);
    ParallelFor(nodes, Threads, [&](std::size_t j) { levelKeys[l][j] = below[runStarts[l][j]] >> shift; });
  }

  Tree.depth = depth;
  Tree.cube = cube;
  Tree.levelBegin.assign(kMaxLevel + 2, 0);
  for (int l = 0; l <= kMaxLevel; ++l)
  {
    Tree.levelBegin[l + 1] = Tree.levelBegin[l] + (l <= depth ? static_cast<std::uint32_t>(levelKeys[l].size()) : 0);
  }
  Tree.Allocate(Tree.levelBegin[depth + 1], Attributes);
  const OctreeView view = Tree.View();
  const PointArraysView pts = PointsView();

  const std::uint32_t leafBegin = view.levelBegin[depth];
  ParallelFor(levelKeys[depth].size(), Threads, [&](std::size_t j) {
    ReduceLeaf(view, pts, SortedIndex.data(), leafBegin + static_cast<std::uint32_t>(j), levelKeys[depth][j],
      runStarts[depth][j], runStarts[depth][j + 1]);
  });
  for (int l = depth - 1; l >= 0; --l)
  {
    const std::uint32_t begin = view.levelBegin[l];
    const std::uint32_t childBegin = view.levelBegin[l + 1];
    ParallelFor(levelKeys[l].size(), Threads, [&](std::size_t j) {
      ReduceChildren(view, begin + static_cast<std::uint32_t>(j), levelKeys[l][j], childBegin + runStarts[l][j],
        childBegin + runStarts[l][j + 1]);
    });
  }
  view.parent[0] = kInvalidIndex;
}

UpdateStats CpuEngine::Update(const PositionsView& positions)
{
  ValidateUpdate(positions, Count);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t moved = positions.count;
  auto pointIndex = [&](std::size_t k) -> std::size_t { return positions.indices ? positions.indices[k] : k; };
  auto newPosition = [&](std::size_t k, double p[3]) {
    for (int a = 0; a < 3; ++a)
    {
      p[a] = positions.xyzDouble ? positions.xyzDouble[3 * k + a] : positions.xyzFloat[3 * k + a];
    }
  };
  // Reject a non-finite position before anything changes.
  for (std::size_t k = 0; k < moved; ++k)
  {
    double p[3];
    newPosition(k, p);
    if (!IsFinitePoint(p))
    {
      throw Error(NonFinitePointMessage(pointIndex(k), p));
    }
  }

  UpdateStats stats;
  stats.moved = moved;
  bool leftCube = false;
  for (std::size_t k = 0; k < moved; ++k)
  {
    double p[3];
    newPosition(k, p);
    const std::size_t i = pointIndex(k);
    for (int a = 0; a < 3; ++a)
    {
      if (!XyzDouble.empty())
      {
        XyzDouble[3 * i + a] = p[a];
      }
      else
      {
        XyzFloat[3 * i + a] = static_cast<float>(p[a]);
      }
    }
    std::uint32_t cell[3];
    leftCube = leftCube || !Tree.cube.GridCell(p[0], p[1], p[2], cell);
  }

  const int depth = Tree.depth;
  if (leftCube)
  {
    // Rebuild around the new bounds at the same depth.
    const PointArraysView pts = PointsView();
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::numeric_limits<double>::infinity();
      hi[a] = -std::numeric_limits<double>::infinity();
    }
    for (std::size_t i = 0; i < Count; ++i)
    {
      double p[3];
      pts.Position(i, p);
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    }
    BuildFromPointState(RootCube::FromBounds(lo, hi), depth);
    stats.changedLeaf = moved;
    stats.path = UpdateStats::Path::NewCube;
    stats.seconds = SecondsSince(start);
    return stats;
  }

  // New keys; collect the points that changed leaf.
  const int shift = 3 * (kMaxLevel - depth);
  const PointArraysView pts = PointsView();
  struct Move
  {
    std::uint32_t point;
    std::uint64_t fromLeaf, toLeaf;
  };
  std::vector<Move> changes;
  for (std::size_t k = 0; k < moved; ++k)
  {
    const std::size_t i = pointIndex(k);
    std::uint64_t key;
    ComputePointKey(pts, Tree.cube, i, key);
    if ((key >> shift) != (PointKey[i] >> shift))
    {
      changes.push_back(Move{ static_cast<std::uint32_t>(i), PointKey[i] >> shift, key >> shift });
    }
    PointKey[i] = key;
  }
  stats.changedLeaf = changes.size();
  if (changes.empty())
  {
    stats.path = UpdateStats::Path::Unchanged;
    stats.seconds = SecondsSince(start);
    return stats;
  }

  // In place while every destination leaf exists and no leaf empties; the
  // hash map keeps the cost proportional to the points that moved. Past a
  // sixteenth of the points a re-sort is cheaper than the map.
  const OctreeView view = Tree.View();
  bool sameTopology = changes.size() <= Count / 16;
  struct Delta
  {
    long long count = 0;
    double sum[kSlotCount] = {};
  };
  std::unordered_map<std::uint32_t, Delta> deltas;
  if (sameTopology)
  {
    float v[kSlotCount] = {};
    for (const Move& m : changes)
    {
      const std::uint32_t from = view.Find(depth, m.fromLeaf);
      const std::uint32_t to = view.Find(depth, m.toLeaf);
      if (to == kInvalidIndex)
      {
        sameTopology = false;
        break;
      }
      pts.Attributes(m.point, v);
      // Walk both paths to the root; shared ancestors see -v + v = 0.
      for (std::uint32_t node = from; node != kInvalidIndex; node = view.parent[node])
      {
        Delta& d = deltas[node];
        --d.count;
        for (int s = 0; s < kSlotCount; ++s)
        {
          d.sum[s] -= v[s];
        }
      }
      for (std::uint32_t node = to; node != kInvalidIndex; node = view.parent[node])
      {
        Delta& d = deltas[node];
        ++d.count;
        for (int s = 0; s < kSlotCount; ++s)
        {
          d.sum[s] += v[s];
        }
      }
    }
    for (const auto& entry : deltas)
    {
      if (!sameTopology)
      {
        break;
      }
      if (static_cast<long long>(view.pointCount[entry.first]) + entry.second.count <= 0)
      {
        sameTopology = false;
      }
    }
  }
  if (sameTopology)
  {
    for (const auto& entry : deltas)
    {
      ApplyNodeDelta(view, entry.first, entry.second.count, entry.second.sum);
    }
    stats.path = UpdateStats::Path::InPlace;
  }
  else
  {
    ParallelFor(Count, Threads, [&](std::size_t i) {
      SortedKey[i] = PointKey[i] >> shift;
      SortedIndex[i] = static_cast<std::uint32_t>(i);
    });
    RadixSortPairs(SortedKey.data(), SortedIndex.data(), Count, 3 * depth, Threads, ScratchKey, ScratchIndex);
    BuildLevels(Tree.cube, depth);
    stats.path = UpdateStats::Path::Relevel;
  }
  stats.seconds = SecondsSince(start);
  return stats;
}

RenderStats CpuEngine::Render(const RenderSettings& settings, Image& image)
{
  if (settings.deviceDepthBuffer)
  {
    throw Error("octoray: the CPU backend cannot read a depth buffer in device memory");
  }
  if (Count == 0)
  {
    throw Error("octoray: render before any build");
  }
  const auto start = std::chrono::steady_clock::now();
  const OctreeView view = Tree.View();
  const FrameConstants frame = MakeFrame(settings, Tree.cube, view.reflectivity != nullptr || view.refraction != nullptr);
  image.width = settings.width;
  image.height = settings.height;
  const std::size_t pixels = static_cast<std::size_t>(settings.width) * settings.height;
  image.rgba.assign(settings.rgba8 ? 0 : 4 * pixels, 0.0f);
  image.rgba8.assign(settings.rgba8 ? 4 * pixels : 0, 0);
  image.depth.resize(pixels);
  // Rows are interleaved over threads so that costly regions are shared.
  std::vector<std::size_t> secondary(Threads, 0);
  DispatchFeatures(frame, [&](auto features) {
    using F = decltype(features);
    ParallelChunks(static_cast<std::size_t>(Threads), Threads, [&](std::size_t, std::size_t, int t) {
      std::size_t rays = 0;
      for (int y = t; y < settings.height; y += Threads)
      {
        for (int x = 0; x < settings.width; ++x)
        {
          const std::size_t i = static_cast<std::size_t>(y) * settings.width + x;
          float pixel[4];
          RenderPixel<F>(frame, view, x, y, pixel, image.depth[i], rays);
          for (int c = 0; c < 4; ++c)
          {
            if (settings.rgba8)
            {
              image.rgba8[4 * i + c] = ChannelToByte(pixel[c]);
            }
            else
            {
              image.rgba[4 * i + c] = pixel[c];
            }
          }
        }
      }
      secondary[t] = rays;
    });
  });
  RenderStats stats;
  stats.primaryRays = pixels;
  for (std::size_t r : secondary)
  {
    stats.secondaryRays += r;
  }
  stats.seconds = SecondsSince(start);
  return stats;
}

void CpuEngine::CopyToHost(HostOctree& out) const
{
  out = Tree;
}

MemoryReport CpuEngine::Memory() const
{
  MemoryReport m;
  m.Add("node keys", Bytes(Tree.key));
  m.Add("node child masks", Bytes(Tree.childMask));
  m.Add("node first children", Bytes(Tree.firstChild));
  m.Add("node parents", Bytes(Tree.parent));
  m.Add("node point counts", Bytes(Tree.pointCount));
  m.Add("node colours", Bytes(Tree.color));
  m.Add("node scalars", Bytes(Tree.scalar));
  m.Add("node reflectivities", Bytes(Tree.reflectivity));
  m.Add("node refraction indices", Bytes(Tree.refraction));
  m.Add("node normals", Bytes(Tree.normal));
  m.Add("point positions", Bytes(XyzFloat) + Bytes(XyzDouble));
  m.Add("point colours", Bytes(Color8) + Bytes(ColorFloat));
  m.Add("point scalars", Bytes(Scalar));
  m.Add("point reflectivities", Bytes(Reflectivity));
  m.Add("point refraction indices", Bytes(Refraction));
  m.Add("point normals", Bytes(Normal));
  m.Add("point keys", Bytes(PointKey));
  m.Add("sort buffers", Bytes(SortedKey) + Bytes(SortedIndex) + Bytes(ScratchKey) + Bytes(ScratchIndex));
  return m;
}
}
