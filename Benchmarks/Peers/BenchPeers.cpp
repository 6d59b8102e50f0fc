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

// The usage, on `to`; the exit status.
int Usage(std::FILE* to = stderr)
{
  return CommandLine::PrintUsage(to,
    "usage: octoray_bench_peers [--cases SET:N[,SET:N...]] [--depth L (0: automatic)] [--threads N]\n"
    "                           [--repeats R] [--peer-repeats R] [--octree-locator-max N] [--json PATH]\n"
    "  SET is uniform or clustered; N may be written 1e7\n");
}

struct Case
{
  std::string set;
  std::size_t n = 0;
};

// Times `build` after `warmups`; `reset` runs untimed after each call, so
// freeing a tree of millions of nodes is not charged to its build.
Timing MeasureFresh(
  const std::function<void()>& build, const std::function<void()>& reset, int warmups, int repeats)
{
  return Measure(build, warmups, repeats, reset);
}

std::string CpuBackendName(int threads)
{
  return "cpu-" + std::to_string(threads) + (threads == 1 ? "thread" : "threads");
}

struct Row
{
  std::string what;
  std::string backend; // octoray's configuration this peer is compared with
  Timing timing;
  std::string note;
  double leaves = 0; // the peer's leaves or buckets, for the report
};
}

