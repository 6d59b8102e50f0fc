// The octree against the brute-force reference, on every backend.
#include "TestRenderSupport.h"
#include "TestSupport.h"

#include <octoray/Frame.h>

using namespace octoray;
using namespace octoray::test;

using OctreeBuild = BackendTest;

TEST_P(OctreeBuild, UniformRandom)
{
  BuildAndCompare(*engine, UniformCloud(20000, 11), 6);
  const Cloud c = UniformCloud(20000, 12);
  BuildAndCompare(*engine, c, 0);
  HostOctree t;
  engine->CopyToHost(t);
  ExpectDepthRule(t, c);
}

// Levels of many children take a select and a loop each, the small ones
// near the root one pass together (Device::ReduceSmallLevels): a level
// with more children than a small level has, on either backend, and every
// level above it.
TEST_P(OctreeBuild, LevelsOfManyAndOfFewChildren)
{
  const Cloud c = UniformCloud(50000, 15);
  BuildAndCompare(*engine, c, 8);
  HostOctree t;
  engine->CopyToHost(t);
  // More leaves than either backend's kSmallLevelItems (4096 and 16384).
  EXPECT_GT(t.levelBegin[9] - t.levelBegin[8], 16384u);
}

TEST_P(OctreeBuild, GaussianClusters)
{
  BuildAndCompare(*engine, GaussianClusters(20000, 13), 9);
  const Cloud c = GaussianClusters(20000, 14);
  BuildAndCompare(*engine, c, 0);
  HostOctree t;
  engine->CopyToHost(t);
  ExpectDepthRule(t, c);
}

// The automatic depth sorts 32-bit keys down to level 10 first, then keys
// of 13 levels where those do not settle the depth rule and the cloud's
// level-10 cells hold few points, then full-depth keys where neither does
// (DepthChoice.h's NextSortDepth): clouds whose rule lands on level 10,
// between it and 13, on 13 and past it (8 points a cluster: every sort),
// past it with 200 points a cluster (full depth after level 10), and on
// coincident points, which no level separates further, against the
// brute-force octree and the rule worked out from it.
TEST_P(OctreeBuild, AutomaticDepthSettledByEachSort)
{
  std::mt19937_64 rng(47);
  const Cloud tenth = TightClusters(300, 2e-3, 48);
  const Cloud twelfth = TightClusters(300, 5e-4, 49);
  const Cloud thirteenth = TightClusters(300, 2.5e-4, 50);
  const Cloud sixteenth = TightClusters(300, 2e-5, 51);
  const Cloud deep = TightClusters(300, 1e-5, 47);
  Cloud dense;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 12; ++k)
  {
    const double x = u(rng), y = u(rng), z = u(rng);
    for (int i = 0; i < 200; ++i)
    {
      dense.Add(x + 1e-5 * u(rng), y + 1e-5 * u(rng), z + 1e-5 * u(rng), rng);
    }
  }
  Cloud coincident;
  for (int i = 0; i < 600; ++i)
  {
    const double corner = i % 3 == 0 ? 0.0 : (i % 3 == 1 ? 1.0 : 0.25);
    coincident.Add(corner, corner, 1.0 - corner, rng);
  }
  const std::pair<const Cloud*, int> cases[] = { { &tenth, 10 }, { &twelfth, 12 }, { &thirteenth, 13 },
    { &sixteenth, 16 }, { &deep, 17 }, { &dense, 19 }, { &coincident, 2 } };
  for (const auto& [c, depth] : cases)
  {
    SCOPED_TRACE("expected depth " + std::to_string(depth));
    BuildAndCompare(*engine, *c, 0);
    HostOctree t;
    engine->CopyToHost(t);
    EXPECT_EQ(t.depth, depth);
    ExpectDepthRule(t, *c);
  }
}

