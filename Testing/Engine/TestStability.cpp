// Numerical stability: the extreme and stiff cases of the report's
// stability table (issue 7), one test per row, in the order, on
// both backends. Each picture is checked against an independent reference
// with a stated tolerance: the brute-force first hit over every leaf box in
// double precision (TestRenderSupport.h), the octree's brute-force
// reference (TestSupport.h), or geometry worked out here (Snell's law, the
// Phong formula, a box's outline). Each test records for the report what
// it compared ("check") and what it measured ("outcome") as properties of
// its <testcase> in the GoogleTest XML (Benchmarks/Report/section_stability.py
// reads them).
#include "TestRenderSupport.h"

#include <cstdarg>
#include <cstdio>

using namespace octoray;
using namespace octoray::test;

namespace
{
using Stability = BackendTest;

std::string Format(const char* format, ...)
{
  char buffer[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  return buffer;
}

// The row of the report: what was compared, with what tolerance, and what
// was measured. Recorded before the expectations, so a failing row still
// says what it saw.
void Record(const std::string& check, const std::string& outcome)
{
  ::testing::Test::RecordProperty("check", check);
  ::testing::Test::RecordProperty("outcome", outcome);
}

// A leaf's colour as the picture should show it: its own, or from a
// per-node table (a transfer function's lookup).
Rgba NodeRgb(const HostOctree& t, std::uint32_t node, const std::vector<Rgba>* colours = nullptr)
{
  return colours ? (*colours)[node] : NodeColour(t, node);
}

// Whether the ray meets any leaf box grown by `margin` on every side (a
// negative margin shrinks them), within the clipping range.
bool AnyLeafHit(const HostOctree& t, const WorldRay& r, double margin)
{
  for (std::uint32_t n = t.levelBegin[t.depth]; n < t.levelBegin[t.depth + 1]; ++n)
  {
    double lo[3], hi[3], t0 = 0, t1 = 1;
    NodeBox(t, n, t.depth, lo, hi);
    for (int a = 0; a < 3; ++a)
      lo[a] -= margin, hi[a] += margin;
    if (Slab(r, lo, hi, t0, t1))
      return true;
  }
  return false;
}

// Whether `pixel` has the colour of some leaf that the ray meets (box grown
// by `margin`) no farther than `tLimit`: a tie with the nearest leaf.
bool TiesWithSomeLeaf(const HostOctree& t, const WorldRay& r, double margin, double tLimit, const float* pixel,
  const std::vector<Rgba>* colours)
{
  for (std::uint32_t n = t.levelBegin[t.depth]; n < t.levelBegin[t.depth + 1]; ++n)
  {
    double lo[3], hi[3], t0 = 0, t1 = 1;
    NodeBox(t, n, t.depth, lo, hi);
    for (int a = 0; a < 3; ++a)
      lo[a] -= margin, hi[a] += margin;
    if (Slab(r, lo, hi, t0, t1) && t0 <= tLimit && SameRgb(pixel, NodeRgb(t, n, colours)))
      return true;
  }
  return false;
}

// A surface picture (first hits, flat shading) against the brute-force
// first hit of every pixel. A pixel may differ from it only where the
// reference itself is within `margin` (world units) of the other verdict:
// a ray that grazes a leaf's edge (covered or not), or meets two leaves at
// the same distance (either colour); those are counted as ties. Depth is
// compared where the colour is the nearest leaf's.
struct HitComparison
{
  int pixels = 0, hits = 0, ties = 0;
  int coverageDiffer = 0, colourDiffer = 0;
  double worstDepth = 0;

  std::string Summary() const
  {
    return Format("%d pixels (%d hits): %d coverage and %d colour mismatches, %d grazing ties, largest depth "
                  "error %.1e",
      pixels, hits, coverageDiffer, colourDiffer, ties, worstDepth);
  }
  void Add(const HitComparison& o)
  {
    pixels += o.pixels, hits += o.hits, ties += o.ties;
    coverageDiffer += o.coverageDiffer, colourDiffer += o.colourDiffer;
    worstDepth = std::max(worstDepth, o.worstDepth);
  }
};

HitComparison CompareWithFirstHits(const Image& image, const HostOctree& t, const Matrix& vp, double margin,
  const std::vector<Rgba>* colours = nullptr)
{
  HitComparison c;
  const int w = image.width, h = image.height;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      ++c.pixels;
      const BruteHit b = BruteForceFirstHit(t, vp, w, h, x, y);
      const WorldRay r = PixelRay(vp, w, h, x, y);
      const std::size_t i = Pixel(image, x, y);
      const float* pixel = &image.rgba[4 * i];
      const bool drawn = pixel[3] > 0;
      if (drawn != b.hit)
      {
        const bool tie = b.hit ? !AnyLeafHit(t, r, -margin) : AnyLeafHit(t, r, margin);
        c.ties += tie;
        c.coverageDiffer += !tie;
        EXPECT_TRUE(tie) << "pixel " << x << "," << y << (drawn ? " drawn, the reference misses"
                                                              : " empty, the reference hits");
        continue;
      }
      if (!b.hit)
        continue;
      ++c.hits;
      if (SameRgb(pixel, NodeRgb(t, b.node, colours)))
      {
        c.worstDepth = std::max(c.worstDepth, std::fabs(image.depth[i] - b.depth));
        continue;
      }
      const double tLimit = b.t + margin / Length(r.d);
      const bool tie = TiesWithSomeLeaf(t, r, margin, tLimit, pixel, colours);
      c.ties += tie;
      c.colourDiffer += !tie;
      EXPECT_TRUE(tie) << "pixel " << x << "," << y << " has the colour of no leaf near the first hit";
    }
  return c;
}

// Every comparison of the suite: exact agreement outside the ties, depth
// to 1e-5 (unless said otherwise), and enough hits, few of them ties, for
// the picture to have said something.
void ExpectAgreement(const HitComparison& c, int minimumHits, double depthTolerance = 1e-5, int tiePercent = 2)
{
  EXPECT_EQ(c.coverageDiffer, 0);
  EXPECT_EQ(c.colourDiffer, 0);
  EXPECT_LE(c.worstDepth, depthTolerance);
  EXPECT_GE(c.hits, minimumHits);
  EXPECT_LE(c.ties * 100, c.hits * tiePercent) << "too many ties: the test says little";
}

// The check of CompareWithFirstHits + ExpectAgreement, as the report says it.
const char* kFirstHitCheck = "brute-force first hit in double: coverage and colour exact outside ties (the "
                             "reference within %.0e of the cube of the other verdict), depth within 1e-5";

// A picture of the octree's one leaf (one point, coincident points) from an
// oblique perspective camera 3 voxels away: per pixel, the leaf's box in
// double, pixels within `marginFraction` of a voxel of its outline left
// unchecked; inside, the expected colour (to 2e-6) and the brute-force hit
// distance (to `marginFraction` of a voxel).
struct LeafPicture
{
  int inside = 0, outside = 0, band = 0, wrongCoverage = 0, wrongColour = 0;
  double worstDistance = 0; // hit distance error, in voxels
  double worstOutline = 0;  // farthest a pixel in the band went the other way, in voxels
};

LeafPicture OneLeafPicture(Engine& engine, const float colour[3], double marginFraction)
{
  HostOctree t;
  engine.CopyToHost(t);
  SCOPED_TRACE("the leaf at depth " + std::to_string(t.depth));
  LeafPicture p;
  EXPECT_EQ(t.levelBegin[t.depth + 1] - t.levelBegin[t.depth], 1u) << "one leaf";
  const std::uint32_t leaf = t.levelBegin[t.depth];
  double lo[3], hi[3];
  NodeBox(t, leaf, t.depth, lo, hi);
  const double voxel = hi[0] - lo[0];
  const double centre[3] = { 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]) };
  const double eye[3] = { centre[0] + 2.2 * voxel, centre[1] - 1.5 * voxel, centre[2] + 1.8 * voxel };
  const int w = 48, h = 48;
  const double zNear = 0.3 * voxel, zFar = 10 * voxel;
  const Matrix vp = ViewProjection(eye, centre, kZUp, 40, 1.0, zNear, zFar);
  // Eye-space distance of a window depth (the perspective projection undone).
  auto eyeDistance = [&](double depth) { return 2 * zFar * zNear / ((zFar + zNear) - (2 * depth - 1) * (zFar - zNear)); };
  RenderSettings settings = Settings(vp, w, h);
  settings.maxBounces = 0; // the points may reflect; here only the first hit counts
  const Image image = RenderChecked(engine, settings);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const int expected = BoxHitWithMargin(PixelRay(vp, w, h, x, y), lo, hi, marginFraction * voxel);
      const std::size_t i = Pixel(image, x, y);
      const bool drawn = image.rgba[4 * i + 3] > 0;
      if (expected < 0)
      {
        ++p.band;
        // How far from the outline the picture's verdict still holds.
        double m = marginFraction;
        while (m > 1e-9 && BoxHitWithMargin(PixelRay(vp, w, h, x, y), lo, hi, m * voxel) < 0)
          m *= 0.5;
        if (BoxHitWithMargin(PixelRay(vp, w, h, x, y), lo, hi, m * voxel) != (drawn ? 1 : 0))
          p.worstOutline = std::max(p.worstOutline, 2 * m);
        continue;
      }
      p.wrongCoverage += drawn != (expected == 1);
      EXPECT_EQ(drawn, expected == 1) << "pixel " << x << "," << y;
      if (expected == 1 && drawn)
      {
        ++p.inside;
        p.wrongColour += !SameRgb(&image.rgba[4 * i], colour, 2e-6f);
        EXPECT_TRUE(SameRgb(&image.rgba[4 * i], colour, 2e-6f)) << "pixel " << x << "," << y;
        const double reference = eyeDistance(BruteForceFirstHit(t, vp, w, h, x, y).depth);
        p.worstDistance = std::max(p.worstDistance, std::fabs(eyeDistance(image.depth[i]) - reference) / voxel);
      }
      p.outside += expected == 0;
    }
  EXPECT_GT(p.inside, 100);
  EXPECT_GT(p.outside, 100);
  EXPECT_LE(p.worstDistance, marginFraction);
  return p;
}

