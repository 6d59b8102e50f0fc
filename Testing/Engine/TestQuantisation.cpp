// The octree's quantisation error as the report measures it
// (octoray/Quantisation.h): on the engine's own tree, the
// distance from each point to the centre of its leaf must equal a
// brute-force recomputation from the point, the root cube and the depth
// alone, and never exceed half the leaf voxel's diagonal.
#include "TestSupport.h"

#include <octoray/Quantisation.h>

#include <cmath>

namespace octoray::test
{
namespace
{
// Brute force, independent of Morton keys and of the tree: the leaf cell is
// floor((p - origin) / side) per axis with side = cube / 2^depth.
QuantisationError BruteForce(const Cloud& c, const RootCube& cube, int depth)
{
  QuantisationError q;
  q.leafSide = cube.size / std::pow(2.0, depth);
  q.bound = std::sqrt(3.0) / 2.0 * q.leafSide;
  double sum = 0;
  for (std::size_t i = 0; i < c.Size(); ++i)
  {
    double d2 = 0;
    for (int a = 0; a < 3; ++a)
    {
      const double cell = std::floor((c.xyz[3 * i + a] - cube.origin[a]) / q.leafSide);
      const double centre = cube.origin[a] + (cell + 0.5) * q.leafSide;
      d2 += (c.xyz[3 * i + a] - centre) * (c.xyz[3 * i + a] - centre);
    }
    q.max = std::max(q.max, std::sqrt(d2));
    sum += std::sqrt(d2);
  }
  q.mean = sum / c.Size();
  q.points = c.Size();
  return q;
}

class Quantisation : public BackendTest
{
};

TEST_P(Quantisation, EqualsBruteForceAndStaysWithinHalfTheLeafDiagonal)
{
  const Cloud clouds[] = { UniformCloud(4000, 11), GaussianClusters(4000, 12), UniformCloud(2000, 13, 1e7, 1e7 + 50) };
  for (const Cloud& cloud : clouds)
  {
    for (const int depth : { 1, 2, 5, 8, 13, 21 })
    {
      SCOPED_TRACE("depth " + std::to_string(depth));
      BuildOptions options;
      options.depth = depth;
      engine->Build(cloud.View(), options);
      HostOctree tree;
      engine->CopyToHost(tree);
      ASSERT_EQ(tree.depth, depth);
      const QuantisationError q = MeasureQuantisation(tree, cloud.View());
      const QuantisationError ref = BruteForce(cloud, tree.cube, depth);
      EXPECT_DOUBLE_EQ(q.bound, ref.bound);
      EXPECT_NEAR(q.max, ref.max, 1e-12 * tree.cube.size);
      EXPECT_NEAR(q.mean, ref.mean, 1e-12 * tree.cube.size);
      EXPECT_LE(q.max, q.bound * (1 + 1e-12));
      EXPECT_GT(q.max, 0.0);
      EXPECT_LE(q.mean, q.max);
    }
  }
}

// Points exactly at voxel corners sit half a diagonal from their centres,
// points at the centres sit on them: the measurement hits both extremes.
TEST_P(Quantisation, CornersReachTheBoundAndCentresAreExact)
{
  const int depth = 3;
  BuildOptions options;
  options.depth = depth;
  options.fixedCube = true; // origin 0, side 1: voxels of side 1/8
  std::mt19937_64 rng(5);
  Cloud corners, centres;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; j += 3)
      for (int k = 0; k < 8; k += 2)
      {
        corners.Add(i / 8.0, j / 8.0, k / 8.0, rng);
        centres.Add((i + 0.5) / 8.0, (j + 0.5) / 8.0, (k + 0.5) / 8.0, rng);
      }
  engine->Build(corners.View(), options);
  HostOctree tree;
  engine->CopyToHost(tree);
  const QuantisationError atCorners = MeasureQuantisation(tree, corners.View());
  EXPECT_DOUBLE_EQ(atCorners.max, std::sqrt(3.0) / 16.0);
  EXPECT_DOUBLE_EQ(atCorners.mean, std::sqrt(3.0) / 16.0);
  EXPECT_DOUBLE_EQ(atCorners.bound, std::sqrt(3.0) / 16.0);

  engine->Build(centres.View(), options);
  engine->CopyToHost(tree);
  const QuantisationError atCentres = MeasureQuantisation(tree, centres.View());
  EXPECT_EQ(atCentres.max, 0.0);
}

// The walk goes through the engine's child masks: a point in a part of the
// cube the tree has no node for is reported, not measured.
TEST_P(Quantisation, APointOutsideTheTreeIsAnError)
{
  BuildOptions options;
  options.depth = 4;
  options.fixedCube = true;
  const Cloud corner = UniformCloud(100, 21, 0.0, 0.25);
  engine->Build(corner.View(), options);
  HostOctree tree;
  engine->CopyToHost(tree);
  std::mt19937_64 rng(1);
  Cloud stranger;
  stranger.Add(0.9, 0.9, 0.9, rng);
  EXPECT_THROW(MeasureQuantisation(tree, stranger.View()), std::runtime_error);
  EXPECT_NO_THROW(MeasureQuantisation(tree, corner.View()));
}

INSTANTIATE_TEST_SUITE_P(Backends, Quantisation, ::testing::Values(Backend::CPU, Backend::CUDA), BackendName);
}
}