// The sort moves each point's record with its key where the record is one
// or two words and the leaf keys fit 32 bits, and the leaf loop reads the
// records through the points' indices otherwise (SortedKeys,
// OctreeKernels.h). Where CUDA sorts the positions while the attributes are
// still on their way (a staged copy of more than 1 MB: CudaUpload.h), it
// sorts the indices, through which the leaf loop reads records of every
// width after the copy. Every record width, at depths that sort
// 32-bit and 64-bit keys and at the automatic depth, with and without kept
// points, against the brute-force octree; then an update of every point
// reads the kept records again.
TEST_P(OctreeBuild, RecordsOfEveryWidth)
{
  const Cloud every = GaussianClusters(4000, 23);
  // The cloud with the attributes not named cleared.
  auto only = [](Cloud c, bool colours, bool scalars, bool reflectivity, bool normals, bool refraction) {
    for (auto [keep, values] : { std::pair{ scalars, &c.scalar }, std::pair{ reflectivity, &c.reflectivity },
           std::pair{ normals, &c.normal }, std::pair{ refraction, &c.refraction } })
    {
      if (!keep)
      {
        values->clear();
      }
    }
    if (!colours)
    {
      c.rgb.clear();
    }
    return c;
  };
  const std::pair<const char*, Cloud> clouds[] = {
    { "no attributes (0 words)", only(every, false, false, false, false, false) },
    { "colours (1 word)", only(every, true, false, false, false, false) },
    { "colours and reflectivity (2 words)", only(every, true, false, true, false, false) },
    // Every attribute of the lean loops (kLeanAttributes); the next cloud has one outside them.
    { "colours, scalars and reflectivity (3 words)", only(every, true, true, true, false, false) },
    { "colours, scalars and normals (3 words)", only(every, true, true, false, true, false) },
    { "every attribute (5 words)", every },
    // Its automatic depth lies beyond the sort of 13 levels: the full-depth
    // sort reads the records again.
    { "deep clusters, colours and reflectivity (2 words)",
      only(TightClusters(300, 1e-5, 47), true, false, true, false, false) },
    // 1.6 and 1.9 MB of input: staged on CUDA, the positions first.
    { "staged, colours (1 word)", only(GaussianClusters(60000, 24), true, false, false, false, false) },
    { "staged, colours and reflectivity (2 words)",
      only(GaussianClusters(60000, 25), true, false, true, false, false) },
    { "staged, colours and scalars (2 words)", only(GaussianClusters(60000, 26), true, true, false, false, false) },
    { "staged, every attribute (5 words)", GaussianClusters(60000, 27) } };
  for (const auto& [label, cloud] : clouds)
  {
    for (int depth : { 7, 0, 14 })
    {
      for (bool keep : { false, true })
      {
        SCOPED_TRACE(std::string(label) + ", depth " + std::to_string(depth) + (keep ? ", points kept" : ""));
        BuildOptions options;
        options.depth = depth;
        options.keepPoints = keep;
        engine->Build(cloud.View(), options);
        HostOctree t;
        engine->CopyToHost(t);
        ExpectMatchesReference(t, cloud);
        if (!keep)
        {
          continue;
        }
        Cloud moved = cloud;
        for (double& v : moved.xyz)
        {
          v *= 0.5; // every point stays in the cube
        }
        PositionsView all;
        all.count = moved.Size();
        all.xyzDouble = moved.xyz.data();
        engine->Update(all);
        engine->CopyToHost(t);
        ExpectMatchesReference(t, moved);
      }
    }
  }
}

// One point, coincident points, flat and collinear data and data far from
// the origin are rows of the stability table (TestStability.cpp).
TEST_P(OctreeBuild, TwoOppositeCorners)
{
  std::mt19937_64 rng(17);
  Cloud two;
  two.Add(-1, -1, -1, rng);
  two.Add(1, 1, 1, rng);
  for (int depth = 1; depth <= 21; depth += 4)
  {
    BuildAndCompare(*engine, two, depth);
  }
  // The corners fall in octants 0 and 7 of the root.
  HostOctree t;
  engine->CopyToHost(t);
  EXPECT_EQ(ChildMaskOf(t, 0), 0x81u);
  BuildAndCompare(*engine, two, 0);
  engine->CopyToHost(t);
  EXPECT_EQ(t.depth, 1);
}