std::string Describe(const LeafPicture& p)
{
  return Format("%d pixels inside, %d outside, %d on the outline band: %d coverage and %d colour mismatches; "
                "outline off by up to %.2g voxel, hit distance by up to %.1e voxel",
    p.inside, p.outside, p.band, p.wrongCoverage, p.wrongColour, p.worstOutline, p.worstDistance);
}
}

// ---------------------------------------------------------------- rays

// Parallel rays exactly along voxel faces: pixel centres fall on multiples
// of 1/64, so columns of rays run along the faces x, y = 3/8, 1/2, 5/8
// inside a solid 4x4x4 block of depth-3 voxels [1/4, 3/4)^3. Inside the
// outline no pixel may show the background (no cracks), outside none may
// show the block, along each of the six axis directions.
TEST_P(Stability, AxisAlignedRays)
{
  Scene s;
  const float c[3] = { 0.3f, 0.6f, 0.9f };
  for (int i = 2; i < 6; ++i)
    for (int j = 2; j < 6; ++j)
      for (int k = 2; k < 6; ++k)
        s.AddCell(3, i, j, k, c);
  engine->Build(s.View(), UnitCubeOptions(3));
  const int w = 64, h = 64;
  int inside = 0, onFaces = 0, cracks = 0, outside = 0, outsideDrawn = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : { -1, 1 })
    {
      SCOPED_TRACE("view axis " + std::to_string(axis) + " sign " + std::to_string(sign));
      double eye[3], target[3];
      for (int a = 0; a < 3; ++a)
        eye[a] = target[a] = 0.5 + 1 / 128.0; // shifts pixel centres onto multiples of 1/64
      eye[axis] = 0.5 + 3 * sign;
      target[axis] = 0.5;
      const Matrix vp = ViewProjection(eye, target, axis == 2 ? kYUp : kZUp, 0, 1.0, 1, 6, true, 0.5);
      const Image image = RenderChecked(*engine, Settings(vp, w, h));
      int viewInside = 0, viewOnFaces = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
        {
          const WorldRay r = PixelRay(vp, w, h, x, y);
          bool in = true, out = false, face = false;
          for (int a = 0; a < 3; ++a)
          {
            if (a == axis)
              continue;
            in = in && r.o[a] > 0.25 + 1e-9 && r.o[a] < 0.75 - 1e-9;
            out = out || r.o[a] < 0.25 - 1e-9 || r.o[a] > 0.75 + 1e-9;
            for (double f : { 0.375, 0.5, 0.625 })
              face = face || std::fabs(r.o[a] - f) < 1e-12;
          }
          const float alpha = image.rgba[4 * Pixel(image, x, y) + 3];
          if (in)
          {
            ++viewInside;
            viewOnFaces += face;
            cracks += !(alpha > 0.0f);
            EXPECT_GT(alpha, 0.0f) << "crack at pixel " << x << "," << y << (face ? " (on a face)" : "");
          }
          if (out)
          {
            ++outside;
            outsideDrawn += alpha != 0.0f;
            EXPECT_EQ(alpha, 0.0f) << "pixel " << x << "," << y << " outside the block";
          }
        }
      EXPECT_EQ(viewInside, 31 * 31);
      EXPECT_GT(viewOnFaces, 150) << "the rays were meant to run along faces";
      inside += viewInside, onFaces += viewOnFaces;
    }
  Record("6 parallel views (+-x, +-y, +-z) of a solid 4x4x4 block with pixel rays exactly along voxel faces, "
         "against the block's outline: no background inside, no block outside (exact)",
    Format("%d cracks in %d pixels inside (%d of them on voxel faces); %d of %d pixels outside drawn", cracks, inside,
      onFaces, outsideDrawn, outside));
}

// Rays almost parallel to a face: a one-voxel-thick checkerboard plate of
// 32x32 depth-5 cells (top face z = 1/32) seen by parallel rays at 10, 1,
// 0.1 and 0.01 degrees above the top face, through the plate's front face
// x = 0 and across its whole length. Pixels are stretched (the top face
// spans sin(angle) of the view's height, the plate's width its width) so
// that every angle puts ~40 rows on the top face. Per pixel, in double:
// whether the ray meets the plate, and the cell under its entry point. A
// float ray is allowed an error of delta = 2^-22 (two float ulps of 1) of
// the cube across the ray, which along the top face becomes
// delta / tan(angle): hits within that of a cell border, and rays within
// delta of the plate's outline, are the band left unchecked; the distance
// to the hit must be within delta / sin(angle) + delta.
TEST_P(Stability, GrazingRays)
{
  Scene s;
  const float red[3] = { 1, 0, 0 }, blue[3] = { 0, 0, 1 };
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j)
      s.AddCell(5, i, j, 0, (i + j) % 2 ? red : blue);
  engine->Build(s.View(), UnitCubeOptions(5));
  const double top = 1 / 32.0, delta = std::ldexp(1.0, -22);
  const double lo[3] = { 0, 0, 0 }, hi[3] = { 1, 1, top };
  const int w = 64, h = 64;
  const double zNear = 1, zFar = 5;
  int checked = 0, onTop = 0, band = 0, wrongCoverage = 0, wrongColour = 0;
  double worstRatio = 0; // distance error over its allowance
  std::string perAngle;
  for (double degrees : { 10.0, 1.0, 0.1, 0.01 })
  {
    SCOPED_TRACE(Format("%g degrees", degrees));
    const double e = degrees * M_PI / 180;
    const double dir[3] = { std::cos(e), 0, -std::sin(e) };
    const double centre[3] = { 0.5, 0.5, top };
    const double eye[3] = { centre[0] - 3 * dir[0], centre[1], centre[2] - 3 * dir[2] };
    const double halfHeight = 0.75 * std::sin(e), halfWidth = 0.6;
    const Matrix vp = ViewProjection(eye, centre, kZUp, 0, halfWidth / halfHeight, zNear, zFar, true, halfHeight);
    const Image image = RenderChecked(*engine, Settings(vp, w, h));
    const double alongTop = delta / std::tan(e) + delta;
    int angleTop = 0;
    double angleWorst = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
      {
        const WorldRay r = PixelRay(vp, w, h, x, y);
        const int expected = BoxHitWithMargin(r, lo, hi, delta);
        const std::size_t i = Pixel(image, x, y);
        const float* pixel = &image.rgba[4 * i];
        if (expected < 0)
        {
          ++band;
          continue;
        }
        const bool drawn = pixel[3] > 0;
        if (drawn != (expected == 1))
        {
          ++wrongCoverage;
          ADD_FAILURE() << "pixel " << x << "," << y << (drawn ? " drawn past the plate" : " misses the plate");
          continue;
        }
        if (expected == 0)
        {
          ++checked;
          continue;
        }
        double t0 = 0, t1 = 1;
        Slab(r, lo, hi, t0, t1);
        double p[3];
        for (int a = 0; a < 3; ++a)
          p[a] = r.o[a] + t0 * r.d[a];
        // Entered through the top face, or through the front face x = 0.
        const bool throughTop = p[0] > delta;
        const double gx = p[0] * 32, gy = p[1] * 32;
        if ((throughTop && std::fabs(gx - std::round(gx)) < 32 * alongTop) ||
          std::fabs(gy - std::round(gy)) < 32 * delta)
        {
          ++band;
          continue;
        }
        const int ci = throughTop ? int(std::floor(gx)) : 0, cj = int(std::floor(gy));
        const float* colour = (ci + cj) % 2 ? red : blue;
        ++checked;
        if (!SameRgb(pixel, colour))
        {
          ++wrongColour;
          ADD_FAILURE() << "pixel " << x << "," << y << " shows the wrong cell; expected " << ci << "," << cj;
          continue;
        }
        // Parallel projection: window depth is the distance from the near
        // plane over the clipping range.
        const double distance = t0 * Length(r.d), drawnDistance = double(image.depth[i]) * (zFar - zNear);
        const double allowed = throughTop ? delta / std::sin(e) + delta : delta;
        angleWorst = std::max(angleWorst, std::fabs(drawnDistance - distance) / allowed);
        angleTop += throughTop;
      }
    EXPECT_GT(angleTop, 1000) << "the top face should fill ~40 rows";
    onTop += angleTop;
    worstRatio = std::max(worstRatio, angleWorst);
    perAngle += Format("%s%g deg: %d top-face pixels", perAngle.empty() ? "" : ", ", degrees, angleTop);
  }
  Record("parallel rays at 10, 1, 0.1, 0.01 degrees to a checkerboard plate's top face, against the plate box and "
         "the cell under the entry point in double; band: d = 2^-22 of the cube across the ray (d/tan(angle) along "
         "the face); hit distance within d/sin(angle) + d",
    Format("%d coverage and %d colour mismatches in %d pixels checked (%s), %d in the band; largest distance "
           "error %.2f of its allowance",
      wrongCoverage, wrongColour, checked, perAngle.c_str(), band, worstRatio));
  EXPECT_EQ(wrongCoverage, 0);
  EXPECT_EQ(wrongColour, 0);
  EXPECT_LE(worstRatio, 1.0);
  EXPECT_LT(band * 10, checked);
}