int main(int argc, char** argv)
{
  std::vector<Case> cases = { { "uniform", 1000000 }, { "uniform", 10000000 }, { "clustered", 1000000 } };
  int requestedDepth = 0;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  int repeats = 5;
  int peerRepeats = 3;
  double octreeLocatorMax = 1e300;
  std::string json;
  CommandLine options;
  options
    .Option("--cases", "a list SET:N of uniform or clustered and a count",
      [&](const std::string& v) {
        cases.clear();
        for (const std::string& item : SplitList(v))
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
      })
    .Integer("--depth", requestedDepth)
    .Integer("--threads", threads, 1)
    .Integer("--repeats", repeats, 1)
    .Integer("--peer-repeats", peerRepeats, 1)
    .Real("--octree-locator-max", octreeLocatorMax)
    .Text("--json", json);
  if (CommandLine::AsksForHelp(argc, argv))
  {
    return Usage(stdout);
  }
  if (!options.Parse(argc, argv))
  {
    return Usage();
  }

  std::printf("octoray_bench_peers: octoray median of %d fresh builds after 1 warm-up; PCL and VTK median of %d "
              "fresh builds, no warm-up (10 M PCL builds take seconds each; vtkOctreePointLocator: 1 build from 5 M points)\n",
    repeats, peerRepeats);
  // Debian's ParaView defaults to the Sequential SMP backend; ask for a
  // threaded one so that vtkStaticPointLocator's threaded build is measured.
  const std::string defaultBackend = vtkSMPTools::GetBackend();
  if (defaultBackend == "Sequential")
  {
    vtkSMPTools::SetBackend("STDThread") || vtkSMPTools::SetBackend("TBB") || vtkSMPTools::SetBackend("OpenMP");
  }
  std::printf("vtkSMPTools backend %s (default %s); %u hardware threads\n", vtkSMPTools::GetBackend(),
    defaultBackend.c_str(), std::thread::hardware_concurrency());

  std::vector<Record> records;
  try
  {
    for (const Case& c : cases)
    {
      const std::size_t n = c.n;
      const std::vector<float> xyz = c.set == "uniform" ? UniformCube(n) : GaussianClusters(n);
      PointCloudView cloud;
      cloud.count = n;
      cloud.xyzFloat = xyz.data();

      // The tree every library is asked for: octoray's cube and depth.
      BuildOptions options;
      options.depth = requestedDepth;
      HostOctree reference;
      {
        auto engine = CreateEngine(Backend::CPU);
        engine->Build(cloud, options);
        engine->CopyToHost(reference);
      }
      const int depth = reference.depth;
      options.depth = depth; // timed builds get the depth, as PCL gets its resolution
      const RootCube cube = reference.cube;
      const double leafSize = cube.size / std::ldexp(1.0, depth);
      const std::size_t leaves = reference.levelBegin[depth + 1] - reference.levelBegin[depth];
      const std::size_t branches = reference.NodeCount() - leaves;
      const double meanPerLeaf = double(n) / double(leaves);
      const int perRegion = std::max(1, static_cast<int>(std::ceil(meanPerLeaf)));

      std::printf("\n== %s, %zu points: depth %d, leaf voxel %.6g (cube %.6g), %zu leaves, %.2f points per leaf\n",
        c.set.c_str(), n, depth, leafSize, cube.size, leaves, meanPerLeaf);

      std::vector<Row> rows;
      std::size_t engineBytes = 0;

      // octoray, 1 thread and all threads.
      Timing ours[2];
      const int threadCounts[2] = { 1, threads };
      for (int t = 0; t < (threads > 1 ? 2 : 1); ++t)
      {
        std::unique_ptr<Engine> engine;
        ours[t] = MeasureFresh(
          [&] {
            engine = CreateEngine(Backend::CPU);
            engine->SetThreadCount(threadCounts[t]);
            engine->Build(cloud, options);
          },
          [&] {
            engineBytes = engine->Memory().Total();
            engine.reset();
          },
          1, repeats);
        rows.push_back(Row{ "octoray", CpuBackendName(threadCounts[t]), ours[t], "" });
      }

      // PCL: the same cube; resolution = leaf voxel, so its depth is ours.
      pcl::PointCloud<pcl::PointXYZ>::Ptr pclCloud(new pcl::PointCloud<pcl::PointXYZ>);
      pclCloud->resize(n);
      for (std::size_t i = 0; i < n; ++i)
      {
        (*pclCloud)[i] = pcl::PointXYZ(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
      }
      using PclOctree = pcl::octree::OctreePointCloudPointVector<pcl::PointXYZ>;
      std::unique_ptr<PclOctree> pclTree;
      std::size_t pclLeaves = 0, pclBranches = 0;
      unsigned pclDepth = 0;
      // Each PCL build is paired with a single-threaded octoray build run
      // right after it (untimed for PCL): on a shared machine the load
      // drifts between the octoray and PCL blocks above and below, and the
      // median of the per-pair ratios is what that drift does not move.
      std::vector<double> pairedRatios;
      double pclSeconds = 0.0;
      const Timing pcl = MeasureFresh(
        [&] {
          const auto start = std::chrono::steady_clock::now();
          pclTree = std::make_unique<PclOctree>(leafSize);
          pclTree->setInputCloud(pclCloud);
          pclTree->defineBoundingBox(cube.origin[0], cube.origin[1], cube.origin[2], cube.origin[0] + cube.size,
            cube.origin[1] + cube.size, cube.origin[2] + cube.size);
          pclTree->addPointsFromInputCloud();
          pclSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        },
        [&] {
          pclLeaves = pclTree->getLeafCount();
          pclBranches = pclTree->getBranchCount();
          pclDepth = pclTree->getTreeDepth();
          pclTree.reset();
#if defined(__GLIBC__)
          // Freeing PCL's tree leaves a million small chunks in glibc's
          // fast bins; the next large allocation consolidates them (about
          // 0.5 s at 1 M points here). That is a cost of PCL's teardown, not
          // of whatever builds next: pay it here, untimed.
          malloc_trim(0);
#endif
          auto engine = CreateEngine(Backend::CPU);
          engine->SetThreadCount(1);
          const auto start = std::chrono::steady_clock::now();
          engine->Build(cloud, options);
          pairedRatios.push_back(
            pclSeconds / std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        },
        0, peerRepeats);
      std::sort(pairedRatios.begin(), pairedRatios.end());
      const std::size_t pairs = pairedRatios.size();
      const double pairedRatio = pairs % 2 ? pairedRatios[pairs / 2]
                                           : 0.5 * (pairedRatios[pairs / 2 - 1] + pairedRatios[pairs / 2]);
      const bool same = pclLeaves == leaves && pclBranches == branches && pclDepth == unsigned(depth);
      char pclNote[160];
      std::snprintf(pclNote, sizeof pclNote, "depth %u, %zu leaves, %zu branches: %s", pclDepth, pclLeaves,
        pclBranches, same ? "same tree as octoray" : "DIFFERS from octoray");
      rows.push_back(Row{ "pcl::octree::OctreePointCloudPointVector", CpuBackendName(1), pcl, pclNote, double(pclLeaves) });
      pclCloud.reset();

      // VTK locators read a vtkPolyData's points; wrap our array, no copy.
      vtkNew<vtkFloatArray> coordinates;
      coordinates->SetNumberOfComponents(3);
      coordinates->SetArray(const_cast<float*>(xyz.data()), static_cast<vtkIdType>(3 * n), 1 /* not ours to free */);
      vtkNew<vtkPoints> points;
      points->SetData(coordinates);
      vtkNew<vtkPolyData> polyData;
      polyData->SetPoints(points);

      if (double(n) <= octreeLocatorMax)
      {
        vtkSmartPointer<vtkOctreePointLocator> octreeLocator;
        int vtkLeaves = 0;
        vtkSMPTools::Initialize(1); // vtkOctreePointLocator is serial; keep SMP out of it anyway
        const Timing vtkOctree = MeasureFresh(
          [&] {
            octreeLocator = vtkSmartPointer<vtkOctreePointLocator>::New();
            octreeLocator->SetDataSet(polyData);
            octreeLocator->SetMaximumPointsPerRegion(perRegion);
            octreeLocator->BuildLocator();
          },
          [&] {
            vtkLeaves = octreeLocator->GetNumberOfLeafNodes();
            octreeLocator = nullptr;
          },
          // About a minute per build at 10 M points on this 2-core machine.
          0, n >= 5000000 ? 1 : peerRepeats);
        char octreeNote[160];
        std::snprintf(octreeNote, sizeof octreeNote, "MaximumPointsPerRegion %d (octoray's mean %.2f rounded up): %d leaves",
          perRegion, meanPerLeaf, vtkLeaves);
        rows.push_back(Row{ "vtkOctreePointLocator", CpuBackendName(1), vtkOctree, octreeNote, double(vtkLeaves) });
      }
      else
      {
        std::printf("vtkOctreePointLocator left out: %zu points > --octree-locator-max %.0f\n", n, octreeLocatorMax);
      }

      for (int t = 0; t < (threads > 1 ? 2 : 1); ++t)
      {
        vtkSMPTools::Initialize(threadCounts[t]);
        vtkSmartPointer<vtkStaticPointLocator> staticLocator;
        int divisions[3] = { 0, 0, 0 };
        const Timing vtkStatic = MeasureFresh(
          [&] {
            staticLocator = vtkSmartPointer<vtkStaticPointLocator>::New();
            staticLocator->SetDataSet(polyData);
            staticLocator->SetNumberOfPointsPerBucket(perRegion);
            staticLocator->BuildLocator();
          },
          [&] {
            staticLocator->GetDivisions(divisions);
            staticLocator = nullptr;
          },
          // Cheap enough to take as many samples as octoray gets.
          1, repeats);
        char staticNote[160];
        std::snprintf(staticNote, sizeof staticNote, "NumberOfPointsPerBucket %d: %dx%dx%d buckets, %d SMP threads",
          perRegion, divisions[0], divisions[1], divisions[2], vtkSMPTools::GetEstimatedNumberOfThreads());
        rows.push_back(Row{ "vtkStaticPointLocator", CpuBackendName(threadCounts[t]), vtkStatic, staticNote,
          double(divisions[0]) * divisions[1] * divisions[2] });
      }
      vtkSMPTools::Initialize(0);

      // The table: every peer against octoray with the same thread count.
      std::printf("%-42s %-13s %10s %10s %5s %9s  %s\n", "build", "threads", "median s", "min s", "runs",
        "peer/ours", "notes");
      for (const Row& row : rows)
      {
        const Timing& mine = row.backend == CpuBackendName(1) ? ours[0] : ours[1];
        const bool isOurs = row.what == "octoray";
        char ratio[32] = "";
        if (!isOurs)
        {
          std::snprintf(ratio, sizeof ratio, "%.2fx", row.timing.median / mine.median);
        }
        std::printf("%-42s %-13s %10.4f %10.4f %5d %9s  %s\n", row.what.c_str(), row.backend.c_str(),
          row.timing.median, row.timing.min, row.timing.repeats, ratio, row.note.c_str());
        if (!isOurs)
        {
          Record r;
          r.name = "build_vs_" + row.what + "/" + c.set;
          r.backend = row.backend;
          r.n = n;
          r.depth = depth;
          r.seconds = mine.median;
          r.peer = row.what;
          r.peerSeconds = row.timing.median;
          r.With("min_seconds", mine.min)
            .With("peer_min_seconds", row.timing.min)
            .With("peer_runs", row.timing.repeats)
            .With("leaves", double(leaves))
            .With("branches", double(branches))
            .With("peer_leaves", row.leaves)
            .With("engine_bytes", double(engineBytes));
          if (row.what == "pcl::octree::OctreePointCloudPointVector")
          {
            r.With("same_tree", same ? 1.0 : 0.0).With("paired_ratio", pairedRatio);
          }
          records.push_back(r);
        }
      }
      std::printf("PCL / octoray (1 thread), median of %zu builds each paired with an octoray build: %.2fx\n", pairs,
        pairedRatio);
      if (threads > 1)
      {
        std::printf("octoray %d threads vs PCL (1 thread): %.2fx\n", threads, pcl.median / ours[1].median);
      }
      std::printf("octoray memory: %.1f B/point (%s; points, keys, sort buffers and nodes); dense pointer skeleton "
                  "of depth %d: %s (8 B x (8^%d-1)/7)\n",
        double(engineBytes) / n, HumanBytes(double(engineBytes)).c_str(), depth,
        HumanBytes(DenseSkeletonBytes(depth)).c_str(), depth + 1);
      std::printf("octoray: %zu leaves, %zu branches; PCL: %zu leaves, %zu branches%s\n", leaves, branches, pclLeaves,
        pclBranches, same ? "" : "  <-- MISMATCH");
    }
    SaveRecords(json, records);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "octoray_bench_peers: %s\n", e.what());
    return 1;
  }
  return 0;
}