// Reflectivity weighs a mirror ray, 0 to 1 (Attributes.h's UnitInput):
// values beyond are clamped before they are averaged, and each is kept in
// Scalar16's unit steps; NaN stays NaN.
TEST_P(OctreeBuild, ReflectivityClampedAndKeptInUnitSteps)
{
  std::mt19937_64 rng(29);
  Cloud c;
  const double corners[4][3] = { { -1, -1, -1 }, { 1, -1, -1 }, { -1, 1, -1 }, { 1, 1, 1 } };
  for (const auto& p : corners)
  {
    c.Add(p[0], p[1], p[2], rng);
  }
  c.reflectivity = { 1.5f, -0.5f, 0.3f, NAN };
  BuildOptions options;
  options.depth = 1;
  engine->Build(c.View(), options);
  HostOctree t;
  engine->CopyToHost(t);
  ASSERT_EQ(t.levelBegin[2] - t.levelBegin[1], 4u);
  // The leaves by octant (x, y and z from bit 0 up): 0, 1, 2 and 7.
  EXPECT_EQ(t.reflectivity[t.levelBegin[1]], 1.0f);
  EXPECT_EQ(t.reflectivity[t.levelBegin[1] + 1], 0.0f);
  EXPECT_EQ(t.reflectivity[t.levelBegin[1] + 2], std::floor(0.3f * kScalarSteps + 0.5f) / kScalarSteps);
  EXPECT_NE(t.reflectivity[t.levelBegin[1] + 2], 0.3f) << "0.3 lies between two steps";
  EXPECT_TRUE(std::isnan(t.reflectivity[t.levelBegin[1] + 3]));
}

TEST_P(OctreeBuild, EveryDepth)
{
  const Cloud c = GaussianClusters(3000, 19);
  for (int depth = 1; depth <= 21; ++depth)
  {
    SCOPED_TRACE("depth " + std::to_string(depth));
    BuildAndCompare(*engine, c, depth);
  }
}

TEST_P(OctreeBuild, FloatPositionsAndFloatRgbaColours)
{
  const Cloud c = UniformCloud(5000, 20);
  std::vector<float> xyz(c.xyz.begin(), c.xyz.end());
  std::vector<float> rgba;
  for (std::size_t i = 0; i < c.Size(); ++i)
  {
    rgba.insert(rgba.end(), { c.rgb[3 * i] / 255.0f, c.rgb[3 * i + 1] / 255.0f, c.rgb[3 * i + 2] / 255.0f, 0.5f });
  }
  PointCloudView v;
  v.count = c.Size();
  v.xyzFloat = xyz.data();
  v.colorFloat = rgba.data();
  v.colorComponents = 4;
  BuildOptions options;
  options.depth = 7;
  engine->Build(v, options);
  HostOctree t;
  engine->CopyToHost(t);
  EXPECT_EQ(t.attributes, static_cast<unsigned>(kHasColor));
  EXPECT_TRUE(t.scalar.empty());
  EXPECT_TRUE(t.normal.empty());
  EXPECT_NEAR(t.color[0].a, 0.5f, 1e-6f);
  // Same keys as from the double positions they were rounded from, except
  // where rounding crossed a cell face: compare counts per level loosely.
  Cloud rounded = c;
  for (std::size_t i = 0; i < rounded.xyz.size(); ++i)
  {
    rounded.xyz[i] = xyz[i];
  }
  const auto levels = ReferenceLevels(rounded, t.cube, 7);
  EXPECT_EQ(t.NodeCount(), [&] {
    std::size_t s = 0;
    for (const auto& l : levels)
    {
      s += l.size();
    }
    return s;
  }());
}