// ---------------------------------------------------------------- camera

TEST_P(Stability, CameraInsideTheData)
{
  const Cloud c = UniformCloud(150, 49);
  HostOctree t = BuildOnHost(*engine, c.View(), 4);
  const int w = 48, h = 48;
  // From the cube's centre, in six directions, against brute force.
  const double eye[3] = { t.cube.origin[0] + 0.5 * t.cube.size, t.cube.origin[1] + 0.5 * t.cube.size,
    t.cube.origin[2] + 0.5 * t.cube.size };
  const double dirs[][3] = { { 1, 0.3, 0.2 }, { -1, 0.1, -0.3 }, { 0.2, 1, 0.1 }, { 0.1, -1, 0.4 }, { 0.3, 0.2, 1 },
    { -0.2, 0.1, -1 } };
  const double margin = 1e-6 * t.cube.size;
  HitComparison all;
  for (const auto& d : dirs)
  {
    const double target[3] = { eye[0] + d[0], eye[1] + d[1], eye[2] + d[2] };
    const Matrix vp = ViewProjection(eye, target, std::fabs(d[2]) > 0.9 ? kYUp : kZUp, 90, 1.0, 0.01, 10);
    RenderSettings settings = Settings(vp, w, h);
    settings.maxBounces = 0; // the points reflect; here only the first hit counts
    const HitComparison one = CompareWithFirstHits(RenderChecked(*engine, settings), t, vp, margin);
    EXPECT_GT(one.hits, 20);
    all.Add(one);
  }

  // The eye inside an occupied leaf, the near plane too: every pixel is
  // that leaf, at window depth 0.
  const std::uint32_t leaf = t.levelBegin[t.depth];
  double lo[3], hi[3];
  NodeBox(t, leaf, t.depth, lo, hi);
  const double inLeaf[3] = { 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]) };
  const double target[3] = { inLeaf[0] + 1, inLeaf[1] + 0.2, inLeaf[2] + 0.1 };
  const double voxel = hi[0] - lo[0];
  const Matrix vp = ViewProjection(inLeaf, target, kZUp, 60, 1.0, 0.05 * voxel, 10);
  RenderSettings settings = Settings(vp, w, h);
  settings.maxBounces = 0;
  const Image image = RenderChecked(*engine, settings);
  int notTheLeaf = 0;
  float worstDepth = 0;
  for (std::size_t i = 0; i < image.depth.size(); ++i)
  {
    notTheLeaf += !SameRgb(&image.rgba[4 * i], NodeRgb(t, leaf));
    worstDepth = std::max(worstDepth, std::fabs(image.depth[i]));
  }
  Record(Format(kFirstHitCheck, 1e-6) + "; from inside an occupied leaf: every pixel that leaf at depth 0 (1e-6)",
    "from the centre, 6 directions: " + all.Summary() +
      Format("; inside a leaf: %d of %zu pixels not that leaf, largest depth %.1e", notTheLeaf, image.depth.size(),
        double(worstDepth)));
  ExpectAgreement(all, 6 * 20);
  EXPECT_EQ(notTheLeaf, 0);
  EXPECT_LE(worstDepth, 1e-6f); // 0 up to the matrices' rounding
}

TEST_P(Stability, CameraAMillionBoxSizesAway)
{
  const Cloud c = UniformCloud(400, 50);
  HostOctree t = BuildOnHost(*engine, c.View(), 5);
  const double size = t.cube.size;
  const double centre[3] = { t.cube.origin[0] + 0.5 * size, t.cube.origin[1] + 0.5 * size,
    t.cube.origin[2] + 0.5 * size };
  double dir[3] = { 1, -0.7, 0.5 };
  Normalize3(dir);
  const double distance = 1e6 * size;
  const double eye[3] = { centre[0] + distance * dir[0], centre[1] + distance * dir[1], centre[2] + distance * dir[2] };
  const int w = 64, h = 64;
  // Field of view such that the cube fills about the image: 2 atan(0.9 / 1e6).
  const double fovy = 2 * std::atan(0.9 * size / distance) * 180 / M_PI;
  const Matrix vp = ViewProjection(eye, centre, kZUp, fovy, 1.0, distance - 2 * size, distance + 2 * size);
  RenderSettings settings = Settings(vp, w, h);
  settings.maxBounces = 0; // the points reflect; here only the first hit counts
  const Image image = RenderChecked(*engine, settings);
  // The reference's own rays are unprojected from 1e6 cube sizes away in
  // double: their rounding (1e-16 x 1e6) is the ties' margin.
  const HitComparison perspective = CompareWithFirstHits(image, t, vp, 1e-6 * size);

  // The same parallel view from 1e6 cube sizes and from 3: only the near
  // plane moves, so hits and colours must be the same pictures.
  const Matrix farVp =
    ViewProjection(eye, centre, kZUp, 0, 1.0, distance - 2 * size, distance + 2 * size, true, 0.9 * size);
  const double nearEye[3] = { centre[0] + 3 * size * dir[0], centre[1] + 3 * size * dir[1],
    centre[2] + 3 * size * dir[2] };
  const Matrix nearVp = ViewProjection(nearEye, centre, kZUp, 0, 1.0, size, 5 * size, true, 0.9 * size);
  settings = Settings(farVp, w, h);
  settings.maxBounces = 0;
  const Image a = RenderChecked(*engine, settings);
  settings = Settings(nearVp, w, h);
  settings.maxBounces = 0;
  const Image b = RenderChecked(*engine, settings);
  int differ = 0;
  for (std::size_t i = 0; i < a.depth.size(); ++i)
    differ += !SameRgb(&a.rgba[4 * i], &b.rgba[4 * i], 0) || a.rgba[4 * i + 3] != b.rgba[4 * i + 3];
  Record(Format(kFirstHitCheck, 1e-6) +
      "; a parallel view from 1e6 cube sizes against the same view from 3 (colour exact, at most 2 pixels)",
    "perspective: " + perspective.Summary() +
      Format("; parallel far vs near: %d of %zu pixels differ", differ, a.depth.size()));
  ExpectAgreement(perspective, 500);
  EXPECT_LE(differ, 2) << "pixels differing between the far and the near parallel view";
}

