// octoray_bench_peers: the octree build of issue 2 against what users would
// otherwise reach for, in one run on the same points:
//   - PCL's pcl::octree::OctreePointCloudPointVector<PointXYZ>, given
//     octoray's root cube and leaf voxel size, so both build the same tree
//     (the leaf and branch counts are compared as a check);
//   - VTK's vtkOctreePointLocator, with MaximumPointsPerRegion set to
//     octoray's mean points per leaf (rounded up);
//   - VTK's vtkStaticPointLocator (issue 7), with NumberOfPointsPerBucket the
//     same, on one thread and on all of them through vtkSMPTools.
// Every build here starts from nothing: a fresh engine, a fresh PCL octree, a
// fresh locator; tearing a tree down is left out of every timing.
//
//   octoray_bench_peers [--cases uniform:1e6,uniform:1e7,clustered:1e6]
//                       [--depth 0] [--threads N] [--repeats 5]
//                       [--peer-repeats 3] [--octree-locator-max N] [--json PATH]
// --octree-locator-max: leave vtkOctreePointLocator out of cases with more
// than N points (about a minute per build at 10 M on 2 cores).
#include "BenchUtil.h"
#include "CommandLine.h"

#include <octoray/Engine.h>

#include <pcl/octree/octree_pointcloud_pointvector.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <vtkFloatArray.h>
#include <vtkNew.h>
#include <vtkOctreePointLocator.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSMPTools.h>
#include <vtkStaticPointLocator.h>

#include <chrono>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <thread>

namespace
{
using namespace octoray;
using namespace octoray::bench;

// The usage, printed for --help or -h and after a wrong argument.
constexpr const char* kUsage =
    "usage: octoray_bench_peers [--cases SET:N[,SET:N...]] [--depth L (0: automatic)] [--threads N]\n"
    "                           [--repeats R] [--peer-repeats R] [--octree-locator-max N] [--json PATH]\n"
    "  SET is uniform or clustered; N may be written 1e7\n";

struct Case
{
  std::string set;
  std::size_t n = 0;
};

struct Settings
{
  std::vector<Case> cases = { { "uniform", 1000000 }, { "uniform", 10000000 }, { "clustered", 1000000 } };
  int requestedDepth = 0;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  int repeats = 5;
  int peerRepeats = 3;
  double octreeLocatorMax = 1e300;
  std::string json;

  // The thread counts octoray and vtkStaticPointLocator run with: one, and
  // all of them where there are more.
  std::vector<int> ThreadCounts() const { return threads > 1 ? std::vector<int>{ 1, threads } : std::vector<int>{ 1 }; }
};

bool ParseCases(const std::string& list, std::vector<Case>& cases)
{
  cases.clear();
  for (const std::string& item : SplitList(list))
  {
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos)
    {
      return false;
    }
    Case c{ item.substr(0, colon), 0 };
    if ((c.set != "uniform" && c.set != "clustered") || !CommandLine::ParseCount(item.substr(colon + 1), c.n) ||
      c.n == 0)
    {
      return false;
    }
    cases.push_back(c);
  }
  return true;
}

CommandLine OptionsOf(Settings& s)
{
  CommandLine options;
  options
    .Option("--cases", "a list SET:N of uniform or clustered and a count",
      [&s](const std::string& v) { return ParseCases(v, s.cases); })
    .Integer("--depth", s.requestedDepth)
    .Integer("--threads", s.threads, 1)
    .Integer("--repeats", s.repeats, 1)
    .Integer("--peer-repeats", s.peerRepeats, 1)
    .Real("--octree-locator-max", s.octreeLocatorMax)
    .Text("--json", s.json);
  return options;
}

std::string CpuBackendName(int threads)
{
  return "cpu-" + std::to_string(threads) + (threads == 1 ? "thread" : "threads");
}

// Debian's ParaView defaults to the Sequential SMP backend; ask for a
// threaded one so that vtkStaticPointLocator's threaded build is measured.
void ChooseThreadedSmpBackend()
{
  const std::string defaultBackend = vtkSMPTools::GetBackend();
  if (defaultBackend == "Sequential")
  {
    vtkSMPTools::SetBackend("STDThread") || vtkSMPTools::SetBackend("TBB") || vtkSMPTools::SetBackend("OpenMP");
  }
  std::printf("vtkSMPTools backend %s (default %s); %u hardware threads\n", vtkSMPTools::GetBackend(),
    defaultBackend.c_str(), std::thread::hardware_concurrency());
}