TEST_P(OctreeBuild, EmptyAndNonFiniteInputAreErrors)
{
  PointCloudView empty;
  std::vector<double> none;
  empty.xyzDouble = none.data();
  try
  {
    engine->Build(empty, BuildOptions());
    FAIL() << "no error for empty input";
  }
  catch (const Error& e)
  {
    EXPECT_STREQ(e.what(), "octoray: cannot build an octree from 0 points");
  }

  Cloud c = UniformCloud(100, 21);
  engine->Build(c.View(), BuildOptions());
  HostOctree before;
  engine->CopyToHost(before);

  Cloud bad = c;
  bad.xyz[3 * 42 + 1] = std::nan("");
  bad.xyz[3 * 77 + 0] = INFINITY;
  try
  {
    engine->Build(bad.View(), BuildOptions());
    FAIL() << "no error for NaN input";
  }
  catch (const Error& e)
  {
    EXPECT_NE(std::string(e.what()).find("point 42 has a non-finite coordinate"), std::string::npos) << e.what();
  }
  // The previous octree is untouched.
  HostOctree after;
  engine->CopyToHost(after);
  EXPECT_EQ(after.key, before.key);
  EXPECT_EQ(after.pointCount, before.pointCount);

  BuildOptions deep;
  deep.depth = 22;
  EXPECT_THROW(engine->Build(c.View(), deep), Error);
}

// 1.5 M points of double positions, 36 MB: the CUDA backend copies them
// through its pinned staging, in pieces of 0.5 to 4 MB that it reduces to
// bounds as they land (Device::StageReduced). The cube must be the one
// fitted to every point, wherever an extreme lies: in the first or last
// point, or in points next to 4 MB boundaries, where a piece of a plain
// 4 MB would have cut them; and an error must name the first non-finite
// point however far into the copy.
TEST_P(OctreeBuild, BoundsOfAnUploadInPieces)
{
  const std::size_t n = 1500000;
  std::mt19937_64 rng(24);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> xyz(3 * n);
  for (double& x : xyz)
  {
    x = u(rng);
  }
  const std::size_t split = (std::size_t(4) << 20) / sizeof(double) / 3; // its z past 4 MB
  const std::pair<std::size_t, double> extremes[] = { { 3 * 0 + 1, -3.5 }, { 3 * split + 2, 4.25 },
    { 3 * (2 * split) + 0, 6.0 }, { 3 * (5 * split + 1) + 1, 2.5 }, { 3 * (n - 1) + 2, -5.0 },
    { 3 * (n / 2) + 0, -1.75 } };
  for (const auto& e : extremes)
  {
    xyz[e.first] = e.second;
  }
  double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
  for (std::size_t e = 0; e < xyz.size(); ++e)
  {
    lo[e % 3] = std::min(lo[e % 3], xyz[e]);
    hi[e % 3] = std::max(hi[e % 3], xyz[e]);
  }
  PointCloudView v;
  v.count = n;
  v.xyzDouble = xyz.data();
  BuildOptions options;
  options.depth = 2;
  options.keepPoints = false;
  const RootCube expected = RootCube::FromBounds(lo, hi);
  const BuildStats stats = engine->Build(v, options);
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_EQ(stats.cube.origin[a], expected.origin[a]) << "axis " << a;
  }
  EXPECT_EQ(stats.cube.size, expected.size);
  EXPECT_EQ(stats.points, n);

  xyz[3 * (7 * split) + 2] = std::nan("");
  xyz[3 * (n - 2) + 0] = -INFINITY;
  try
  {
    engine->Build(v, options);
    FAIL() << "no error for NaN input";
  }
  catch (const Error& e)
  {
    const std::string first = "point " + std::to_string(7 * split) + " has a non-finite coordinate";
    EXPECT_NE(std::string(e.what()).find(first), std::string::npos) << e.what();
  }
}

