// Updates of moved points against a fresh build of the new positions in the
// same root cube, on every backend.
#include "TestSupport.h"

using namespace octoray;
using namespace octoray::test;

using OctreeUpdate = BackendTest;

namespace
{
struct Fixture
{
  Cloud cloud;
  HostOctree tree;
};

// Moves cloud points (indices) to `to` through Update, then checks the
// result against a fresh build in the same cube and against the reference.
UpdateStats MoveAndCheck(Backend backend, Engine& engine, Cloud& cloud, const std::vector<std::uint32_t>& indices,
  const std::vector<double>& to, bool allPoints = false)
{
  for (std::size_t k = 0; k < indices.size(); ++k)
  {
    for (int a = 0; a < 3; ++a)
    {
      cloud.xyz[3 * indices[k] + a] = to[3 * k + a];
    }
  }
  PositionsView moved;
  moved.count = allPoints ? cloud.Size() : indices.size();
  moved.xyzDouble = allPoints ? cloud.xyz.data() : to.data();
  moved.indices = allPoints ? nullptr : indices.data();
  const UpdateStats stats = engine.Update(moved);
  EXPECT_EQ(stats.moved, moved.count);

  HostOctree updated;
  engine.CopyToHost(updated);
  auto fresh = CreateEngine(backend);
  BuildOptions same;
  same.depth = updated.depth;
  same.fixedCube = true;
  same.cube = updated.cube;
  fresh->Build(cloud.View(), same);
  HostOctree rebuilt;
  fresh->CopyToHost(rebuilt);
  ExpectSameOctree(updated, rebuilt);
  ExpectMatchesReference(updated, cloud);
  return stats;
}

// A position whose grid cell differs from p's at `level` (and below), but
// not above: p's cell with the level's bit of x flipped.
std::vector<double> AcrossBoundaryAt(const RootCube& cube, const double* p, int level)
{
  std::uint32_t cell[3];
  EXPECT_TRUE(cube.GridCell(p[0], p[1], p[2], cell));
  cell[0] ^= 1u << (kMaxLevel - level);
  std::vector<double> q(3);
  for (int a = 0; a < 3; ++a)
  {
    q[a] = cube.origin[a] + (cell[a] + 0.5) * cube.size / 2097152.0;
  }
  return q;
}
}

TEST_P(OctreeUpdate, SmallMovesInsideLeavesChangeNothing)
{
  Cloud c = UniformCloud(5000, 31);
  BuildOptions options;
  options.depth = 4;
  engine->Build(c.View(), options);
  HostOctree t;
  engine->CopyToHost(t);
  // Move 10 points to the centre of their own depth-4 leaf.
  std::vector<std::uint32_t> idx;
  std::vector<double> to;
  for (std::uint32_t i = 0; i < 10; ++i)
  {
    std::uint32_t cell[3];
    ASSERT_TRUE(t.cube.GridCell(c.xyz[3 * i], c.xyz[3 * i + 1], c.xyz[3 * i + 2], cell));
    idx.push_back(i * 37);
    ASSERT_TRUE(t.cube.GridCell(c.xyz[3 * idx.back()], c.xyz[3 * idx.back() + 1], c.xyz[3 * idx.back() + 2], cell));
    for (int a = 0; a < 3; ++a)
    {
      const std::uint32_t leafCell = cell[a] >> 17;
      to.push_back(t.cube.origin[a] + (leafCell + 0.5) * t.cube.size / 16.0);
    }
  }
  const UpdateStats s = MoveAndCheck(GetParam(), *engine, c, idx, to);
  EXPECT_EQ(s.path, UpdateStats::Path::Unchanged);
  EXPECT_EQ(s.changedLeaf, 0u);
}

// Builds c (20 000 points, dense at depth 3: every leaf holds ~40 of them)
// and moves 20 points onto other points' positions, which empties no leaf
// and creates none.
UpdateStats MoveOntoOtherPoints(Backend backend, Engine& engine, Cloud& c)
{
  BuildOptions options;
  options.depth = 3;
  engine.Build(c.View(), options);
  std::vector<std::uint32_t> idx;
  std::vector<double> to;
  for (std::uint32_t k = 0; k < 20; ++k)
  {
    idx.push_back(k * 101);
    const std::uint32_t target = 19999 - k * 53;
    to.insert(to.end(), { c.xyz[3 * target], c.xyz[3 * target + 1], c.xyz[3 * target + 2] });
  }
  return MoveAndCheck(backend, engine, c, idx, to);
}

TEST_P(OctreeUpdate, FewPointsBetweenOccupiedLeavesUpdateInPlace)
{
  Cloud c = UniformCloud(20000, 32).WithExactMeans();
  const UpdateStats s = MoveOntoOtherPoints(GetParam(), *engine, c);
  EXPECT_EQ(s.path, UpdateStats::Path::InPlace);
  EXPECT_GT(s.changedLeaf, 10u);
}

// The same moves with 8-bit colours, scalars and normals: adjusting their rounded
// means would carry the rounding, so the update re-sorts, and every colour,
// scalar and normal is again within its bound of its mean (MoveAndCheck).
TEST_P(OctreeUpdate, RoundedMeansReSortInsteadOfBeingAdjusted)
{
  Cloud c = UniformCloud(20000, 32);
  const UpdateStats s = MoveOntoOtherPoints(GetParam(), *engine, c);
  EXPECT_EQ(s.path, UpdateStats::Path::Relevel);
  EXPECT_GT(s.changedLeaf, 10u);
}