// One case's points, and the tree every library is asked for: octoray's
// cube and depth, with its leaf and branch counts to check PCL's against.
struct Scene
{
  Case c;
  std::vector<float> xyz;
  PointCloudView cloud;
  BuildOptions options; // at the reference's depth: timed builds get it, as PCL gets its resolution
  RootCube cube;
  int depth = 0;
  double leafSize = 0;
  std::size_t leaves = 0, branches = 0;
  double meanPerLeaf = 0;
  int perRegion = 1; // the locators' points a region or bucket: the mean a leaf, rounded up

  Scene(const Case& which, int requestedDepth)
    : c(which)
    , xyz(c.set == "uniform" ? UniformCube(c.n) : GaussianClusters(c.n))
  {
    cloud.count = c.n;
    cloud.xyzFloat = xyz.data();
    options.depth = requestedDepth;
    HostOctree reference;
    auto engine = CreateEngine(Backend::CPU);
    engine->Build(cloud, options);
    engine->CopyToHost(reference);
    depth = options.depth = reference.depth;
    cube = reference.cube;
    leafSize = cube.size / std::ldexp(1.0, depth);
    leaves = reference.levelBegin[depth + 1] - reference.levelBegin[depth];
    branches = reference.NodeCount() - leaves;
    meanPerLeaf = double(c.n) / double(leaves);
    perRegion = std::max(1, static_cast<int>(std::ceil(meanPerLeaf)));
  }
};

struct Row
{
  std::string what;
  std::string backend; // octoray's configuration this peer is compared with
  Timing timing;
  std::string note;
  double leaves = 0; // the peer's leaves or buckets, for the report
};

// octoray's fresh builds on `threads`; engineBytes gets what the engine
// holds after one.
Row MeasureOctoray(const Scene& scene, int threads, int repeats, std::size_t& engineBytes)
{
  std::unique_ptr<Engine> engine;
  const Timing timing = Measure(
    [&] {
      engine = CreateEngine(Backend::CPU);
      engine->SetThreadCount(threads);
      engine->Build(scene.cloud, scene.options);
    },
    1, repeats,
    [&] {
      engineBytes = engine->Memory().Total();
      engine.reset();
    });
  return Row{ "octoray", CpuBackendName(threads), timing, "" };
}

// Seconds of one octoray build on one thread.
double OneThreadBuildSeconds(const Scene& scene)
{
  auto engine = CreateEngine(Backend::CPU);
  engine->SetThreadCount(1);
  const auto start = std::chrono::steady_clock::now();
  engine->Build(scene.cloud, scene.options);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// PCL's octree of the same cube, its resolution the leaf voxel, so that its
// depth is octoray's.
struct PclResult
{
  Row row;
  bool sameTree = false;
  double pairedRatio = 0;
  std::size_t pairs = 0, leaves = 0, branches = 0;
};

PclResult MeasurePcl(const Scene& scene, int repeats)
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  points->resize(scene.c.n);
  for (std::size_t i = 0; i < scene.c.n; ++i)
  {
    (*points)[i] = pcl::PointXYZ(scene.xyz[3 * i], scene.xyz[3 * i + 1], scene.xyz[3 * i + 2]);
  }
  using PclOctree = pcl::octree::OctreePointCloudPointVector<pcl::PointXYZ>;
  std::unique_ptr<PclOctree> tree;
  PclResult r;
  unsigned depth = 0;
  // Each PCL build is paired with a single-threaded octoray build run
  // right after it (untimed for PCL): on a shared machine the load drifts
  // between the octoray and PCL blocks, and the median of the per-pair
  // ratios is what that drift does not move.
  std::vector<double> pairedRatios;
  double pclSeconds = 0.0;
  const RootCube& cube = scene.cube;
  const Timing timing = Measure(
    [&] {
      const auto start = std::chrono::steady_clock::now();
      tree = std::make_unique<PclOctree>(scene.leafSize);
      tree->setInputCloud(points);
      tree->defineBoundingBox(cube.origin[0], cube.origin[1], cube.origin[2], cube.origin[0] + cube.size,
        cube.origin[1] + cube.size, cube.origin[2] + cube.size);
      tree->addPointsFromInputCloud();
      pclSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    },
    0, repeats,
    [&] {
      r.leaves = tree->getLeafCount();
      r.branches = tree->getBranchCount();
      depth = tree->getTreeDepth();
      tree.reset();
#if defined(__GLIBC__)
      // Freeing PCL's tree leaves a million small chunks in glibc's fast
      // bins; the next large allocation consolidates them (about 0.5 s at
      // 1 M points here). That is a cost of PCL's teardown, not of whatever
      // builds next: pay it here, untimed.
      malloc_trim(0);
#endif
      pairedRatios.push_back(pclSeconds / OneThreadBuildSeconds(scene));
    });
  r.pairs = pairedRatios.size();
  r.pairedRatio = Summarise(pairedRatios).median;
  r.sameTree = r.leaves == scene.leaves && r.branches == scene.branches && depth == unsigned(scene.depth);
  char note[160];
  std::snprintf(note, sizeof note, "depth %u, %zu leaves, %zu branches: %s", depth, r.leaves, r.branches,
    r.sameTree ? "same tree as octoray" : "DIFFERS from octoray");
  r.row = Row{ "pcl::octree::OctreePointCloudPointVector", CpuBackendName(1), timing, note, double(r.leaves) };
  return r;
}