// ---------------------------------------------------------------- coordinates and extents

TEST_P(Stability, CoordinatesOffsetBy1e7)
{
  // A 20 x 20 x 5 grid of points 1 mm apart at 1e7 m: at depth 16 the
  // leaves are ~0.3 micrometres, so every point has a leaf of its own.
  std::mt19937_64 rng(18);
  Cloud c;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      for (int k = 0; k < 5; ++k)
        c.Add(1e7 + 0.001 * i, -1e7 + 0.001 * j, 5e6 + 0.001 * k, rng);
  BuildAndCompare(*engine, c, 16);
  HostOctree t;
  engine->CopyToHost(t);
  EXPECT_EQ(t.levelBegin[17] - t.levelBegin[16], c.Size());
  const std::size_t leaves16 = t.levelBegin[17] - t.levelBegin[16];
  const int w = 48, h = 48;

  // The corner of the grid at depth 7 (0.15 mm leaves) from 7 mm away.
  BuildAndCompare(*engine, c, 7);
  engine->CopyToHost(t);
  HitComparison grid;
  {
    const double corner[3] = { 1e7 + 0.0015, -1e7 + 0.0015, 5e6 + 0.0015 };
    const double eye[3] = { corner[0] - 0.004, corner[1] - 0.003, corner[2] + 0.005 };
    const Matrix vp = ViewProjection(eye, corner, kZUp, 40, 1.0, 1e-3, 0.1);
    RenderSettings settings = Settings(vp, w, h);
    settings.maxBounces = 0; // the points reflect; here only the first hit counts
    grid = CompareWithFirstHits(RenderChecked(*engine, settings), t, vp, 1e-6 * t.cube.size);
  }
  // One depth-16 leaf (0.3 micrometres) seen from 1 micrometre, 13 orders
  // of magnitude below the coordinates: there a double resolves 1.9e-9 m
  // (ulp(1e7)), 1/150 of the leaf, and the camera matrices, the reference's
  // rays and the window depth (clip w is a difference of 1e7-sized terms)
  // each round to a few of those. Ties: within 8 ulp(1e7) of the other
  // verdict; depth: 8 ulp(1e7) over the eye's distance.
  const double ulp = std::nextafter(1e7, 2e7) - 1e7;
  BuildAndCompare(*engine, c, 16);
  engine->CopyToHost(t);
  HitComparison closeUp;
  double closeUpDepth = 0;
  {
    double lo[3], hi[3];
    NodeBox(t, t.levelBegin[16], 16, lo, hi);
    const double voxel = hi[0] - lo[0];
    const double centre[3] = { 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]) };
    const double eye[3] = { centre[0] - 2.2 * voxel, centre[1] - 1.5 * voxel, centre[2] + 1.8 * voxel };
    const Matrix vp = ViewProjection(eye, centre, kZUp, 40, 1.0, 0.3 * voxel, 10 * voxel);
    RenderSettings settings = Settings(vp, w, h);
    settings.maxBounces = 0;
    closeUp = CompareWithFirstHits(RenderChecked(*engine, settings), t, vp, 8 * ulp);
    closeUpDepth = 8 * ulp / Length(std::array<double, 3>{ eye[0] - centre[0], eye[1] - centre[1], eye[2] - centre[2] }.data());
  }
  BuildAndCompare(*engine, c, 0);
  engine->CopyToHost(t);
  ExpectDepthRule(t, c);
  Record("octree node by node against the brute-force reference at depths 16, 7 and automatic; picture of "
         "depth 7 (0.15 mm leaves from 7 mm): " +
      Format(kFirstHitCheck, 1e-6) +
      Format("; one depth-16 leaf (0.3 um from 1 um): the same with ties within 8 ulp(1e7) and depth within %.1e",
        closeUpDepth),
    Format("octree equal to the reference, %zu of %zu points in leaves of their own at depth 16; depth 7: ",
      leaves16, c.Size()) +
      grid.Summary() + "; close-up: " + closeUp.Summary());
  ExpectAgreement(grid, 50);
  ExpectAgreement(closeUp, 500, closeUpDepth, 10);
}

namespace
{
// Gaussian clusters scaled to the largest extent `extent`: the octree
// against its reference and pictures against brute force, perspective and
// parallel, with the camera scaled alike.
void ScaledClusters(Engine& engine, double extent)
{
  Cloud c = GaussianClusters(400, 41);
  double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
  for (std::size_t i = 0; i < c.xyz.size(); ++i)
    lo[i % 3] = std::min(lo[i % 3], c.xyz[i]), hi[i % 3] = std::max(hi[i % 3], c.xyz[i]);
  const double scale = extent / std::max({ hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] });
  for (double& v : c.xyz)
    v *= scale;
  BuildAndCompare(engine, c, 5);
  HostOctree t;
  engine.CopyToHost(t);
  const int w = 64, h = 48;
  const double eye[3] = { 25 * scale, -30 * scale, 18 * scale }, target[3] = { 2 * scale, 1 * scale, 1 * scale };
  HitComparison all;
  for (bool parallel : { false, true })
  {
    SCOPED_TRACE(parallel ? "parallel projection" : "perspective");
    const Matrix vp = ViewProjection(eye, target, kZUp, 40, double(w) / h, 5 * scale, 120 * scale, parallel, 12 * scale);
    RenderSettings settings = Settings(vp, w, h);
    settings.maxBounces = 0; // the points reflect; here only the first hit counts
    all.Add(CompareWithFirstHits(RenderChecked(engine, settings), t, vp, 1e-6 * t.cube.size));
  }
  Record("octree node by node against the brute-force reference (depth 5); perspective and parallel pictures: " +
      Format(kFirstHitCheck, 1e-6),
    Format("extent %.3g (cube %.3g): octree equal to the reference; ", extent, t.cube.size) + all.Summary());
  ExpectAgreement(all, 200);
}
}

TEST_P(Stability, Extent1eMinus6)
{
  ScaledClusters(*engine, 1e-6);
}

TEST_P(Stability, Extent1e6)
{
  ScaledClusters(*engine, 1e6);
}

// ---------------------------------------------------------------- degenerate data

TEST_P(Stability, OnePoint)
{
  // A single point: the root cube comes from degenerate bounds (side 2^-20
  // of the coordinates' magnitude, RootCube::FromBounds).
  std::mt19937_64 rng(17);
  Cloud one;
  one.Add(7, 8, 9, rng);
  const float colour[3] = { one.rgb[0] / 255.0f, one.rgb[1] / 255.0f, one.rgb[2] / 255.0f };
  BuildAndCompare(*engine, one, 3);
  BuildAndCompare(*engine, one, 0);
  const LeafPicture automatic = OneLeafPicture(*engine, colour, 1e-3);
  BuildAndCompare(*engine, one, 21);
  // At depth 21 the leaf is 2^-21 of the cube, 8 float ulps at the cube's
  // centre, where the traversal's float rays resolve 1/8 of it: band 1/4.
  const LeafPicture deepest = OneLeafPicture(*engine, colour, 0.25);
  HostOctree t;
  engine->CopyToHost(t);
  Record("octree against the brute-force reference at depths 3, automatic and 21; the picture of its one leaf "
         "against the leaf's box in double: outside a band of 1e-3 voxel (1/4 at depth 21, 2 float ulps) "
         "coverage exact, colour 2e-6, hit distance within the band",
    "automatic depth: " + Describe(automatic) + "; depth 21 (leaf " + Format("%.1e", t.cube.size / 2097152.0) +
      " wide at 9): " + Describe(deepest));
}