TEST_P(OctreeBuild, ReportsMemoryLinearInNodes)
{
  const Cloud c = UniformCloud(20000, 22);
  BuildOptions options;
  options.depth = 10;
  const BuildStats stats = engine->Build(c.View(), options);
  const MemoryReport m = engine->Memory();
  EXPECT_EQ(stats.bytes, m.Total());
  // At depth 10 every key fits its low word (Attributes.h): 4 bytes a node.
  EXPECT_GE(m.BytesOf("node keys"), stats.nodes * sizeof(std::uint32_t));
  EXPECT_LE(m.BytesOf("node keys"), 2 * stats.nodes * sizeof(std::uint32_t));
  EXPECT_EQ(m.BytesOf("node keys' high words"), 0u);
  // Far below a dense skeleton of depth 10: (8^11 - 1) / 7 pointers.
  EXPECT_LT(m.Total(), ((1ull << 33) - 1) / 7 * 8 / 100);

  // Deeper, each key has its high word too.
  options.depth = 12;
  const BuildStats deep = engine->Build(c.View(), options);
  const MemoryReport d = engine->Memory();
  for (const char* label : { "node keys", "node keys' high words" })
  {
    SCOPED_TRACE(label);
    EXPECT_GE(d.BytesOf(label), deep.nodes * sizeof(std::uint32_t));
    EXPECT_LE(d.BytesOf(label), 2 * deep.nodes * sizeof(std::uint32_t));
  }
}

// With a fixed root cube, a point outside it is refused before anything is
// replaced, by name and with its coordinates as given, on every backend.
TEST_P(OctreeBuild, APointOutsideAFixedCubeIsNamed)
{
  Cloud c = UniformCloud(1000, 23, 0.1, 0.9);
  BuildOptions options;
  options.depth = 5;
  options.fixedCube = true;
  options.cube.size = 1.0;
  engine->Build(c.View(), options);
  HostOctree before;
  engine->CopyToHost(before);

  c.xyz[3 * 700] = 1.5;
  c.xyz[3 * 700 + 1] = 0.25;
  c.xyz[3 * 700 + 2] = -0.5;
  c.xyz[3 * 900 + 2] = 2.0;
  try
  {
    engine->Build(c.View(), options);
    FAIL() << "no error for a point outside the fixed cube";
  }
  catch (const Error& e)
  {
    EXPECT_STREQ(e.what(), "octoray: point 700 (1.5, 0.25, -0.5) lies outside the root cube");
  }
  HostOctree after;
  engine->CopyToHost(after);
  ExpectSameOctree(after, before, true);
}

// The memory report's labels, which the benchmark report reads: one line
// per array the engine holds, in this order, and last the memory its
// allocator keeps for reuse where it keeps some (CUDA's pool).
TEST_P(OctreeBuild, ReportsMemoryUnderItsLabels)
{
  const Cloud c = UniformCloud(5000, 24);
  BuildOptions options;
  options.depth = 6;
  engine->Build(c.View(), options);
  std::vector<std::string> labels;
  for (const auto& a : engine->Memory().arrays)
  {
    labels.push_back(a.first);
  }
  if (!labels.empty() && labels.back() == MemoryReport::kAllocatorCache)
  {
    EXPECT_EQ(GetParam(), Backend::CUDA);
    labels.pop_back();
  }
  const std::vector<std::string> expected = { "node keys", "node child masks", "node first children",
    "node point counts", "node 8-bit colours", "node scalars", "node reflectivities", "node refraction indices",
    "node normals", "point positions", "point 8-bit colours", "point scalars", "point reflectivities",
    "point refraction indices", "point normals", "sort buffers" };
  EXPECT_EQ(labels, expected);
}

