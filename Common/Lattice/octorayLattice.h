// Slice stacks as closed volumes: the one rule that vtkSliceStackReader (its
// particles) and vtkOctreeVolumeMapper (a vtkImageData input) both follow.
// VTK-free and header-only.
//
// The problem. The points of a slice stack lie on a lattice: one point per
// pixel, pixels `sx` x `sy` apart within a slice, slices `sz` apart, and `sz`
// is often 1.5 to 5 times `sx`. An octree leaf is a cube. Leaves about the
// pixel size leave empty layers between the slices, which show as see-through
// gaps wherever a ray runs between two slices; leaves as large as the slice
// spacing close the volume but blur each slice to a few pixels per leaf. And
// the engine's own choice of the leaf level (octoray/DepthChoice.h: the
// median leaf holds one point) is made for scattered points: on a lattice
// whose size is not a power of two it often picks leaves a little smaller
// than the lattice step, and then even a stack of equally spaced pixels
// shows empty layers, in any axis.
//
// The rule, in two parts:
//
// 1. Fill (FillFactors, Axis, ForEachSampleInPlane). Between two
//    neighbouring slices, planes of points are added whose values are
//    interpolated linearly from the two slices, so that the points are no
//    farther apart along the slice axis than across it: the coarsest axis is
//    filled down to the second-coarsest spacing (for a stack: the pixel
//    spacing; in an image any axis may be the coarsest). The background test
//    then applies to the interpolated values, so the surface of an object
//    lies where the interpolated intensity crosses the threshold, as in a ray
//    caster that samples trilinearly. Samples on a slice keep the slice's
//    values exactly. Both shade by the same gradient (GradientNormal).
// 2. Leaf grid (ChooseLeafGrid). Given the lattice of the points (origin,
//    step vectors, counts), the root cube and leaf level are chosen so that
//    no leaf inside the solid is empty: leaves exactly as large as the
//    largest step and, where the lattice runs along the world axes, centred
//    on its planes (a leaf then holds exactly one point along the axis of
//    the largest step and at least one along the others); where it is
//    oblique, as large as a lattice cell's diagonal. The mapper uses it for
//    image input, and for point sets that carry their lattice in the
//    field-data array kFieldArrayName (the reader's particles), when its
//    LeafDepth is 0 (automatic).
//
// Why both. Filling alone is not enough: the engine's own leaf choice may
// still give leaves a little smaller than the pixel, with gaps in any axis.
// The leaf grid alone closes the volume only with leaves as large as the
// slice spacing, blurring each slice to a few pixels per leaf. Together they
// give leaves of the pixel size and a closed volume, for about
// (slice spacing / pixel spacing) times the points. Without filling
// (FillBetweenSlices off) the leaf grid still closes the volume, with leaves
// as large as the slice spacing. The engine is unchanged: the mapper passes
// the depth and a fixed root cube (octoray::BuildOptions).
#ifndef octorayLattice_h
#define octorayLattice_h

#include <algorithm>
#include <cmath>
#include <vector>