TEST_P(Stability, CoincidentPoints)
{
  std::mt19937_64 rng(16);
  Cloud c;
  for (int i = 0; i < 1000; ++i)
  {
    c.Add(1.5, -2.5, 1e3, rng);
  }
  double mean[3] = { 0, 0, 0 };
  for (std::size_t i = 0; i < c.Size(); ++i)
    for (int k = 0; k < 3; ++k)
      mean[k] += c.rgb[3 * i + k] / 255.0 / c.Size();
  // 8-bit colours: their mean is stored rounded to a byte (Attributes.h).
  float colour[3];
  for (int k = 0; k < 3; ++k)
    colour[k] = float(std::lround(mean[k] * 255.0) / 255.0);
  BuildAndCompare(*engine, c, 5);
  const LeafPicture five = OneLeafPicture(*engine, colour, 1e-3);
  BuildAndCompare(*engine, c, 21);
  const LeafPicture deepest = OneLeafPicture(*engine, colour, 0.25);
  // Deeper levels separate nothing, so the automatic depth stops at 1.
  BuildAndCompare(*engine, c, 0);
  HostOctree t;
  engine->CopyToHost(t);
  EXPECT_EQ(t.depth, 1);
  EXPECT_EQ(t.pointCount.back(), 1000u);
  Record("1000 points at one place: octree against the brute-force reference at depths 5, 21 and automatic "
         "(which must stop at 1); the picture of the one leaf against its box in double: outside a band of 1e-3 "
         "voxel (1/4 at depth 21, 2 float ulps) coverage exact, colour = the mean of the 1000 8-bit colours rounded "
         "to a byte, to 2e-6, "
         "hit distance within the band",
    Format("automatic depth %d; depth 5: ", t.depth) + Describe(five) + "; depth 21: " + Describe(deepest));
}

namespace
{
// 5000 points on a tilted plane (flat in z) or on a line.
Cloud PlaneOrLine(bool plane)
{
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> u(-3, 3);
  Cloud c;
  for (int i = 0; i < 5000; ++i)
  {
    const double a = u(rng), b = u(rng);
    if (plane)
      c.Add(a, 0.25 * a + 0.5 * b, 2.0, rng); // tilted in y, flat in z
    else
      c.Add(a, 2 * a + 1, -a, rng);
  }
  return c;
}

HitComparison FirstHitPicture(Engine& engine, const double eye[3], const double target[3], double zNear, double zFar)
{
  HostOctree t;
  engine.CopyToHost(t);
  const int w = 64, h = 48;
  const Matrix vp = ViewProjection(eye, target, kZUp, 45, double(w) / h, zNear, zFar);
  RenderSettings settings = Settings(vp, w, h);
  settings.maxBounces = 0; // the points reflect; here only the first hit counts
  return CompareWithFirstHits(RenderChecked(engine, settings), t, vp, 1e-6 * t.cube.size);
}
}

TEST_P(Stability, FlatData)
{
  const Cloud plane = PlaneOrLine(true);
  BuildAndCompare(*engine, plane, 8);
  // Pictured at depth 6, where most cells of the plane are occupied: from
  // above at an angle, and nearly edge-on (the eye 2 degrees above the
  // plane's level).
  BuildAndCompare(*engine, plane, 6);
  const double eye[3] = { 2.5, -3.5, 4.5 }, target[3] = { 0, 0, 2 };
  const HitComparison oblique = FirstHitPicture(*engine, eye, target, 1, 30);
  const double edgeEye[3] = { 5, -2.2, 2 + 0.035 * 5.46 };
  const HitComparison edgeOn = FirstHitPicture(*engine, edgeEye, target, 1, 30);
  Record("points on a plane: octree against the brute-force reference (depths 8 and 6); an oblique and a nearly "
         "edge-on picture (2 degrees) at depth 6: " +
      Format(kFirstHitCheck, 1e-6),
    "oblique: " + oblique.Summary() + "; nearly edge-on: " + edgeOn.Summary());
  ExpectAgreement(oblique, 500);
  ExpectAgreement(edgeOn, 100);
}

TEST_P(Stability, CollinearData)
{
  const Cloud line = PlaneOrLine(false);
  BuildAndCompare(*engine, line, 12);
  // The whole line at depth 5 (voxels of ~0.4, a pixel or two wide), and a
  // close-up of its middle at the automatic depth.
  BuildAndCompare(*engine, line, 5);
  const double eye[3] = { 9, -6, 7 }, target[3] = { 0, 1, 0 };
  const HitComparison whole = FirstHitPicture(*engine, eye, target, 1, 40);
  BuildAndCompare(*engine, line, 0);
  HostOctree t;
  engine->CopyToHost(t);
  const double voxel = t.cube.size / double(1 << t.depth);
  const double closeEye[3] = { 12 * voxel, 1 - 8 * voxel, 10 * voxel };
  const HitComparison closeUp = FirstHitPicture(*engine, closeEye, target, voxel, 100 * voxel);
  Record("points on a line: octree against the brute-force reference (depths 12, 5 and automatic); the whole line "
         "at depth 5 and a close-up at the automatic depth: " +
      Format(kFirstHitCheck, 1e-6),
    "depth 5: " + whole.Summary() + Format("; automatic depth %d, close-up: ", t.depth) + closeUp.Summary());
  ExpectAgreement(whole, 100);
  ExpectAgreement(closeUp, 100);
}

TEST_P(Stability, Depth21)
{
  // Two points in neighbouring depth-21 leaves along x: [1/2, 1/2 + e) and
  // [1/2 + e, 1/2 + 2e), e = 2^-21. A parallel view of 4e x 4e over 8x8
  // pixels puts pixel centres at x = 1/2 + (i - 1.5) e / 2: columns 0..1 are
  // left of both, 2..3 the first leaf, 4..5 the second, 6..7 right of both;
  // rows alike on y: both leaves span y in [1/2, 1/2 + e), rows 2..3.
  const double e = std::ldexp(1.0, -21);
  Scene s;
  const float a[3] = { 1, 0, 0 }, b[3] = { 0, 1, 0 };
  s.Add(0.5 + 0.5 * e, 0.5 + 0.5 * e, 0.5 + 0.5 * e, a);
  s.Add(0.5 + 1.5 * e, 0.5 + 0.5 * e, 0.5 + 0.5 * e, b);
  engine->Build(s.View(), UnitCubeOptions(21));
  HostOctree t;
  engine->CopyToHost(t);
  ASSERT_EQ(t.levelBegin[22] - t.levelBegin[21], 2u) << "two separate leaves at depth 21";
  const int w = 8, h = 8;
  const double centre[3] = { 0.5 + e, 0.5 + e, 0.5 };
  const double eye[3] = { centre[0], centre[1], 3 };
  const Matrix vp = ViewProjection(eye, centre, kYUp, 0, 1.0, 1, 5, true, 2 * e);
  const Image image = RenderChecked(*engine, Settings(vp, w, h));
  int wrong = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const std::size_t i = Pixel(image, x, y);
      const bool row = y >= 2 && y <= 3; // y in [1/2, 1/2 + e)
      bool right;
      if (row && x >= 2 && x <= 3)
        right = SameRgb(&image.rgba[4 * i], a);
      else if (row && x >= 4 && x <= 5)
        right = SameRgb(&image.rgba[4 * i], b);
      else
        right = image.rgba[4 * i + 3] == 0.0f;
      wrong += !right;
      EXPECT_TRUE(right) << "pixel " << x << "," << y;
    }
  Record("two points in neighbouring depth-21 leaves (2^-21 of the cube) under an 8x8 parallel view 4 leaves "
         "wide: each pixel's leaf from the layout, colour exact",
    Format("2 separate leaves; %d of %d pixels wrong", wrong, w * h));
}

// ---------------------------------------------------------------- shading