// Without BuildOptions::keepPoints the engine holds the node arrays alone:
// the same octree and the same picture as with the points kept, less
// memory, and an update that says why it cannot run.
TEST_P(OctreeBuild, WithoutItsPointsHoldsOnlyTheNodes)
{
  const Cloud c = GaussianClusters(20000, 25);
  BuildOptions options;
  options.depth = 8;
  engine->Build(c.View(), options);
  const std::size_t keptBytes = engine->Memory().Total();
  HostOctree kept;
  engine->CopyToHost(kept);
  const double eye[3] = { 30, -40, 25 }, target[3] = { 2, 1, 1 };
  RenderSettings s = Settings(ViewProjection(eye, target, kZUp, 40, 4.0 / 3.0, 5, 150, false, 12), 64, 48);
  const Image keptImage = RenderChecked(*engine, s);

  options.keepPoints = false;
  const BuildStats stats = engine->Build(c.View(), options);
  HostOctree lean;
  engine->CopyToHost(lean);
  ExpectSameOctree(lean, kept, true);
  EXPECT_TRUE(BitIdentical(RenderChecked(*engine, s), keptImage));
  // Besides the nodes, only what CUDA's pool cannot give back: the free
  // part of the blocks that the nodes occupy.
  const MemoryReport memory = engine->Memory();
  for (const auto& a : memory.arrays)
  {
    EXPECT_TRUE(MemoryReport::IsNodeArray(a.first) || a.first == MemoryReport::kAllocatorCache)
      << a.first << " kept without keepPoints";
  }
  const std::size_t nodeBytes = memory.NodeBytes();
  EXPECT_EQ(stats.bytes, nodeBytes + memory.BytesOf(MemoryReport::kAllocatorCache));
  EXPECT_LT(3 * nodeBytes, 2 * keptBytes) << "node arrays " << nodeBytes << " B of " << keptBytes << " B";
  EXPECT_EQ(engine->PointCount(), c.Size());

  const std::uint32_t first[1] = { 0 };
  const double to[3] = { 0, 0, 0 };
  PositionsView moved;
  moved.count = 1;
  moved.xyzDouble = to;
  moved.indices = first;
  try
  {
    engine->Update(moved);
    FAIL() << "no error for an update without the points";
  }
  catch (const Error& e)
  {
    EXPECT_STREQ(e.what(), "octoray: update of an octree built without its points (BuildOptions::keepPoints off); "
                           "build again from the new positions");
  }
  // A build that keeps them makes the octree updatable again.
  options.keepPoints = true;
  engine->Build(c.View(), options);
  EXPECT_EQ(engine->Update(moved).moved, 1u);
}

INSTANTIATE_TEST_SUITE_P(Backends, OctreeBuild, ::testing::Values(Backend::CPU, Backend::CUDA), BackendName);

// Suites that only the CUDA backend has: skipped, saying why, without a GPU.
using CudaFaults = CudaOnlyTest;
using OctreeCUDA = CudaOnlyTest;

// Out of device memory: a clear error naming what did not fit, the previous
// octree intact and still drawable, and a later build within budget works.
TEST_F(CudaFaults, OutOfMemoryKeepsThePreviousOctree)
{
  auto engine = CreateEngine(Backend::CUDA);
  const Cloud small = UniformCloud(1000, 51);
  BuildOptions options;
  options.depth = 6;
  engine->Build(small.View(), options);
  HostOctree before;
  engine->CopyToHost(before);
  const std::size_t held = engine->Memory().ArrayBytes();

  engine->SetMemoryBudget(held + 200000); // far too little for 100 k points
  const Cloud big = UniformCloud(100000, 52);
  try
  {
    engine->Build(big.View(), options);
    FAIL() << "no error past the memory budget";
  }
  catch (const Error& e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("octoray: out of memory for "), std::string::npos) << message;
    EXPECT_NE(message.find("within the engine's budget"), std::string::npos) << message;
  }
  HostOctree after;
  engine->CopyToHost(after);
  EXPECT_EQ(after.key, before.key);
  EXPECT_EQ(after.pointCount, before.pointCount);

  engine->SetMemoryBudget(~std::size_t(0));
  EXPECT_NO_THROW(engine->Build(big.View(), options));
  engine->CopyToHost(after);
  ExpectMatchesReference(after, big);
}