// vtkOctreePointLocator, serial, with MaximumPointsPerRegion octoray's mean
// points a leaf rounded up.
Row MeasureOctreeLocator(const Scene& scene, vtkPolyData* polyData, int repeats)
{
  vtkSmartPointer<vtkOctreePointLocator> locator;
  int leaves = 0;
  vtkSMPTools::Initialize(1); // vtkOctreePointLocator is serial; keep SMP out of it anyway
  const Timing timing = Measure(
    [&] {
      locator = vtkSmartPointer<vtkOctreePointLocator>::New();
      locator->SetDataSet(polyData);
      locator->SetMaximumPointsPerRegion(scene.perRegion);
      locator->BuildLocator();
    },
    // About a minute per build at 10 M points on this 2-core machine.
    0, scene.c.n >= 5000000 ? 1 : repeats,
    [&] {
      leaves = locator->GetNumberOfLeafNodes();
      locator = nullptr;
    });
  char note[160];
  std::snprintf(note, sizeof note, "MaximumPointsPerRegion %d (octoray's mean %.2f rounded up): %d leaves",
    scene.perRegion, scene.meanPerLeaf, leaves);
  return Row{ "vtkOctreePointLocator", CpuBackendName(1), timing, note, double(leaves) };
}

// vtkStaticPointLocator through vtkSMPTools on `threads`, with
// NumberOfPointsPerBucket as MeasureOctreeLocator's regions.
Row MeasureStaticLocator(const Scene& scene, vtkPolyData* polyData, int threads, int repeats)
{
  vtkSMPTools::Initialize(threads);
  vtkSmartPointer<vtkStaticPointLocator> locator;
  int divisions[3] = { 0, 0, 0 };
  const Timing timing = Measure(
    [&] {
      locator = vtkSmartPointer<vtkStaticPointLocator>::New();
      locator->SetDataSet(polyData);
      locator->SetNumberOfPointsPerBucket(scene.perRegion);
      locator->BuildLocator();
    },
    // Cheap enough to take as many samples as octoray gets.
    1, repeats,
    [&] {
      locator->GetDivisions(divisions);
      locator = nullptr;
    });
  char note[160];
  std::snprintf(note, sizeof note, "NumberOfPointsPerBucket %d: %dx%dx%d buckets, %d SMP threads", scene.perRegion,
    divisions[0], divisions[1], divisions[2], vtkSMPTools::GetEstimatedNumberOfThreads());
  vtkSMPTools::Initialize(0);
  return Row{ "vtkStaticPointLocator", CpuBackendName(threads), timing, note,
    double(divisions[0]) * divisions[1] * divisions[2] };
}

// The case's points as a vtkPolyData for the VTK locators: our array
// wrapped, no copy.
vtkSmartPointer<vtkPolyData> WrapPoints(const Scene& scene)
{
  vtkNew<vtkFloatArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetArray(
    const_cast<float*>(scene.xyz.data()), static_cast<vtkIdType>(3 * scene.c.n), 1 /* not ours to free */);
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);
  auto polyData = vtkSmartPointer<vtkPolyData>::New();
  polyData->SetPoints(points);
  return polyData;
}

// octoray's timing on the threads of `backend` (CpuBackendName).
const Timing& OctorayTiming(const std::vector<Row>& rows, const std::string& backend)
{
  return std::find_if(rows.begin(), rows.end(), [&](const Row& r) { return r.what == "octoray" && r.backend == backend; })
    ->timing;
}