// A flat floor (normal +z: its occupancy gradient vanishes inside, so the
// entry face gives it) under a point light, seen by a parallel camera: the
// Phong colour of every pixel worked out in double from the hit point, the
// light and the view (the light vector taken, as the engine does, from the
// entry point nudged 1e-3 voxel out of the face). Powers 0, 10 and 1e4
// per pixel: a float ray's error of ~1e-7 in r.v becomes ~power x 1e-7 in
// pow(r.v, power), so the tolerance is 1e-5 + 2e-7 x power. Power 1e30:
// finite, and no channel above ambient + diffuse + specular.
TEST_P(Stability, SpecularPower1e4)
{
  Scene s;
  const float grey[3] = { 0.6f, 0.6f, 0.6f };
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j)
      s.AddCell(5, i, j, 0, grey);
  engine->Build(s.View(), UnitCubeOptions(5));
  const double top = 1 / 32.0;
  const double lamp[3] = { 0.5, 0.5, 0.4 };
  double v[3] = { 0.3, -0.2, 1.0 }; // towards the eye
  Normalize3(v);
  // The mirror point: where the direction to the light is v mirrored
  // about the floor, (-vx, -vy, vz).
  const double reach = (lamp[2] - top) / v[2];
  const double spot[3] = { lamp[0] + reach * v[0], lamp[1] + reach * v[1], top };
  const double eye[3] = { spot[0] + 3 * v[0], spot[1] + 3 * v[1], spot[2] + 3 * v[2] };
  const int w = 96, h = 96;
  const Matrix vp = ViewProjection(eye, spot, kZUp, 0, 1.0, 1, 5, true, 0.1);
  RenderSettings settings = Settings(vp, w, h);
  settings.shade = ShadeMode::Phong;
  settings.ambient = 0.1f;
  settings.diffuse = 0.6f;
  settings.specular = 1.0f;
  Light light;
  for (int a = 0; a < 3; ++a)
    light.position[a] = lamp[a];
  light.position[3] = 1;
  settings.lights.push_back(light);
  const double floorLo[3] = { 0, 0, 0 }, floorHi[3] = { 1, 1, top };
  std::string outcome;
  int wrongTotal = 0;
  for (float power : { 0.0f, 10.0f, 1e4f })
  {
    SCOPED_TRACE(Format("power %g", power));
    settings.specularPower = power;
    const Image image = RenderChecked(*engine, settings);
    const double tol = 1e-5 + 2e-7 * power;
    int checked = 0, wrong = 0, highlight = 0;
    double worst = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
      {
        const WorldRay r = PixelRay(vp, w, h, x, y);
        double t0 = 0, t1 = 1;
        if (!Slab(r, floorLo, floorHi, t0, t1))
          continue;
        double p[3], l[3], view[3];
        for (int a = 0; a < 3; ++a)
          p[a] = r.o[a] + t0 * r.d[a], view[a] = -r.d[a];
        if (std::fabs(p[2] - top) > 1e-9 || p[0] < 1 / 32.0 || p[0] > 31 / 32.0 || p[1] < 1 / 32.0 || p[1] > 31 / 32.0)
          continue; // not the top face, or the rim, whose gradient normal tilts
        p[2] += 1e-3 / 32;
        for (int a = 0; a < 3; ++a)
          l[a] = lamp[a] - p[a];
        Normalize3(l);
        Normalize3(view);
        const double nl = l[2];
        const double rv = -l[0] * view[0] - l[1] * view[1] + l[2] * view[2]; // r = 2 (n.l) n - l, n = +z
        const double spec = rv > 0 ? std::pow(rv, double(power)) : 0.0;
        const double expected = 0.6 * (0.1 + 0.6 * nl) + spec;
        const float* pixel = &image.rgba[4 * Pixel(image, x, y)];
        ++checked;
        highlight += spec > 0.01;
        double err = 0;
        for (int k = 0; k < 3; ++k)
          err = std::max(err, std::fabs(pixel[k] - expected));
        worst = std::max(worst, err);
        wrong += err > tol;
        EXPECT_LE(err, tol) << "pixel " << x << "," << y << ": " << pixel[0] << " against " << expected;
      }
    EXPECT_GT(checked, w * h * 9 / 10);
    if (power == 1e4f)
      EXPECT_GT(highlight, 20) << "the highlight should cover some pixels";
    wrongTotal += wrong;
    outcome += Format("%spower %g: largest error %.1e (tol %.1e), %d highlight pixels", outcome.empty() ? "" : "; ",
      double(power), worst, tol, highlight);
  }
  settings.specularPower = 1e30f;
  const Image image = RenderChecked(*engine, settings);
  float most = 0;
  for (std::size_t i = 0; i < image.depth.size(); ++i)
    most = std::max(most, image.rgba[4 * i]);
  Record("Phong on a flat floor under a point light, per pixel against the formula in double (tolerance 1e-5 + "
         "2e-7 x power) for powers 0, 10, 1e4; power 1e30: finite, no channel above ambient + diffuse + specular",
    outcome + Format("; power 1e30: finite, brightest %.3f (bound %.3f); %d pixels out of tolerance", double(most),
                0.6 * 0.7 + 1.0, wrongTotal));
  EXPECT_LE(most, 0.6f * 0.7f + 1.0f);
  EXPECT_GT(most, 0.0f);
}

TEST_P(Stability, LightInsideAVoxel)
{
  // Floor and block as in the shadow test, a point light at the centre of a
  // block voxel: every shadow ray towards it enters that voxel first, so
  // with shadows every surface gets the ambient term alone; without, the
  // floor around the block is lit. No NaN either way (the light's own voxel
  // puts p - light near zero).
  const float grey[3] = { 0.6f, 0.6f, 0.6f };
  const Scene s = FloorAndBlock(grey);
  engine->Build(s.View(), UnitCubeOptions(5));
  const int w = 64, h = 64;
  const double eye[3] = { 0.5, -0.5, 1.2 }, target[3] = { 0.5, 0.5, 0 };
  RenderSettings settings = Settings(ViewProjection(eye, target, kZUp, 45, 1.0, 0.1, 5), w, h);
  settings.shade = ShadeMode::Phong;
  settings.ambient = 0.2f;
  Light lamp;
  lamp.position[0] = 12.5 / 32, lamp.position[1] = 12.5 / 32, lamp.position[2] = 6.5 / 32, lamp.position[3] = 1;
  settings.lights.push_back(lamp);
  settings.shadows = true;
  RenderStats stats;
  const Image shadowed = RenderChecked(*engine, settings, &stats);
  const float ambient[3] = { 0.2f * 0.6f, 0.2f * 0.6f, 0.2f * 0.6f };
  int hits = 0, notAmbient = 0;
  for (std::size_t i = 0; i < shadowed.depth.size(); ++i)
    if (shadowed.rgba[4 * i + 3] > 0)
    {
      ++hits;
      notAmbient += !SameRgb(&shadowed.rgba[4 * i], ambient);
    }
  settings.shadows = false;
  const Image lit = RenderChecked(*engine, settings);
  int brighter = 0;
  for (std::size_t i = 0; i < lit.depth.size(); ++i)
    brighter += lit.rgba[4 * i] > ambient[0] + 1e-3f;
  Record("a point light at the centre of an occupied voxel, shadows on: every surface pixel exactly the ambient "
         "term (1e-6); shadows off: the floor lit; no NaN or infinity",
    Format("shadows on: %d of %d surface pixels not ambient; shadows off: %d pixels lit; all finite", notAmbient,
      hits, brighter));
  EXPECT_GT(stats.secondaryRays, 0u);
  EXPECT_GT(hits, 1000);
  EXPECT_EQ(notAmbient, 0) << "surfaces lit by a light enclosed in a voxel";
  EXPECT_GT(brighter, 100);
}

// ---------------------------------------------------------------- refraction

// Scenes on a fixed 64^3 grid of unit voxels; the floor's colour encodes
// each voxel's x so that the picture says where every ray landed.
namespace
{
struct GridScene
{
  std::vector<double> xyz;
  std::vector<std::uint8_t> rgb;
  std::vector<float> refraction;

  void Voxel(int x, int y, int z, std::uint8_t r, std::uint8_t g, float ior)
  {
    xyz.insert(xyz.end(), { x + 0.5, y + 0.5, z + 0.5 });
    rgb.insert(rgb.end(), { r, g, 255 });
    refraction.push_back(ior);
  }
  // The floor z = 0: red encodes x (4 per voxel), green y.
  void Floor()
  {
    for (int x = 0; x < 64; ++x)
      for (int y = 0; y < 64; ++y)
        Voxel(x, y, 0, static_cast<std::uint8_t>(4 * x), static_cast<std::uint8_t>(4 * y), 0.0f);
  }
  PointCloudView View() const
  {
    PointCloudView v;
    v.count = xyz.size() / 3;
    v.xyzDouble = xyz.data();
    v.color8 = rgb.data();
    v.colorComponents = 3;
    v.refraction = refraction.data();
    return v;
  }
};

BuildOptions Grid64()
{
  BuildOptions o;
  o.depth = 6;
  o.fixedCube = true;
  o.cube.size = 64.0;
  return o;
}

// A parallel projection looking along `dir` (unit, world) at the grid centre.
RenderSettings ParallelView(const double dir[3], int w, int h, double halfHeight)
{
  const double centre[3] = { 32, 32, 32 };
  const double eye[3] = { 32 - 100 * dir[0], 32 - 100 * dir[1], 32 - 100 * dir[2] };
  return Settings(ViewProjection(eye, centre, kYUp, 0, double(w) / h, 1, 300, true, halfHeight), w, h);
}

// World point where pixel (x, y)'s ray crosses the plane z = planeZ.
void PixelRayAtZ(const RenderSettings& s, int x, int y, const double dir[3], double planeZ, double p[3])
{
  const double ndc[4] = { 2.0 * (x + 0.5) / s.width - 1, 2.0 * (y + 0.5) / s.height - 1, -1, 1 };
  double h[4] = {};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k)
      h[i] += s.inverseViewProjection[4 * i + k] * ndc[k];
  const double o[3] = { h[0] / h[3], h[1] / h[3], h[2] / h[3] };
  const double t = (planeZ - o[2]) / dir[2];
  for (int a = 0; a < 3; ++a)
    p[a] = o[a] + t * dir[a];
}

