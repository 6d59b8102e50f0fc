// octorayLattice.h, the rule that closes a slice stack (shared by
// vtkSliceStackReader and vtkOctreeVolumeMapper), against hand-computed
// cases: how many planes fill a gap, where a sample's value comes from, the
// lattice of an image, the leaf grid (leaf size, alignment, depth, every
// leaf inside the solid holding a lattice point) and the check that points
// are on their lattice.
#include <octorayLattice.h>
#include <octorayTestCheck.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <set>
#include <tuple>
#include <vector>

namespace
{
using namespace octoray::lattice;

std::vector<int> Fill(double sx, double sy, double sz, long long nx = 10, long long ny = 10, long long nz = 10)
{
  const double step[3] = { sx, sy, sz };
  const long long count[3] = { nx, ny, nz };
  int fill[3];
  FillFactors(step, count, fill);
  return { fill[0], fill[1], fill[2] };
}

// Every leaf of `grid` whose cube lies inside the lattice's box holds a
// lattice point: the leaves of all lattice points, against all leaves of
// the box.
bool Closed(const Lattice& l, const LeafGrid& grid)
{
  const double leaf = grid.LeafSize();
  std::set<std::tuple<long long, long long, long long>> occupied;
  double lo[3] = { 1e300, 1e300, 1e300 }, hi[3] = { -1e300, -1e300, -1e300 };
  for (long long k = 0; k < l.Count[2]; ++k)
  {
    for (long long j = 0; j < l.Count[1]; ++j)
    {
      for (long long i = 0; i < l.Count[0]; ++i)
      {
        double p[3];
        l.Position(i, j, k, p);
        long long cell[3];
        for (int a = 0; a < 3; ++a)
        {
          cell[a] = static_cast<long long>(std::floor((p[a] - grid.Origin[a]) / leaf));
          lo[a] = std::min(lo[a], p[a]);
          hi[a] = std::max(hi[a], p[a]);
        }
        occupied.insert({ cell[0], cell[1], cell[2] });
      }
    }
  }
  // Leaves wholly inside the points' box (for an axis-aligned lattice, the
  // solid).
  long long first[3], last[3];
  for (int a = 0; a < 3; ++a)
  {
    first[a] = static_cast<long long>(std::ceil((lo[a] - grid.Origin[a]) / leaf));
    last[a] = static_cast<long long>(std::floor((hi[a] - grid.Origin[a]) / leaf)) - 1;
  }
  for (long long z = first[2]; z <= last[2]; ++z)
  {
    for (long long y = first[1]; y <= last[1]; ++y)
    {
      for (long long x = first[0]; x <= last[0]; ++x)
      {
        if (!occupied.count({ x, y, z }))
        {
          return false;
        }
      }
    }
  }
  return true;
}

double Bounds(const Lattice& l, double b[6])
{
  for (int a = 0; a < 3; ++a)
  {
    b[2 * a] = 1e300;
    b[2 * a + 1] = -1e300;
  }
  for (long long k : { 0LL, l.Count[2] - 1 })
  {
    for (long long j : { 0LL, l.Count[1] - 1 })
    {
      for (long long i : { 0LL, l.Count[0] - 1 })
      {
        double p[3];
        l.Position(i, j, k, p);
        for (int a = 0; a < 3; ++a)
        {
          b[2 * a] = std::min(b[2 * a], p[a]);
          b[2 * a + 1] = std::max(b[2 * a + 1], p[a]);
        }
      }
    }
  }
  return 0;
}
}