// The normals a render estimates for a cloud without them (the render's
// own allocation site, RenderSettings::estimateNormals): out of memory there
// is that frame's error, naming them; the octree stays, and the next frame
// with room makes them and draws what a fresh engine draws.
TEST_F(CudaFaults, OutOfMemoryForEstimatedNormalsKeepsTheOctree)
{
  const Cloud cloud = UniformCloud(20000, 66).WithExactMeans(); // no normals
  BuildOptions options;
  options.depth = 7;
  RenderSettings s;
  s.width = 64;
  s.height = 48;
  const double vp[16] = { 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, -0.5, 0, 0, 0, 0, 1 };
  Invert4x4(vp, s.inverseViewProjection);
  s.shade = ShadeMode::Phong;
  s.estimateNormals = true;
  RenderSettings occupancy = s;
  occupancy.estimateNormals = false;
  auto engine = CreateEngine(Backend::CUDA);
  engine->Build(cloud.View(), options);
  Image image;
  engine->Render(occupancy, image); // the picture's own buffers
  const std::size_t held = engine->Memory().ArrayBytes();
  engine->SetMemoryBudget(held + 1024); // far less than 4 bytes a node
  try
  {
    engine->Render(s, image);
    FAIL() << "no error past the memory budget";
  }
  catch (const Error& e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("octoray: out of memory for node normals (estimated)"), std::string::npos) << message;
  }
  EXPECT_LE(engine->Memory().ArrayBytes(), held + 1024);
  EXPECT_EQ(engine->PointCount(), cloud.Size());

  engine->SetMemoryBudget(~std::size_t(0));
  Image estimated, fresh;
  engine->Render(s, estimated);
  auto other = CreateEngine(Backend::CUDA);
  other->Build(cloud.View(), options);
  other->Render(s, fresh);
  EXPECT_EQ(estimated.rgba, fresh.rgba);
}

// Out-of-memory at every allocation site: budgets swept from nothing up to
// what a build, an update and a render need. At each step the call either
// succeeds or fails with the documented error, gives back what it took (the
// engine holds no more than before) and leaves the previous octree intact.
TEST_F(CudaFaults, OutOfMemoryAtEveryAllocationSite)
{
  const Cloud first = UniformCloud(2000, 53);
  const Cloud second = GaussianClusters(30000, 54);
  BuildOptions options;
  options.depth = 7;
  int failures = 0, successes = 0;
  for (std::size_t budget = 0;; budget += 48 * 1024)
  {
    auto engine = CreateEngine(Backend::CUDA);
    engine->Build(first.View(), options);
    HostOctree before;
    engine->CopyToHost(before);
    const std::size_t held = engine->Memory().ArrayBytes();
    engine->SetMemoryBudget(held + budget);
    bool ok = true;
    try
    {
      engine->Build(second.View(), options);
      // An update that changes the topology (re-sort path) and a render.
      std::vector<std::uint32_t> idx(300);
      std::vector<double> to(900);
      for (std::uint32_t k = 0; k < 300; ++k)
      {
        idx[k] = k * 97;
        to[3 * k] = second.xyz[3 * idx[k]] * 0.5, to[3 * k + 1] = second.xyz[3 * idx[k] + 1] * 0.5,
                 to[3 * k + 2] = second.xyz[3 * idx[k] + 2] * 0.5;
      }
      PositionsView moved;
      moved.count = idx.size();
      moved.indices = idx.data();
      moved.xyzDouble = to.data();
      engine->Update(moved);
      RenderSettings s;
      s.width = 64;
      s.height = 48;
      const double vp[16] = { 0.1, 0, 0, 0, 0, 0.1, 0, 0, 0, 0, -0.1, 0, 0, 0, 0, 1 };
      Invert4x4(vp, s.inverseViewProjection);
      Image image;
      engine->Render(s, image);
    }
    catch (const Error& e)
    {
      ok = false;
      ++failures;
      const std::string message = e.what();
      ASSERT_NE(message.find("octoray: out of memory for "), std::string::npos) << message;
      if (engine->PointCount() == first.Size())
      {
        // The build failed: the first octree is untouched and nothing leaked.
        HostOctree after;
        engine->CopyToHost(after);
        EXPECT_EQ(after.key, before.key) << "budget " << budget;
        EXPECT_EQ(after.pointCount, before.pointCount) << "budget " << budget;
        EXPECT_LE(engine->Memory().ArrayBytes(), held + budget) << "budget " << budget;
      }
    }
    if (ok)
    {
      ++successes;
      break;
    }
    ASSERT_LT(budget, 256u << 20) << "no budget was enough";
  }
  EXPECT_GT(failures, 5); // several allocation sites were hit on the way
  EXPECT_EQ(successes, 1);
}