TEST_P(OctreeUpdate, RandomMovesOfSomePoints)
{
  Cloud c = GaussianClusters(20000, 33);
  BuildOptions options;
  options.depth = 10;
  engine->Build(c.View(), options);
  std::mt19937_64 rng(34);
  std::uniform_int_distribution<std::uint32_t> pick(0, 19999);
  std::normal_distribution<double> step(0.0, 0.05);
  for (int round = 0; round < 3; ++round)
  {
    std::vector<std::uint32_t> idx;
    std::vector<double> to;
    for (int k = 0; k < 2000; ++k)
    {
      idx.push_back(pick(rng));
      for (int a = 0; a < 3; ++a)
      {
        // Clamped to the data's box so that the cube is kept.
        const double v = c.xyz[3 * idx.back() + a] + step(rng);
        to.push_back(std::max(-4.0, std::min(4.0, v)));
      }
    }
    // Remove duplicates: the engine refuses a point listed twice.
    std::vector<std::uint32_t> uniqueIdx;
    std::vector<double> uniqueTo;
    std::vector<bool> seen(20000, false);
    for (std::size_t k = 0; k < idx.size(); ++k)
    {
      if (!seen[idx[k]])
      {
        seen[idx[k]] = true;
        uniqueIdx.push_back(idx[k]);
        uniqueTo.insert(uniqueTo.end(), to.begin() + 3 * k, to.begin() + 3 * k + 3);
      }
    }
    const UpdateStats s = MoveAndCheck(GetParam(), *engine, c, uniqueIdx, uniqueTo);
    EXPECT_NE(s.path, UpdateStats::Path::NewCube);
  }
}

TEST_P(OctreeUpdate, AllPointsMoved)
{
  Cloud c = UniformCloud(10000, 35);
  BuildOptions options;
  options.depth = 8;
  engine->Build(c.View(), options);
  // Shrink the cloud towards the centre: every point stays in the cube.
  for (double& v : c.xyz)
  {
    v *= 0.5;
  }
  const UpdateStats s = MoveAndCheck(GetParam(), *engine, c, {}, {}, true);
  EXPECT_EQ(s.path, UpdateStats::Path::Relevel);
}

TEST_P(OctreeUpdate, MovesAcrossNodeBoundariesAtEveryLevel)
{
  Cloud c = UniformCloud(3000, 36);
  BuildOptions options;
  options.depth = 21;
  engine->Build(c.View(), options);
  HostOctree t;
  engine->CopyToHost(t);
  for (int level = 1; level <= 21; ++level)
  {
    SCOPED_TRACE("level " + std::to_string(level));
    const std::uint32_t i = static_cast<std::uint32_t>(level * 97);
    const std::vector<double> to = AcrossBoundaryAt(t.cube, &c.xyz[3 * i], level);
    const UpdateStats s = MoveAndCheck(GetParam(), *engine, c, { i }, to);
    EXPECT_EQ(s.changedLeaf, 1u);
    EXPECT_NE(s.path, UpdateStats::Path::NewCube);
  }
}

TEST_P(OctreeUpdate, LeavingTheCubeRebuildsAroundNewBounds)
{
  Cloud c = UniformCloud(4000, 37);
  BuildOptions options;
  options.depth = 6;
  engine->Build(c.View(), options);
  const UpdateStats s = MoveAndCheck(GetParam(), *engine, c, { 5 }, { 3.0, 0.0, 0.0 });
  EXPECT_EQ(s.path, UpdateStats::Path::NewCube);
  // The new cube is the one a build from scratch fits to the new bounds.
  HostOctree updated, fresh;
  engine->CopyToHost(updated);
  auto other = CreateEngine(GetParam());
  other->Build(c.View(), options);
  other->CopyToHost(fresh);
  EXPECT_EQ(updated.cube.size, fresh.cube.size);
  EXPECT_EQ(updated.key, fresh.key);
  EXPECT_EQ(updated.pointCount, fresh.pointCount);
}

TEST_P(OctreeUpdate, BadUpdatesAreErrorsAndChangeNothing)
{
  Cloud c = UniformCloud(1000, 38);
  engine->Build(c.View(), BuildOptions());
  HostOctree before, after;
  engine->CopyToHost(before);

  const std::uint32_t idx[2] = { 3, 999 };
  const double to[6] = { 0, 0, 0, NAN, 0, 0 };
  PositionsView moved;
  moved.count = 2;
  moved.xyzDouble = to;
  moved.indices = idx;
  try
  {
    engine->Update(moved);
    FAIL() << "no error for a NaN position";
  }
  catch (const Error& e)
  {
    EXPECT_NE(std::string(e.what()).find("point 999 has a non-finite coordinate"), std::string::npos) << e.what();
  }
  const std::uint32_t outOfRange[1] = { 1000 };
  moved.count = 1;
  moved.indices = outOfRange;
  try
  {
    engine->Update(moved);
    FAIL() << "no error for an index out of range";
  }
  catch (const Error& e)
  {
    EXPECT_NE(std::string(e.what()).find("names point 1000 of an octree of 1000 points"), std::string::npos)
      << e.what();
  }
  const std::uint32_t twice[2] = { 7, 7 };
  const double two[6] = { 0, 0, 0, 0.1, 0, 0 };
  moved.count = 2;
  moved.indices = twice;
  moved.xyzDouble = two;
  try
  {
    engine->Update(moved);
    FAIL() << "no error for a point listed twice";
  }
  catch (const Error& e)
  {
    EXPECT_STREQ(e.what(), "octoray: update index 1 names point 7 a second time");
  }
  engine->CopyToHost(after);
  EXPECT_EQ(after.key, before.key);
  EXPECT_EQ(after.pointCount, before.pointCount);
}

INSTANTIATE_TEST_SUITE_P(Backends, OctreeUpdate, ::testing::Values(Backend::CPU, Backend::CUDA), BackendName);