// A glass slab of index `ior` fills 20 <= z < 28 over the floor; parallel
// rays at `degrees` from the vertical. Snell's law: down 8 voxels of glass
// at asin(sin(theta) / ior), then 19 of air at theta to the floor's top face
// (z = 1); the floor's red says which voxel column each pixel landed on.
struct SlabLanding
{
  int checked = 0, exact = 0, near = 0, shifted = 0;
  double shift = 0; // how far short of the straight path Snell lands, voxels
};

SlabLanding GlassSlab(Engine& engine, float ior, double degrees)
{
  GridScene scene;
  scene.Floor();
  for (int x = 0; x < 64; ++x)
    for (int y = 0; y < 64; ++y)
      for (int z = 20; z < 28; ++z)
        scene.Voxel(x, y, z, 255, 255, ior);
  engine.Build(scene.View(), Grid64());
  const double theta = degrees * M_PI / 180;
  const double dir[3] = { std::sin(theta), 0, -std::cos(theta) };
  const RenderSettings s = ParallelView(dir, 48, 48, 10);
  const Image image = RenderChecked(engine, s);
  const double thetaT = std::asin(std::sin(theta) / ior);
  SlabLanding result;
  result.shift = 8 * (std::tan(theta) - std::tan(thetaT));
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x)
    {
      double top[3];
      PixelRayAtZ(s, x, y, dir, 28.0, top);
      if (top[0] < 4 || top[0] > 40 || top[1] < 4 || top[1] > 60)
        continue;
      const double floorX = top[0] + 8 * std::tan(thetaT) + 19 * std::tan(theta);
      const double straightX = top[0] + 27 * std::tan(theta);
      const std::size_t i = Pixel(image, x, y);
      const int seen = static_cast<int>(std::lround(image.rgba[4 * i] * 255.0 / 4.0));
      ++result.checked;
      result.exact += seen == static_cast<int>(std::floor(floorX));
      result.near += std::abs(seen - static_cast<int>(std::floor(floorX))) <= 1;
      result.shifted += seen < static_cast<int>(std::floor(straightX)) - 2;
    }
  return result;
}

void RecordSlab(const SlabLanding& r, float ior, double degrees)
{
  Record(Format("a glass slab of index %g, 8 voxels thick, parallel rays at %g degrees: the floor voxel each pixel "
                "lands on against Snell's law in double: every pixel within 1 voxel, 95%% on the very voxel",
           double(ior), degrees),
    Format("%d of %d pixels on Snell's voxel, %d within 1; %d shifted short of the straight path (Snell's shift "
           "%.2f voxels)",
      r.exact, r.checked, r.near, r.shifted, r.shift));
  ASSERT_GT(r.checked, 500);
  EXPECT_EQ(r.near, r.checked);              // every pixel within one voxel of Snell's landing point
  EXPECT_GE(r.exact * 100, r.checked * 95); // and 95% on the very voxel
}
}

TEST_P(Stability, RefractionIndex1)
{
  // Index 1.0 bends nothing: the floor is seen where the straight ray lands.
  const SlabLanding r = GlassSlab(*engine, 1.0f, 30);
  RecordSlab(r, 1.0f, 30);
  EXPECT_EQ(r.shifted, 0);
}

TEST_P(Stability, RefractionIndex1_5)
{
  // The refracted path lands ~3.7 voxels short of the straight one.
  const SlabLanding r = GlassSlab(*engine, 1.5f, 45);
  RecordSlab(r, 1.5f, 45);
  EXPECT_EQ(r.shifted, r.checked);
}

TEST_P(Stability, RefractionIndex10)
{
  // Index 10 bends a 45-degree ray to 4 degrees: ~7.4 voxels short.
  const SlabLanding r = GlassSlab(*engine, 10.0f, 45);
  RecordSlab(r, 10.0f, 45);
  EXPECT_EQ(r.shifted, r.checked);
}

TEST_P(Stability, TotalInternalReflection)
{
  // A glass block 0 <= x < 32, 8 <= z < 24; air beyond x = 32.
  GridScene scene;
  scene.Floor();
  for (int x = 0; x < 32; ++x)
    for (int y = 0; y < 64; ++y)
      for (int z = 8; z < 24; ++z)
        scene.Voxel(x, y, z, 255, 255, 1.5f);
  engine->Build(scene.View(), Grid64());
  const double theta = 60.0 * M_PI / 180;
  const double dir[3] = { std::sin(theta), 0, -std::cos(theta) };
  RenderSettings s = ParallelView(dir, 64, 32, 12);
  s.maxBounces = 3; // in, reflected at the side, out
  const Image image = RenderChecked(*engine, s);

  const double thetaT = std::asin(std::sin(theta) / 1.5); // 35.3 deg; the side sees 54.7 > 41.8 (critical)
  const double critical = std::asin(1 / 1.5);
  ASSERT_GT(M_PI / 2 - thetaT, critical);
  int checked = 0, near = 0, escaped = 0;
  for (int y = 0; y < s.height; ++y)
  {
    for (int x = 0; x < s.width; ++x)
    {
      double top[3];
      PixelRayAtZ(s, x, y, dir, 24.0, top);
      // Entries whose refracted ray meets the side face x = 32 above z = 8.
      if (top[0] < 23 || top[0] > 31.5 || top[1] < 4 || top[1] > 60)
        continue;
      const double zSide = 24 - (32 - top[0]) / std::tan(thetaT);
      const double xBottom = 32 - (zSide - 8) * std::tan(thetaT);
      const double floorX = xBottom - 7 * std::tan(theta);
      if (floorX < 1)
        continue;
      const std::size_t i = Pixel(image, x, y);
      const int seen = static_cast<int>(std::lround(image.rgba[4 * i] * 255.0 / 4.0));
      ++checked;
      near += std::abs(seen - static_cast<int>(std::floor(floorX))) <= 1;
      escaped += seen >= 32;
      EXPECT_LT(seen, 32) << "pixel " << x << "," << y << ": the ray escaped through the side face";
    }
  }
  Record("a glass block of index 1.5, rays at 60 degrees meeting its side face at 54.7 > 41.8 degrees (critical): "
         "the floor voxel each pixel lands on after the internal reflection, against the geometry in double, "
         "within 1 voxel",
    Format("%d of %d pixels within 1 voxel of the reflected landing point; %d escaped through the side face", near,
      checked, escaped));
  ASSERT_GT(checked, 20);
  EXPECT_EQ(near, checked);
}

// ---------------------------------------------------------------- opacity and colour

namespace
{
// 300 points uniform in the unit cube with scalars in [0, 1] and float
// RGBA colours of alpha `alpha`, depth 4.
struct VolumeScene
{
  std::vector<double> xyz;
  std::vector<float> rgba, scalar;
  PointCloudView View() const
  {
    PointCloudView v;
    v.count = scalar.size();
    v.xyzDouble = xyz.data();
    v.colorFloat = rgba.data();
    v.colorComponents = 4;
    v.scalar = scalar.data();
    return v;
  }
};

VolumeScene UniformVolume(float alpha)
{
  VolumeScene s;
  std::mt19937_64 rng(47);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 300; ++i)
  {
    s.xyz.insert(s.xyz.end(), { u(rng), u(rng), u(rng) });
    s.rgba.insert(s.rgba.end(), { float(u(rng)), float(u(rng)), float(u(rng)), alpha });
    s.scalar.push_back(float(u(rng)));
  }
  return s;
}

// Composite settings over the scene: with a transfer function of opacity
// `alpha` (colour ramp on the scalar), or with none (the points' RGBA).
RenderSettings CompositeSettings(const Matrix& vp, int w, int h, bool transfer, float alpha)
{
  RenderSettings s = Settings(vp, w, h);
  s.blend = BlendMode::Composite;
  s.opacityUnitDistance = 0.1f;
  if (transfer)
  {
    s.transfer.range[0] = 0;
    s.transfer.range[1] = 1;
    for (int i = 0; i <= 100; ++i)
    {
      const float v = i / 100.0f;
      s.transfer.table.push_back(Rgba{ v, 1 - v, 0.5f, alpha });
    }
  }
  return s;
}