// The CUDA octree equals the CPU one bit for bit, after a build (fixed and
// automatic depth) and after each update path: both run the same steps in
// the same order (OctreeDriver.h), and CUDA rounds like the CPU.
TEST_F(OctreeCUDA, EqualsTheCpuOctreeBitForBit)
{
  auto cpu = CreateEngine(Backend::CPU);
  auto gpu = CreateEngine(Backend::CUDA);
  auto expectSame = [&](const char* what) {
    SCOPED_TRACE(what);
    HostOctree a, b;
    cpu->CopyToHost(a);
    gpu->CopyToHost(b);
    ExpectSameOctree(b, a, true);
  };
  // 8-bit colours, scalars and normals: their means rounded to the same bits.
  const Cloud rounded = GaussianClusters(30000, 25);
  cpu->Build(rounded.View(), BuildOptions{});
  gpu->Build(rounded.View(), BuildOptions{});
  expectSame("build with 8-bit colours, scalars and normals");
  // Every point twice (with other attributes), so that moving a copy onto
  // another point's place empties no leaf and creates none: the in-place
  // path, which octrees with rounded means do not take (Attributes.h).
  Cloud c = GaussianClusters(30000, 25).WithExactMeans();
  const std::size_t n = c.Size();
  Cloud twins = GaussianClusters(n, 26).WithExactMeans();
  twins.xyz = c.xyz;
  c.Append(twins);
  for (int depth : { 0, 9 })
  {
    BuildOptions options;
    options.depth = depth;
    cpu->Build(c.View(), options);
    gpu->Build(c.View(), options);
    expectSame(depth ? "build at depth 9" : "build at an automatic depth");
  }

  auto update = [&](const std::vector<std::uint32_t>& indices, const std::vector<double>& to,
                  UpdateStats::Path path, const char* what) {
    PositionsView moved;
    moved.count = indices.size();
    moved.indices = indices.data();
    moved.xyzDouble = to.data();
    EXPECT_EQ(cpu->Update(moved).path, path) << what;
    EXPECT_EQ(gpu->Update(moved).path, path) << what;
    expectSame(what);
  };
  std::vector<std::uint32_t> indices;
  std::vector<double> to;
  for (std::uint32_t k = 0; k < 500; ++k)
  {
    indices.push_back(static_cast<std::uint32_t>(n) + k * 37);
    const std::size_t target = (k * 53 + 11) % n;
    to.insert(to.end(), c.xyz.begin() + 3 * target, c.xyz.begin() + 3 * target + 3);
  }
  update(indices, to, UpdateStats::Path::InPlace, "in-place update");
  for (double& v : to)
  {
    v *= 0.5;
  }
  update(indices, to, UpdateStats::Path::Relevel, "re-sorting update");
  update({ 3 }, { 100.0, -100.0, 3.0 }, UpdateStats::Path::NewCube, "update to a new cube");
}