namespace octoray
{
namespace lattice
{
// At most this many planes per interval between two slices (a spacing typed
// wrong by a factor of 1000 must not make a billion points); past it the leaf
// grid still closes the volume, with larger leaves.
constexpr int kMaxFill = 32;

// ---------------------------------------------------------------------------
// 1. Filling.

/**
 * How many sub-steps each axis gets: `step` is the distance between
 * neighbouring selected samples along each axis (spacing times stride),
 * `count` the number of selected samples. Of the axes with more than one
 * sample, those whose step is larger than the second-largest step (the
 * coarsest axis, unless two tie) get fill = ceil(step / that), at most
 * kMaxFill; the others get 1.
 */
inline void FillFactors(const double step[3], const long long count[3], int fill[3])
{
  double steps[3];
  int active = 0;
  for (int a = 0; a < 3; ++a)
  {
    fill[a] = 1;
    if (count[a] > 1 && std::isfinite(step[a]) && std::abs(step[a]) > 0)
    {
      steps[active++] = std::abs(step[a]);
    }
  }
  if (active < 2)
  {
    return;
  }
  std::sort(steps, steps + active);
  const double target = steps[active - 2];
  for (int a = 0; a < 3; ++a)
  {
    if (count[a] > 1 && std::isfinite(step[a]) && std::abs(step[a]) > target)
    {
      // The tolerance keeps 3.0000000001 / 1 at 3.
      const double n = std::ceil(std::abs(step[a]) / target * (1.0 - 1e-9));
      fill[a] = static_cast<int>(std::min<double>(kMaxFill, std::max(1.0, n)));
    }
  }
}

/**
 * The samples along one index axis: the selected source samples First,
 * First + Stride, ..., Count of them, and Fill samples per interval between
 * two of them (1: the source samples only).
 */
struct Axis
{
  long long First = 0;
  long long Stride = 1;
  long long Count = 1;
  int Fill = 1;

  long long Samples() const { return this->Count > 1 ? (this->Count - 1) * this->Fill + 1 : this->Count; }