// The transfer function's entry for a scalar, in double.
const Rgba& TableEntry(const TransferFunction& tf, double value)
{
  double u = (value - tf.range[0]) / (tf.range[1] - tf.range[0]);
  u = std::min(1.0, std::max(0.0, u));
  return tf.table[std::size_t(u * (tf.table.size() - 1) + 0.5)];
}

const double kVolumeEye[3] = { 2.2, -1.6, 1.5 }, kVolumeTarget[3] = { 0.5, 0.5, 0.5 };
}

TEST_P(Stability, OpacityZeroEverywhere)
{
  // Opacity 0 through the transfer function, then through the points'
  // alpha: the composite picture is empty, every channel exactly 0.
  const int w = 40, h = 40;
  const Matrix vp = ViewProjection(kVolumeEye, kVolumeTarget, kZUp, 40, 1.0, 0.5, 8);
  std::string outcome;
  for (bool transfer : { true, false })
  {
    SCOPED_TRACE(transfer ? "transfer function" : "point RGBA");
    engine->Build(UniformVolume(transfer ? 1.0f : 0.0f).View(), UnitCubeOptions(4));
    HostOctree t;
    engine->CopyToHost(t);
    const Image image = RenderChecked(*engine, CompositeSettings(vp, w, h, transfer, 0.0f));
    int crossing = 0, nonZero = 0, depthWritten = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
      {
        const std::size_t i = Pixel(image, x, y);
        crossing += BruteForceFirstHit(t, vp, w, h, x, y).hit;
        bool zero = true;
        for (int k = 0; k < 4; ++k)
          zero = zero && image.rgba[4 * i + k] == 0.0f;
        nonZero += !zero;
        depthWritten += image.depth[i] < 1.0f;
      }
    outcome += Format("%s%s: %d of %d pixels not exactly 0 (%d rays cross voxels; %d pixels carry the first "
                      "voxel's depth under alpha 0)",
      outcome.empty() ? "" : "; ", transfer ? "transfer function" : "point alpha", nonZero, w * h, crossing,
      depthWritten);
    EXPECT_EQ(nonZero, 0);
    EXPECT_GT(crossing, 300);
  }
  Record("composite blend, opacity 0 from the transfer function and from the points' RGBA alpha: every pixel's "
         "RGBA exactly 0",
    outcome);
}

TEST_P(Stability, OpacityOneEverywhere)
{
  // Opacity 1 through the transfer function, then through the points'
  // alpha: the composite picture is the first voxel each ray touches, its
  // colour at alpha 1, at its depth.
  const int w = 40, h = 40;
  const Matrix vp = ViewProjection(kVolumeEye, kVolumeTarget, kZUp, 40, 1.0, 0.5, 8);
  std::string outcome;
  for (bool transfer : { true, false })
  {
    SCOPED_TRACE(transfer ? "transfer function" : "point RGBA");
    engine->Build(UniformVolume(transfer ? 0.0f : 1.0f).View(), UnitCubeOptions(4));
    HostOctree t;
    engine->CopyToHost(t);
    const RenderSettings settings = CompositeSettings(vp, w, h, transfer, 1.0f);
    const Image image = RenderChecked(*engine, settings);
    // What the first voxel should show: the transfer function's entry for
    // its scalar (in double), or its own colour.
    std::vector<Rgba> colours;
    for (std::size_t n = 0; n < t.color.size(); ++n)
      colours.push_back(transfer ? TableEntry(settings.transfer, t.Scalar(n)) : t.color[n]);
    const HitComparison c = CompareWithFirstHits(image, t, vp, 1e-6, &colours);
    int notOpaque = 0;
    for (std::size_t i = 0; i < image.depth.size(); ++i)
      notOpaque += image.rgba[4 * i + 3] != 0.0f && image.rgba[4 * i + 3] != 1.0f;
    outcome += Format("%s%s: %s; %d pixels of alpha other than 0 or 1", outcome.empty() ? "" : "; ",
      transfer ? "transfer function" : "point alpha", c.Summary().c_str(), notOpaque);
    ExpectAgreement(c, 300);
    EXPECT_EQ(notOpaque, 0);
  }
  Record("composite blend, opacity 1 from the transfer function and from the points' RGBA alpha: the first voxel's "
         "colour at alpha 1, " +
      Format(kFirstHitCheck, 1e-6),
    outcome);
}

// Colours above 1 (HDR) are kept as floats from the input to the picture:
// node averages and flat and Phong shading do not clamp; only the 8-bit
// output (RenderSettings::rgba8) clamps each channel to [0, 1] before
// rounding. Two depth-3 cells under a parallel view down -z: the
// flat picture shows the input colours exactly, Phong with the headlight
// straight down (n.l = r.v = 1) shows colour x (ambient + diffuse) +
// specular, and 8-bit output is 255 for every channel above 1.
TEST_P(Stability, HdrColours)
{
  Scene s;
  const float hot[3] = { 4.0f, 0.5f, 12.0f }, blazing[3] = { 1000.0f, 1.5f, 0.25f };
  s.AddCell(3, 2, 2, 1, hot);
  s.AddCell(3, 5, 4, 1, blazing);
  engine->Build(s.View(), UnitCubeOptions(3));
  HostOctree t;
  engine->CopyToHost(t);
  const int w = 64, h = 64;
  const double eye[3] = { 0.5, 0.5, 3 }, target[3] = { 0.5, 0.5, 0 };
  const Matrix vp = ViewProjection(eye, target, kYUp, 0, 1.0, 1, 5, true, 0.5);
  RenderSettings settings = Settings(vp, w, h);
  // Pixel (x, y) has its centre at ((x + 0.5) / 64, (y + 0.5) / 64): cell
  // (i, j) at depth 3 is the pixels [8i, 8i + 8) x [8j, 8j + 8).
  auto cellColour = [&](int x, int y) -> const float* {
    if (x / 8 == 2 && y / 8 == 2)
      return hot;
    if (x / 8 == 5 && y / 8 == 4)
      return blazing;
    return nullptr;
  };
  const Image flat = RenderChecked(*engine, settings);
  settings.shade = ShadeMode::Phong;
  const Image phong = RenderChecked(*engine, settings);
  settings.shade = ShadeMode::Flat;
  settings.rgba8 = true;
  Image bytes;
  engine->Render(settings, bytes);
  ASSERT_EQ(bytes.rgba8.size(), 4u * w * h);
  int covered = 0, flatWrong = 0, phongWrong = 0, byteWrong = 0;
  float brightest = 0;
  double worstPhong = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const std::size_t i = Pixel(flat, x, y);
      const float* c = cellColour(x, y);
      if (!c)
      {
        EXPECT_EQ(flat.rgba[4 * i + 3], 0.0f);
        continue;
      }
      ++covered;
      for (int k = 0; k < 3; ++k)
      {
        brightest = std::max(brightest, flat.rgba[4 * i + k]);
        flatWrong += flat.rgba[4 * i + k] != c[k];
        // Phong: ambient 0.1, diffuse 0.7, specular 0.2 (the defaults).
        const double lit = c[k] * (0.1 + 0.7) + 0.2;
        const double err = std::fabs(phong.rgba[4 * i + k] - lit) / lit;
        worstPhong = std::max(worstPhong, err);
        phongWrong += err > 1e-6;
        const std::uint8_t expected = c[k] >= 1.0f ? 255 : std::uint8_t(std::lround(c[k] * 255.0));
        byteWrong += bytes.rgba8[4 * i + k] != expected;
      }
    }
  Record("two cells of colours (4, 0.5, 12) and (1000, 1.5, 0.25) under a parallel view: flat colour equal to the "
         "input (exact), Phong = colour x (ambient + diffuse) + specular (relative 1e-6), 8-bit output 255 for "
         "channels above 1",
    Format("kept as float, not clamped: brightest flat channel %g; %d flat and %d Phong channels wrong (largest "
           "Phong relative error %.1e); 8-bit output clamps: %d bytes wrong, in %d covered pixels",
      double(brightest), flatWrong, phongWrong, worstPhong, byteWrong, covered));
  EXPECT_EQ(covered, 2 * 64);
  EXPECT_EQ(brightest, 1000.0f);
  EXPECT_EQ(flatWrong, 0);
  EXPECT_EQ(phongWrong, 0);
  EXPECT_EQ(byteWrong, 0);
}

INSTANTIATE_TEST_SUITE_P(Backends, Stability, ::testing::Values(Backend::CPU, Backend::CUDA), BackendName);