int TestOctreeLattice(int, char*[])
{
  // ---- How many planes fill a gap: the coarsest axis down to the
  // second-coarsest spacing.
  CHECK((Fill(0.9570312, 0.9570312, 1.5) == std::vector<int>{ 1, 1, 2 })); // the head CT
  CHECK((Fill(1, 1, 3) == std::vector<int>{ 1, 1, 3 }));
  CHECK((Fill(1, 1, 3.0000000001) == std::vector<int>{ 1, 1, 3 })); // rounding is not a gap
  CHECK((Fill(0.5, 1, 3) == std::vector<int>{ 1, 1, 3 }));         // to the coarser pixel spacing
  CHECK((Fill(0.488281, 0.488281, 2.5) == std::vector<int>{ 1, 1, 6 }));
  CHECK((Fill(3, 1, 1) == std::vector<int>{ 3, 1, 1 })); // any axis
  CHECK((Fill(1, 1, 1) == std::vector<int>{ 1, 1, 1 }));
  CHECK((Fill(1, 1, 0.5) == std::vector<int>{ 1, 1, 1 }));
  CHECK((Fill(1, 1, 1000) == std::vector<int>{ 1, 1, kMaxFill })); // a spacing typed wrong
  CHECK((Fill(1, 1, 3, 10, 10, 1) == std::vector<int>{ 1, 1, 1 }));  // one slice: no gap
  CHECK((Fill(1, 5, 3, 10, 1, 10) == std::vector<int>{ 1, 1, 3 }));  // an axis of one sample does not count
  CHECK((Fill(1, 1, std::nan(""), 10, 10, 10) == std::vector<int>{ 1, 1, 1 }));

  // ---- Samples: source position and interpolation.
  {
    Axis z;
    z.First = 2;
    z.Stride = 2;
    z.Count = 3; // source slices 2, 4, 6
    z.Fill = 4;  // samples every half slice
    CHECK(z.Samples() == 9);
    long long below;
    double t;
    z.Source(0, below, t);
    CHECK(below == 2 && t == 0.0);
    z.Source(1, below, t);
    CHECK(below == 2 && t == 0.5);
    z.Source(3, below, t);
    CHECK(below == 3 && t == 0.5); // between the real slices 3 and 4, not 2 and 4
    z.Source(8, below, t);
    CHECK(below == 6 && t == 0.0);

    // 2 x 1 pixels, 3 slices of values 10 * k + i; fill 2 along z.
    const float data[] = { 0, 1, 10, 11, 20, 21 };
    const long long dims[3] = { 2, 1, 3 };
    Axis axes[3];
    axes[0].Count = 2;
    axes[1].Count = 1;
    axes[2].Count = 3;
    axes[2].Fill = 2;
    std::vector<double> got;
    double values[1];
    for (long long r = 0; r < axes[2].Samples(); ++r)
    {
      ForEachSampleInPlane(axes, data, dims, 1, r, values, [&](long long, long long, const double* v) { got.push_back(v[0]); });
    }
    CHECK((got == std::vector<double>{ 0, 1, 5, 6, 10, 11, 15, 16, 20, 21 }));
    // Fill along x too: bilinear.
    axes[0].Fill = 2;
    got.clear();
    ForEachSampleInPlane(axes, data, dims, 1, 1, values, [&](long long, long long, const double* v) { got.push_back(v[0]); });
    CHECK((got == std::vector<double>{ 5, 5.5, 6 }));
  }

  // ---- The lattice of an image and its leaf grid.
  {
    // The head CT: 256 x 256 x 108, 0.957 x 0.957 x 1.5 mm, filled to 0.75.
    Axis axes[3];
    const long long dims[3] = { 256, 256, 108 };
    const double spacing[3] = { 0.9570312, 0.9570312, 1.5 };
    const double origin[3] = { -122.021478, -122.021478, 0.0 };
    const double identity[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
    int fill[3];
    FillFactors(spacing, dims, fill);
    for (int a = 0; a < 3; ++a)
    {
      axes[a].Count = dims[a];
      axes[a].Fill = fill[a];
    }
    const Lattice l = LatticeOf(axes, origin, spacing, identity);
    CHECK(l.Count[2] == 215 && std::abs(l.Step[2][2] - 0.75) < 1e-12);
    double b[6];
    Bounds(l, b);
    const LeafGrid grid = ChooseLeafGrid(l, b);
    CHECK(grid.Valid);
    CHECK(std::abs(grid.LeafSize() - 0.9570312) < 1e-12); // the pixel
    CHECK(grid.Depth == 8);
    // Leaf centres on the pixel columns: the corner half a pixel before one.
    const double phase = (origin[0] - grid.Origin[0]) / grid.LeafSize();
    CHECK(std::abs(phase - std::round(phase) - 0.5) < 1e-9 || std::abs(phase - std::round(phase) + 0.5) < 1e-9);
    for (int a = 0; a < 3; ++a)
    {
      CHECK(grid.Origin[a] <= b[2 * a] && b[2 * a + 1] < grid.Origin[a] + grid.Size);
    }
    double tuple[kFieldArrayComponents];
    ToTuple(l, tuple);
    const Lattice back = FromTuple(tuple);
    CHECK(back.Count[0] == 256 && back.Count[2] == 215 && back.Step[2][2] == l.Step[2][2]);
    double p[3];
    l.Position(17, 200, 33, p);
    CHECK(OnLattice(l, p));
    p[2] += 0.3;
    CHECK(!OnLattice(l, p));
    l.Position(255, 0, 214, p);
    CHECK(OnLattice(l, p));
    p[0] += 0.9570312; // one past the last column
    CHECK(!OnLattice(l, p));
  }
  {
    // Sizes that are not powers of two, unfilled and filled, a flipped axis
    // (DICOM's LPS directions): closed every time.
    for (const double sz : { 1.0, 1.7, 3.0, 4.9 })
    {
      for (const bool filled : { false, true })
      {
        Axis axes[3];
        const long long dims[3] = { 23, 15, 9 };
        const double spacing[3] = { 1.0, 1.0, sz };
        const double origin[3] = { 0.31, -7.2, 100.05 };
        const double flipped[9] = { -1, 0, 0, 0, 1, 0, 0, 0, -1 };
        int fill[3] = { 1, 1, 1 };
        if (filled)
        {
          FillFactors(spacing, dims, fill);
        }
        for (int a = 0; a < 3; ++a)
        {
          axes[a].Count = dims[a];
          axes[a].Fill = fill[a];
        }
        const Lattice l = LatticeOf(axes, origin, spacing, flipped);
        double b[6];
        Bounds(l, b);
        const LeafGrid grid = ChooseLeafGrid(l, b);
        CHECK(grid.Valid);
        CHECK(std::abs(grid.LeafSize() - (filled ? 1.0 : std::max(1.0, sz))) < 1e-12);
        CHECK(Closed(l, grid));
      }
    }
  }
  {
    // An oblique lattice: leaves as large as a cell's diagonal; direction
    // cosines with a little noise (written with a few digits) still count
    // as aligned.
    Axis axes[3];
    const long long dims[3] = { 12, 10, 8 };
    const double spacing[3] = { 1.0, 1.0, 1.0 };
    const double origin[3] = { 0, 0, 0 };
    const double c = std::cos(0.5), s = std::sin(0.5);
    const double turned[9] = { c, -s, 0, s, c, 0, 0, 0, 1 };
    for (int a = 0; a < 3; ++a)
    {
      axes[a].Count = dims[a];
    }
    Lattice l = LatticeOf(axes, origin, spacing, turned);
    double b[6];
    Bounds(l, b);
    LeafGrid grid = ChooseLeafGrid(l, b);
    CHECK(grid.Valid && std::abs(grid.LeafSize() - std::sqrt(3.0)) < 1e-12);
    const double noisy[9] = { 1, 1e-6, 0, -1e-6, 1, 0, 0, 0, 1 };
    l = LatticeOf(axes, origin, spacing, noisy);
    Bounds(l, b);
    grid = ChooseLeafGrid(l, b);
    CHECK(grid.Valid && std::abs(grid.LeafSize() - 1.0) < 1e-9);
    CHECK(Closed(l, grid));
  }
  {
    // One point, or too many levels: no grid (the engine chooses).
    Lattice l;
    l.Step[0][0] = l.Step[1][1] = l.Step[2][2] = 1;
    const double b[6] = { 0, 0, 0, 0, 0, 0 };
    CHECK(!ChooseLeafGrid(l, b).Valid);
    l.Count[0] = l.Count[1] = l.Count[2] = 2;
    l.Step[0][0] = l.Step[1][1] = l.Step[2][2] = 1e-6;
    const double wide[6] = { 0, 1e6, 0, 1, 0, 1 }; // 10^12 leaves across
    CHECK(!ChooseLeafGrid(l, wide).Valid);
  }
  return octoray_test::Result();
}