  // Source position of sample r: First + r * Stride / Fill, as the source
  // index at or below it and the weight (0 <= t < 1) of the index above.
  void Source(long long r, long long& below, double& t) const
  {
    const long long num = r * this->Stride;
    below = this->First + num / this->Fill;
    t = static_cast<double>(num % this->Fill) / this->Fill;
  }
};

/**
 * Sets each axis's Fill from the source's spacing and the axes' Stride and
 * Count (FillFactors of the selected samples' steps): how the reader's
 * particles and the mapper's images both fill between slices.
 */
inline void FillAxes(const double spacing[3], Axis axes[3])
{
  double step[3];
  long long count[3];
  for (int a = 0; a < 3; ++a)
  {
    step[a] = spacing[a] * static_cast<double>(axes[a].Stride);
    count[a] = axes[a].Count;
  }
  int fill[3];
  FillFactors(step, count, fill);
  for (int a = 0; a < 3; ++a)
  {
    axes[a].Fill = fill[a];
  }
}

/**
 * An image's samples: its points, or with `cells` its cells (one fewer
 * along each axis that has cells, at their centres). Gives how many lie
 * along each index axis and where the first lies: the extent's first index
 * through the image's index-to-physical map, which is at its Origin only
 * where the extent starts at 0 (not for the Wavelet source's -10..10, nor
 * for the pieces of an image split over ranks). `Image` is vtkImageData; a
 * template, so that this header needs no VTK.
 */
template <class Image>
void ImageSamples(Image* image, bool cells, int dims[3], double first[3])
{
  image->GetDimensions(dims);
  const int* extent = image->GetExtent();
  double index[3] = { static_cast<double>(extent[0]), static_cast<double>(extent[2]),
    static_cast<double>(extent[4]) };
  for (int a = 0; a < 3 && cells; ++a)
  {
    if (dims[a] > 1)
    {
      --dims[a];
      index[a] += 0.5;
    }
  }
  image->TransformContinuousIndexToPhysicalPoint(index, first);
}

/**
 * Every sample of plane `r2` (a sample index along axis 2), row by row:
 * visit(r0, r1, values), `values` (the caller's buffer of `comps` doubles)
 * holding the components interpolated from the source: `data` holds
 * dims[0] x dims[1] x dims[2] samples of `comps` interleaved components,
 * axis 0 fastest. Linear along each axis whose sample falls between two
 * source samples (bi- or trilinear where several do); a sample on a source
 * sample gets its values exactly.
 */
template <typename T, typename Visit>
void ForEachSampleInPlane(const Axis axes[3], const T* data, const long long dims[3], int comps, long long r2,
  double* values, Visit&& visit)
{
  struct Tap
  {
    long long Offset;
    double Weight;
  };
  auto taps = [&](int a, long long r, long long stride, Tap out[2]) {
    long long below;
    double t;
    axes[a].Source(r, below, t);
    out[0] = { below * stride, 1.0 - t };
    if (t == 0.0)
    {
      return 1;
    }
    out[1] = { (below + 1) * stride, t };
    return 2;
  };
  const long long strideX = comps;
  const long long strideY = strideX * dims[0];
  const long long strideZ = strideY * dims[1];
  const long long nx = axes[0].Samples(), ny = axes[1].Samples();
  std::vector<Tap> rowTaps(static_cast<size_t>(2 * nx));
  std::vector<int> rowTapCount(static_cast<size_t>(nx));
  for (long long r0 = 0; r0 < nx; ++r0)
  {
    rowTapCount[r0] = taps(0, r0, strideX, &rowTaps[2 * r0]);
  }
  Tap tz[2];
  const int nz = taps(2, r2, strideZ, tz);
  for (long long r1 = 0; r1 < ny; ++r1)
  {
    Tap ty[2];
    const int nyCount = taps(1, r1, strideY, ty);
    Tap tyz[4];
    int nyz = 0;
    for (int a = 0; a < nz; ++a)
    {
      for (int b = 0; b < nyCount; ++b)
      {
        tyz[nyz++] = { tz[a].Offset + ty[b].Offset, tz[a].Weight * ty[b].Weight };
      }
    }
    for (long long r0 = 0; r0 < nx; ++r0)
    {
      const Tap* tx = &rowTaps[2 * r0];
      const int nxCount = rowTapCount[r0];
      if (nxCount == 1 && nyz == 1)
      {
        const T* p = data + tx[0].Offset + tyz[0].Offset;
        for (int c = 0; c < comps; ++c)
        {
          values[c] = static_cast<double>(p[c]);
        }
      }
      else if (nxCount == 1 && nyz == 2)
      {
        // The usual case: between two slices.
        const T* p = data + tx[0].Offset + tyz[0].Offset;
        const T* q = data + tx[0].Offset + tyz[1].Offset;
        const double wp = tyz[0].Weight, wq = tyz[1].Weight;
        for (int c = 0; c < comps; ++c)
        {
          values[c] = wp * static_cast<double>(p[c]) + wq * static_cast<double>(q[c]);
        }
      }
      else
      {
        std::fill(values, values + comps, 0.0);
        for (int a = 0; a < nyz; ++a)
        {
          for (int b = 0; b < nxCount; ++b)
          {
            const double w = tyz[a].Weight * tx[b].Weight;
            const T* p = data + tx[b].Offset + tyz[a].Offset;
            for (int c = 0; c < comps; ++c)
            {
              values[c] += w * static_cast<double>(p[c]);
            }
          }
        }
      }
      visit(r0, r1, static_cast<const double*>(values));
    }
  }
}

/**
 * The normal of the one-component field `data` (as ForEachSampleInPlane
 * reads it; component 0 where `comps` is more) at sample (r[0], r[1], r[2]):
 * the gradient by central differences (one-sided at the border) at the
 * source samples around it, interpolated with the sample's weights, through
 * the row-major `direction` matrix, negated and made unit length, so that it
 * points out of the denser material; (0, 0, 0) where the field is flat. VTK's
 * volume mappers shade by the same gradient. The octree mapper's image input
 * and the slice-stack reader's particles take their normals from here.
 */
template <typename T>
void GradientNormal(const T* data, int comps, const long long dims[3], const Axis axes[3], const double spacing[3],
  const double* direction, const long long r[3], float normal[3])
{
  long long below[3];
  double t[3];
  for (int a = 0; a < 3; ++a)
  {
    axes[a].Source(r[a], below[a], t[a]);
  }
  const long long stride[3] = { comps, comps * dims[0], comps * dims[0] * dims[1] };
  double g[3] = { 0.0, 0.0, 0.0 };
  for (int corner = 0; corner < 8; ++corner)
  {
    double weight = 1.0;
    long long at[3];
    for (int a = 0; a < 3; ++a)
    {
      const bool up = (corner >> a) & 1;
      weight *= up ? t[a] : 1.0 - t[a];
      at[a] = std::min(below[a] + (up ? 1 : 0), dims[a] - 1);
    }
    if (weight <= 0.0)
    {
      continue;
    }
    const long long id = at[0] * stride[0] + at[1] * stride[1] + at[2] * stride[2];
    for (int a = 0; a < 3; ++a)
    {
      if (dims[a] < 2 || spacing[a] == 0.0)
      {
        continue;
      }
      const long long lo = at[a] > 0 ? id - stride[a] : id;
      const long long hi = at[a] + 1 < dims[a] ? id + stride[a] : id;
      const double steps = (at[a] > 0 && at[a] + 1 < dims[a]) ? 2.0 : 1.0;
      g[a] += weight * (static_cast<double>(data[hi]) - static_cast<double>(data[lo])) / (steps * spacing[a]);
    }
  }
  double world[3];
  for (int row = 0; row < 3; ++row)
  {
    world[row] = direction[3 * row] * g[0] + direction[3 * row + 1] * g[1] + direction[3 * row + 2] * g[2];
  }
  const double length = std::sqrt(world[0] * world[0] + world[1] * world[1] + world[2] * world[2]);
  for (int a = 0; a < 3; ++a)
  {
    normal[a] = length > 0.0 ? static_cast<float>(-world[a] / length) : 0.0f;
  }
}

// ---------------------------------------------------------------------------
// 2. The lattice and its leaf grid.

/**
 * Points at Origin + r0 * Step[0] + r1 * Step[1] + r2 * Step[2] (world
 * coordinates) for integers 0 <= ra < Count[a].
 */
struct Lattice
{
  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Step[3][3] = { { 0.0, 0.0, 0.0 }, { 0.0, 0.0, 0.0 }, { 0.0, 0.0, 0.0 } };
  long long Count[3] = { 1, 1, 1 };

