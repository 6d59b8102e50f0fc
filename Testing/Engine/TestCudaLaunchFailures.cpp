// A refused CUDA kernel launch (issue 8), injected at every kernel of build,
// update and render (octoray/FaultInjection.h): the CUDA runtime refuses the
// launch for real and the engine's own check reports it. Each failure must
// name the kernel, leave no sticky error behind, and leave an octree that is
// either the previous one, intact (build, render, an update refused before
// its first write) or none at all, said so (an update that had begun).
#include "TestSupport.h"

#include <octoray/FaultInjection.h>
#include <octoray/Frame.h>

#include <functional>

using namespace octoray;
using namespace octoray::test;

namespace
{
// The engine's words for a refused launch of `kernel`, then CUDA's reason
// (an empty grid is "invalid argument" in CUDA 13, "invalid configuration
// argument" in earlier releases; the reason is CUDA's, not ours), then
// `after`.
::testing::AssertionResult IsRefusal(const std::string& message, const std::string& kernel,
  const std::string& after = "")
{
  const std::string prefix = "octoray: CUDA launch of " + kernel + " failed: ";
  const bool prefixOk = message.compare(0, prefix.size(), prefix) == 0;
  const bool afterOk = message.size() >= prefix.size() + after.size() + 1 &&
    message.compare(message.size() - after.size(), after.size(), after) == 0;
  if (prefixOk && afterOk)
  {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "\"" << message << "\" is not \"" << prefix << "<CUDA's reason>" << after
                                       << "\"";
}

// What `call` threw, or "(no error)".
std::string ErrorOf(const std::function<void()>& call)
{
  try
  {
    call();
  }
  catch (const Error& e)
  {
    return e.what();
  }
  return "(no error)";
}

RenderSettings SmallView()
{
  RenderSettings s;
  s.width = 64;
  s.height = 48;
  const double viewProjection[16] = { 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, -0.5, 0, 0, 0, 0, 1 };
  Invert4x4(viewProjection, s.inverseViewProjection);
  return s;
}

std::vector<float> Picture(Engine& engine)
{
  Image image;
  engine.Render(SmallView(), image);
  return image.rgba;
}

// Every point twice, so that moving one copy of a point onto another point
// empties no node and creates none: the in-place update path.
Cloud Doubled(const Cloud& c)
{
  Cloud d = c;
  d.Append(c);
  return d;
}

class CudaFaultsLaunch : public CudaOnlyTest
{
protected:
  void TearDown() override { InjectCudaLaunchFailure(""); }
};

// A build of `second` with `refused` (the automatic depth, say) whose
// launch of `kernel` the runtime refuses: the error names the kernel, the
// octree of `first` and its picture stay as they were, and a build of
// `second` at the fixed depth then succeeds.
void ExpectRefusedBuildKeepsTheOctree(const Cloud& first, const Cloud& second, const char* kernel,
  const BuildOptions& fixedDepth, const BuildOptions& refused)
{
  auto engine = CreateEngine(Backend::CUDA);
  engine->Build(first.View(), fixedDepth);
  HostOctree before;
  engine->CopyToHost(before);
  const std::vector<float> picture = Picture(*engine);

  InjectCudaLaunchFailure(kernel);
  EXPECT_TRUE(IsRefusal(ErrorOf([&] { engine->Build(second.View(), refused); }), kernel));

  HostOctree after;
  engine->CopyToHost(after);
  ExpectSameOctree(after, before, true);
  EXPECT_EQ(Picture(*engine), picture);

  // Nothing sticky: the same build now succeeds and is right.
  engine->Build(second.View(), fixedDepth);
  engine->CopyToHost(after);
  ExpectMatchesReference(after, second);
}
}

TEST_F(CudaFaultsLaunch, BuildKeepsThePreviousOctree)
{
  const Cloud first = UniformCloud(1500, 61);
  // Its automatic depth lies beyond level 13: the sorts of 13 levels and of
  // full depth run too, their keys computed again. Records of two words
  // (colours and reflectivity) travel with the first sort's keys.
  Cloud tight = TightClusters(300, 1e-5, 47);
  tight.scalar.clear();
  tight.normal.clear();
  tight.refraction.clear();
  // Levels of more children than SmallLevelsKernel takes (InnerKernel).
  const Cloud wide = UniformCloud(50000, 62);
  // Records of two words over 1 MB of input: staged, its keys and sort
  // queued from a staging thread during the attributes' upload, its leaf
  // loop reading the records through the sorted indices after it.
  Cloud staged = UniformCloud(60000, 64);
  staged.scalar.clear();
  staged.normal.clear();
  staged.refraction.clear();
  BuildOptions fixedDepth;
  fixedDepth.depth = 6;
  BuildOptions automaticDepth; // depth 0: the count of the levels' run starts adds up the depth's histograms too

  for (const char* kernel : { "ReduceRangeKernel", "PointRecordsKernel", "KeysKernel", "LevelCountKernel",
         "LevelStartsKernel", "LeafKernel", "InnerKernel", "SmallLevelsKernel" })
  {
    const std::string name = kernel;
    const std::vector<const Cloud*> seconds =
      name == "InnerKernel" ? std::vector<const Cloud*>{ &wide } : std::vector<const Cloud*>{ &tight, &staged };
    for (const Cloud* second : seconds)
    {
      SCOPED_TRACE(name + (second == &staged ? ", staged" : ""));
      ExpectRefusedBuildKeepsTheOctree(first, *second, kernel, fixedDepth, automaticDepth);
    }
  }
}

// A fixed cube that leaves points out: the loop that finds the first of
// them is refused, for a cloud the engine copies itself and for one it
// stages; the error names that loop, not a point.
TEST_F(CudaFaultsLaunch, CubeCheckKeepsThePreviousOctree)
{
  const Cloud first = UniformCloud(1500, 61);
  BuildOptions fixedDepth;
  fixedDepth.depth = 6;
  BuildOptions tooSmall = fixedDepth;
  tooSmall.fixedCube = true; // the unit cube from the origin: the clouds span [-1, 1]
  for (const Cloud& second : { UniformCloud(1500, 65), UniformCloud(60000, 66) })
  {
    SCOPED_TRACE(second.Size());
    ExpectRefusedBuildKeepsTheOctree(first, second, "OutsideCubeKernel", fixedDepth, tooSmall);
  }
}

TEST_F(CudaFaultsLaunch, RenderKeepsTheOctreeAndTheNextFrame)
{
  const Cloud cloud = UniformCloud(3000, 63);
  BuildOptions options;
  options.depth = 6;
  auto engine = CreateEngine(Backend::CUDA);
  engine->Build(cloud.View(), options);
  const std::vector<float> picture = Picture(*engine);

  InjectCudaLaunchFailure("RenderKernel");
  EXPECT_TRUE(IsRefusal(ErrorOf([&] { Picture(*engine); }), "RenderKernel"));
  EXPECT_EQ(Picture(*engine), picture);
}

// Normals estimated for a cloud without them (RenderSettings::
// estimateNormals) are made at the first frame that shades by them: a
// refused estimate is that frame's error, and the next frame makes them.
TEST_F(CudaFaultsLaunch, RefusedNormalEstimationIsMadeByTheNextFrame)
{
  const Cloud cloud = UniformCloud(3000, 65).WithExactMeans(); // no normals
  BuildOptions options;
  options.depth = 6;
  RenderSettings s = SmallView();
  s.shade = ShadeMode::Phong;
  s.estimateNormals = true;
  const auto picture = [&](Engine& engine) {
    Image image;
    engine.Render(s, image);
    return image.rgba;
  };
  auto engine = CreateEngine(Backend::CUDA);
  engine->Build(cloud.View(), options);
  InjectCudaLaunchFailure("EstimateNormalsKernel");
  EXPECT_TRUE(IsRefusal(ErrorOf([&] { picture(*engine); }), "EstimateNormalsKernel"));
  auto fresh = CreateEngine(Backend::CUDA);
  fresh->Build(cloud.View(), options);
  EXPECT_EQ(picture(*engine), picture(*fresh));
}

TEST_F(CudaFaultsLaunch, UpdateSaysWhatBecameOfTheOctree)
{
  const Cloud base = UniformCloud(4000, 64).WithExactMeans(); // the in-place path: no rounded means
  const Cloud cloud = Doubled(base);
  BuildOptions options;
  options.depth = 6;
  // The second copies of points 0..9 move onto points 100..109.
  std::vector<std::uint32_t> indices;
  std::vector<double> to;
  for (std::uint32_t k = 0; k < 10; ++k)
  {
    indices.push_back(static_cast<std::uint32_t>(base.Size()) + k);
    to.insert(to.end(), base.xyz.begin() + 3 * (100 + k), base.xyz.begin() + 3 * (100 + k) + 3);
  }
  PositionsView moves;
  moves.count = indices.size();
  moves.indices = indices.data();
  moves.xyzDouble = to.data();

  // Without a failure these moves take the in-place path, so its kernels
  // (path records, emptied nodes, deltas) are the ones refused below.
  {
    auto engine = CreateEngine(Backend::CUDA);
    engine->Build(cloud.View(), options);
    ASSERT_EQ(engine->Update(moves).path, UpdateStats::Path::InPlace);
  }

  // Refused before the first write: the octree is the one before the update.
  {
    auto engine = CreateEngine(Backend::CUDA);
    engine->Build(cloud.View(), options);
    HostOctree before, after;
    engine->CopyToHost(before);
    const std::vector<float> picture = Picture(*engine);
    InjectCudaLaunchFailure("ReduceRangeKernel"); // the moved positions' bounds: their check for NaN
    EXPECT_TRUE(IsRefusal(ErrorOf([&] { engine->Update(moves); }), "ReduceRangeKernel"));
    engine->CopyToHost(after);
    ExpectSameOctree(after, before, true);
    EXPECT_EQ(Picture(*engine), picture);
  }

  // Refused after it began writing: no octree, said so, until a build.
  for (const char* kernel :
    { "ScatterPositionsKernel", "MovedKeysKernel", "PathRecordsKernel", "EmptiedNodesKernel", "ApplyDeltasKernel" })
  {
    SCOPED_TRACE(kernel);
    auto engine = CreateEngine(Backend::CUDA);
    engine->Build(cloud.View(), options);
    InjectCudaLaunchFailure(kernel);
    EXPECT_TRUE(IsRefusal(ErrorOf([&] { engine->Update(moves); }), kernel,
      " (the update had begun: the octree was discarded; build again)"));
    EXPECT_EQ(engine->PointCount(), 0u);
    EXPECT_EQ(ErrorOf([&] { Picture(*engine); }),
      "octoray: render after a failed update discarded the octree; build again");
    EXPECT_EQ(ErrorOf([&] { engine->Update(moves); }),
      "octoray: update after a failed update discarded the octree; build again");

    engine->Build(cloud.View(), options);
    engine->Update(moves);
    HostOctree after;
    engine->CopyToHost(after);
    Cloud moved = cloud;
    for (std::size_t k = 0; k < indices.size(); ++k)
    {
      std::copy(to.begin() + 3 * k, to.begin() + 3 * k + 3, moved.xyz.begin() + 3 * indices[k]);
    }
    ExpectMatchesReference(after, moved);
  }
}