// The table, every peer against octoray with the same thread count, and
// the peers' records.
void Report(const Scene& scene, const std::vector<Row>& rows, const PclResult& pcl, std::size_t engineBytes,
  std::vector<Record>& records)
{
  std::printf("%-42s %-13s %10s %10s %5s %9s  %s\n", "build", "threads", "median s", "min s", "runs", "peer/ours",
    "notes");
  for (const Row& row : rows)
  {
    const bool isOurs = row.what == "octoray";
    const Timing& mine = OctorayTiming(rows, row.backend);
    char ratio[32] = "";
    if (!isOurs)
    {
      std::snprintf(ratio, sizeof ratio, "%.2fx", row.timing.median / mine.median);
    }
    std::printf("%-42s %-13s %10.4f %10.4f %5d %9s  %s\n", row.what.c_str(), row.backend.c_str(), row.timing.median,
      row.timing.min, row.timing.repeats, ratio, row.note.c_str());
    if (isOurs)
    {
      continue;
    }
    Record r;
    r.name = "build_vs_" + row.what + "/" + scene.c.set;
    r.backend = row.backend;
    r.n = scene.c.n;
    r.depth = scene.depth;
    r.seconds = mine.median;
    r.peer = row.what;
    r.peerSeconds = row.timing.median;
    r.With("min_seconds", mine.min)
      .With("peer_min_seconds", row.timing.min)
      .With("peer_runs", row.timing.repeats)
      .With("leaves", double(scene.leaves))
      .With("branches", double(scene.branches))
      .With("peer_leaves", row.leaves)
      .With("engine_bytes", double(engineBytes));
    if (row.what == pcl.row.what)
    {
      r.With("same_tree", pcl.sameTree ? 1.0 : 0.0).With("paired_ratio", pcl.pairedRatio);
    }
    records.push_back(r);
  }
}

// The case's closing lines: the paired ratio, octoray on all `threads`
// against PCL, its memory and both trees' counts.
void PrintSummary(
  const Scene& scene, const std::vector<Row>& rows, const PclResult& pcl, int threads, std::size_t engineBytes)
{
  std::printf("PCL / octoray (1 thread), median of %zu builds each paired with an octoray build: %.2fx\n", pcl.pairs,
    pcl.pairedRatio);
  if (threads > 1)
  {
    std::printf("octoray %d threads vs PCL (1 thread): %.2fx\n", threads,
      pcl.row.timing.median / OctorayTiming(rows, CpuBackendName(threads)).median);
  }
  std::printf("octoray memory: %.1f B/point (%s; points, keys, sort buffers and nodes); dense pointer skeleton "
              "of depth %d: %s (8 B x (8^%d-1)/7)\n",
    double(engineBytes) / scene.c.n, HumanBytes(double(engineBytes)).c_str(), scene.depth,
    HumanBytes(DenseSkeletonBytes(scene.depth)).c_str(), scene.depth + 1);
  std::printf("octoray: %zu leaves, %zu branches; PCL: %zu leaves, %zu branches%s\n", scene.leaves, scene.branches,
    pcl.leaves, pcl.branches, pcl.sameTree ? "" : "  <-- MISMATCH");
}

// Every peer on one case; appends the peers' records.
void RunCase(const Case& c, const Settings& s, std::vector<Record>& records)
{
  const Scene scene(c, s.requestedDepth);
  std::printf("\n== %s, %zu points: depth %d, leaf voxel %.6g (cube %.6g), %zu leaves, %.2f points per leaf\n",
    c.set.c_str(), c.n, scene.depth, scene.leafSize, scene.cube.size, scene.leaves, scene.meanPerLeaf);
  std::vector<Row> rows;
  std::size_t engineBytes = 0;
  for (int threads : s.ThreadCounts())
  {
    rows.push_back(MeasureOctoray(scene, threads, s.repeats, engineBytes));
  }
  const PclResult pcl = MeasurePcl(scene, s.peerRepeats);
  rows.push_back(pcl.row);
  const vtkSmartPointer<vtkPolyData> polyData = WrapPoints(scene);
  if (double(c.n) <= s.octreeLocatorMax)
  {
    rows.push_back(MeasureOctreeLocator(scene, polyData, s.peerRepeats));
  }
  else
  {
    std::printf("vtkOctreePointLocator left out: %zu points > --octree-locator-max %.0f\n", c.n, s.octreeLocatorMax);
  }
  for (int threads : s.ThreadCounts())
  {
    rows.push_back(MeasureStaticLocator(scene, polyData, threads, s.repeats));
  }
  Report(scene, rows, pcl, engineBytes, records);
  PrintSummary(scene, rows, pcl, s.threads, engineBytes);
}
}

int main(int argc, char** argv)
{
  Settings s;
  if (const std::optional<int> stop = OptionsOf(s).ParseOrStop(argc, argv, kUsage))
  {
    return *stop;
  }
  std::printf("octoray_bench_peers: octoray median of %d fresh builds after 1 warm-up; PCL and VTK median of %d "
              "fresh builds, no warm-up (10 M PCL builds take seconds each; vtkOctreePointLocator: 1 build from 5 M "
              "points)\n",
    s.repeats, s.peerRepeats);
  ChooseThreadedSmpBackend();
  std::vector<Record> records;
  try
  {
    for (const Case& c : s.cases)
    {
      RunCase(c, s, records);
    }
    SaveRecords(s.json, records);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "octoray_bench_peers: %s\n", e.what());
    return 1;
  }
  return 0;
}