  void Position(long long r0, long long r1, long long r2, double p[3]) const
  {
    for (int w = 0; w < 3; ++w)
    {
      p[w] = this->Origin[w] + static_cast<double>(r0) * this->Step[0][w] +
        static_cast<double>(r1) * this->Step[1][w] + static_cast<double>(r2) * this->Step[2][w];
    }
  }
};

/**
 * The lattice of the samples of `axes` over an image: where its first
 * sample lies, its spacing per index axis and its direction matrix
 * (row-major; index axis a runs along column a), as vtkImageData has them.
 * The first sample is the data array's first value: for a vtkImageData
 * ImageSamples's `first`.
 */
inline Lattice LatticeOf(const Axis axes[3], const double first[3], const double spacing[3], const double direction[9])
{
  Lattice l;
  for (int w = 0; w < 3; ++w)
  {
    l.Origin[w] = first[w];
    for (int a = 0; a < 3; ++a)
    {
      l.Origin[w] += direction[3 * w + a] * (static_cast<double>(axes[a].First) * spacing[a]);
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    for (int w = 0; w < 3; ++w)
    {
      l.Step[a][w] = direction[3 * w + a] * spacing[a] * static_cast<double>(axes[a].Stride) / axes[a].Fill;
    }
    l.Count[a] = axes[a].Samples();
  }
  return l;
}

/**
 * A point set carries its lattice to the mapper in a field-data array of
 * this name: one tuple of 15 doubles, Origin (3), Step[0], Step[1], Step[2]
 * (3 each) and Count (3).
 */
constexpr const char* kFieldArrayName = "PointLattice";
constexpr int kFieldArrayComponents = 15;

inline void ToTuple(const Lattice& l, double tuple[kFieldArrayComponents])
{
  std::copy(l.Origin, l.Origin + 3, tuple);
  for (int a = 0; a < 3; ++a)
  {
    std::copy(l.Step[a], l.Step[a] + 3, tuple + 3 + 3 * a);
    tuple[12 + a] = static_cast<double>(l.Count[a]);
  }
}

inline Lattice FromTuple(const double tuple[kFieldArrayComponents])
{
  Lattice l;
  std::copy(tuple, tuple + 3, l.Origin);
  for (int a = 0; a < 3; ++a)
  {
    std::copy(tuple + 3 + 3 * a, tuple + 6 + 3 * a, l.Step[a]);
    l.Count[a] = std::isfinite(tuple[12 + a]) && tuple[12 + a] >= 1 ? static_cast<long long>(tuple[12 + a]) : 0;
  }
  return l;
}

namespace detail
{
inline double Length(const double v[3])
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// The world axis a step vector runs closest to.
inline int MainAxis(const double v[3])
{
  int w = 0;
  for (int u = 1; u < 3; ++u)
  {
    w = std::abs(v[u]) > std::abs(v[w]) ? u : w;
  }
  return w;
}
}

/**
 * Whether point p is a lattice point (within `tolerance` of a step along
 * each axis, inside the counts). Used to check that a point set still lies
 * on the lattice its field data names (a filter may have moved the points).
 */
inline bool OnLattice(const Lattice& l, const double p[3], double tolerance = 1e-3)
{
  // Solve M r = p - Origin, M's columns the three step vectors.
  double m[3][3];
  for (int a = 0; a < 3; ++a)
  {
    for (int w = 0; w < 3; ++w)
    {
      m[w][a] = l.Step[a][w];
    }
  }
  const double d[3] = { p[0] - l.Origin[0], p[1] - l.Origin[1], p[2] - l.Origin[2] };
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
    m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  if (!std::isfinite(det) || det == 0.0)
  {
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    // Cramer's rule: column a replaced by d.
    double n[3][3];
    for (int w = 0; w < 3; ++w)
    {
      for (int b = 0; b < 3; ++b)
      {
        n[w][b] = b == a ? d[w] : m[w][b];
      }
    }
    const double r = (n[0][0] * (n[1][1] * n[2][2] - n[1][2] * n[2][1]) -
                       n[0][1] * (n[1][0] * n[2][2] - n[1][2] * n[2][0]) +
                       n[0][2] * (n[1][0] * n[2][1] - n[1][1] * n[2][0])) /
      det;
    const double nearest = std::round(r);
    if (!(std::abs(r - nearest) <= tolerance && nearest >= 0 && nearest <= static_cast<double>(l.Count[a] - 1)))
    {
      return false;
    }
  }
  return true;
}

/**
 * A root cube (minimum corner Origin, side Size) and a leaf level Depth for
 * the octree of points on lattice `l` within `bounds` (xmin, xmax, ymin,
 * ymax, zmin, zmax: the points', or a larger box every rank shares). Valid
 * is false where no such grid exists within maxDepth levels, or for a
 * lattice of fewer than two points along every axis.
 *
 * Along the axes with more than one sample: where every such step vector
 * runs along a world axis, leaves are as large as the largest step, and the
 * cube is placed so that leaf centres lie on the lattice's planes: a leaf
 * then holds exactly one point along the axis of the largest step and at
 * least one along the others, so no leaf inside the solid is empty. Where
 * the lattice is oblique, leaves are as large as a lattice cell's diagonal
 * (a cube of that side always contains a lattice point).
 */
struct LeafGrid
{
  bool Valid = false;
  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Size = 0.0;
  int Depth = 0;
  double LeafSize() const { return this->Size / static_cast<double>(1LL << this->Depth); }
};

namespace detail
{
// The leaf side a lattice asks for, and whether its step vectors run along
// world axes (alongWorld[w]: the lattice axis along world axis w, or -1).
// Leaf 0 where no axis has two samples or a step is not a finite length.
struct LatticeLeaf
{
  double Leaf = 0.0;
  bool Aligned = true;
  int AlongWorld[3] = { -1, -1, -1 };
};

inline LatticeLeaf LeafOf(const Lattice& l)
{
  LatticeLeaf r;
  double diagonal2 = 0.0;
  double drift[3] = { 0.0, 0.0, 0.0 }; // how far the lattice strays from its world axes over its extent
  for (int a = 0; a < 3; ++a)
  {
    if (l.Count[a] < 2)
    {
      continue;
    }
    const double length = Length(l.Step[a]);
    if (!std::isfinite(length) || length <= 0.0)
    {
      return LatticeLeaf();
    }
    r.Leaf = std::max(r.Leaf, length);
    diagonal2 += length * length;
    const int w = MainAxis(l.Step[a]);
    r.Aligned = r.Aligned && r.AlongWorld[w] < 0;
    r.AlongWorld[w] = a;
    for (int u = 0; u < 3; ++u)
    {
      drift[u] += u == w ? 0.0 : std::abs(l.Step[a][u]) * static_cast<double>(l.Count[a] - 1);
    }
  }
  // Direction cosines written with a few digits (DICOM) stray a little:
  // aligned while no point strays a tenth of a leaf from its plane.
  for (int u = 0; u < 3; ++u)
  {
    r.Aligned = r.Aligned && drift[u] <= 0.1 * r.Leaf;
  }
  if (!r.Aligned)
  {
    r.Leaf = std::sqrt(diagonal2);
  }
  return r;
}

// The root cube's corner along world axis w: leaf centres on the lattice's
// planes along it where the lattice is aligned and has an axis there (the
// corner half a leaf before a lattice point, whole leaves before the lowest
// bound); elsewhere the lowest bound centred in a leaf.
inline double CubeCorner(const Lattice& l, const LatticeLeaf& leaf, const double bounds[6], int w)
{
  const double lo = bounds[2 * w];
  if (!(leaf.Aligned && leaf.AlongWorld[w] >= 0))
  {
    return lo - 0.5 * leaf.Leaf;
  }
  const double phase = l.Origin[w] - 0.5 * leaf.Leaf;
  const double corner = phase - leaf.Leaf * std::ceil((phase - lo) / leaf.Leaf);
  return corner > lo ? corner - leaf.Leaf : corner; // rounding
}
}

inline LeafGrid ChooseLeafGrid(const Lattice& l, const double bounds[6], int maxDepth = 21)
{
  LeafGrid grid;
  const detail::LatticeLeaf leaf = detail::LeafOf(l);
  for (int w = 0; w < 3; ++w)
  {
    if (!(std::isfinite(bounds[2 * w]) && std::isfinite(bounds[2 * w + 1]) && bounds[2 * w] <= bounds[2 * w + 1]))
    {
      return grid;
    }
  }
  if (leaf.Leaf <= 0.0)
  {
    return grid;
  }
  for (int w = 0; w < 3; ++w)
  {
    grid.Origin[w] = detail::CubeCorner(l, leaf, bounds, w);
  }
  for (int depth = 1; depth <= maxDepth; ++depth)
  {
    // The cube's side, leaf * 2^depth, must hold every bound strictly
    // inside, with room for rounding (as RootCube::FromBounds pads by 2^-20).
    const double size = std::ldexp(leaf.Leaf, depth);
    bool inside = true;
    for (int w = 0; w < 3; ++w)
    {
      inside = inside && bounds[2 * w + 1] - grid.Origin[w] < size * (1.0 - 0x1p-20);
    }
    if (inside)
    {
      grid.Size = size;
      grid.Depth = depth;
      grid.Valid = true;
      return grid;
    }
  }
  return grid;
}
}
}

#endif
