// The two passes over the sample planes run on vtkSMPTools, not on
// IO/Particles' ParallelChunks: the image is already in memory, the passes
// take a fraction of the time the slices took to read, and no progress or
// abort is reported inside them, which is what ParallelChunks is for (the
// calling thread free to report while workers parse a file, chunks handed
// out in order so that a bad one stops those after it). Counting first and
// writing each plane at its offset keeps plane order with any split of the
// planes, and vtkSMPTools follows the SMP backend and thread count that VTK
// (or ParaView) was set up with.
#include "octoraySliceParticles.h"

#include "octorayVertexCells.h"

#include <octorayLattice.h>

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <type_traits>
#include <vector>

namespace octoray
{
namespace slices
{
namespace
{
using octoray::lattice::Axis;

// Colour channel to 8 bits, by the type's full range (floats: 0..1).
template <typename T>
inline unsigned char ToByte(T v)
{
  if constexpr (std::is_same<T, unsigned char>::value)
  {
    return v;
  }
  else if constexpr (std::is_same<T, unsigned short>::value)
  {
    return static_cast<unsigned char>((static_cast<unsigned>(v) + 128) / 257);
  }
  else if constexpr (std::is_same<T, short>::value)
  {
    return static_cast<unsigned char>(std::clamp((static_cast<int>(v) + 128) / 257, 0, 255));
  }
  else
  {
    return static_cast<unsigned char>(std::lround(std::clamp(static_cast<double>(v), 0.0, 1.0) * 255));
  }
}

// An interpolated colour channel to 8 bits: rounded to the channel's own
// type first, so a sample on a slice gives exactly the slice's byte.
template <typename T>
inline unsigned char InterpolatedToByte(double v)
{
  if constexpr (std::is_integral<T>::value)
  {
    const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
    const double hi = static_cast<double>(std::numeric_limits<T>::max());
    return ToByte(static_cast<T>(std::lround(std::clamp(v, lo, hi))));
  }
  else
  {
    return ToByte(static_cast<T>(v));
  }
}

// Which samples are particles: intensity (grey, or the mean of R, G, B)
// outside the background range, and alpha not 0 (an interpolated alpha is
// 0 only between two transparent pixels).
struct Background
{
  int Comps;
  const double* Range;

  double Intensity(const double* px) const
  {
    return this->Comps >= 3 ? (px[0] + px[1] + px[2]) / 3.0 : px[0];
  }
  bool IsParticle(const double* px) const
  {
    if ((this->Comps == 2 && px[1] == 0) || (this->Comps == 4 && px[3] == 0))
    {
      return false;
    }
    const double v = this->Intensity(px);
    return !(v >= this->Range[0] && v <= this->Range[1]);
  }
};

// The samples of the selected axes over an image's values.
template <typename T>
struct Samples
{
  const T* Data;
  int Comps;
  const Axis* Axes;
  const long long* Dims;
  const double* Spacing;
  const double* Direction; // row-major 3x3

  // The normal of the grey field at sample r (GradientNormal).
  void Normal(long long r0, long long r1, long long r2, float normal[3]) const
  {
    const long long r[3] = { r0, r1, r2 };
    octoray::lattice::GradientNormal(this->Data, this->Comps, this->Dims, this->Axes, this->Spacing,
      this->Direction, r, normal);
  }

  vtkIdType Planes() const { return static_cast<vtkIdType>(this->Axes[2].Samples()); }
  template <typename Visit>
  void ForEachInPlane(vtkIdType plane, Visit&& visit) const
  {
    double values[4];
    octoray::lattice::ForEachSampleInPlane(
      this->Axes, this->Data, this->Dims, this->Comps, plane, values, visit);
  }
};

// The arrays of the particles, allocated for n of them.
struct ParticleArrays
{
  vtkSmartPointer<vtkFloatArray> Points = vtkSmartPointer<vtkFloatArray>::New();
  vtkSmartPointer<vtkFloatArray> Scalars = vtkSmartPointer<vtkFloatArray>::New();
  vtkSmartPointer<vtkUnsignedCharArray> Colors; // colour images only
  vtkSmartPointer<vtkFloatArray> Normals;        // grey images with GradientNormals only

  ParticleArrays(vtkIdType n, bool colour, bool normals)
  {
    this->Points->SetNumberOfComponents(3);
    this->Points->SetNumberOfTuples(n);
    this->Scalars->SetName("Scalars");
    this->Scalars->SetNumberOfTuples(n);
    if (colour)
    {
      this->Colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
      this->Colors->SetName("Colors");
      this->Colors->SetNumberOfComponents(3);
      this->Colors->SetNumberOfTuples(n);
    }
    if (normals)
    {
      this->Normals = vtkSmartPointer<vtkFloatArray>::New();
      this->Normals->SetName("Normals");
      this->Normals->SetNumberOfComponents(3);
      this->Normals->SetNumberOfTuples(n);
    }
  }

  void AttachTo(vtkPolyData* output) const
  {
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetData(this->Points);
    output->SetPoints(points);
    output->GetPointData()->AddArray(this->Scalars);
    if (this->Colors)
    {
      output->GetPointData()->SetScalars(this->Colors);
    }
    else
    {
      output->GetPointData()->SetScalars(this->Scalars);
    }
    if (this->Normals)
    {
      output->GetPointData()->SetNormals(this->Normals);
    }
  }
};

// Pass 1: where each plane's particles start (offsets[plane]; the total at
// offsets[planes]).
template <typename T>
std::vector<vtkIdType> PlaneOffsets(const Samples<T>& samples, const Background& bg)
{
  const vtkIdType nk = samples.Planes();
  std::vector<vtkIdType> counts(nk + 1, 0);
  vtkSMPTools::For(0, nk, [&](vtkIdType b, vtkIdType e) {
    for (vtkIdType s = b; s < e; ++s)
    {
      vtkIdType n = 0;
      samples.ForEachInPlane(
        s, [&](long long, long long, const double* px) { n += bg.IsParticle(px); });
      counts[s + 1] = n;
    }
  });
  std::partial_sum(counts.begin(), counts.end(), counts.begin());
  return counts;
}

// Pass 2: each plane's particles written from its offset on, so that the
// output keeps plane order and needs no locks.
template <typename T>
void WriteParticles(const Samples<T>& samples, const Background& bg,
  const octoray::lattice::Lattice& lattice, const std::vector<vtkIdType>& offsets,
  const ParticleArrays& arrays)
{
  float* p = arrays.Points->GetPointer(0);
  float* sc = arrays.Scalars->GetPointer(0);
  unsigned char* co = arrays.Colors ? arrays.Colors->GetPointer(0) : nullptr;
  float* nm = arrays.Normals ? arrays.Normals->GetPointer(0) : nullptr;
  vtkSMPTools::For(0, samples.Planes(), [&](vtkIdType b, vtkIdType e) {
    for (vtkIdType s = b; s < e; ++s)
    {
      vtkIdType n = offsets[s];
      samples.ForEachInPlane(s, [&](long long r0, long long r1, const double* px) {
        if (!bg.IsParticle(px))
        {
          return;
        }
        double xyz[3];
        lattice.Position(r0, r1, s, xyz);
        for (int a = 0; a < 3; ++a)
        {
          p[3 * n + a] = static_cast<float>(xyz[a]);
        }
        sc[n] = static_cast<float>(bg.Intensity(px));
        if (co)
        {
          for (int c = 0; c < 3; ++c)
          {
            co[3 * n + c] = InterpolatedToByte<T>(px[c]);
          }
        }
        if (nm)
        {
          samples.Normal(r0, r1, s, &nm[3 * n]);
        }
        ++n;
      });
    }
  });
}

template <typename T>
void Extract(const Samples<T>& samples, const Background& bg,
  const octoray::lattice::Lattice& lattice, const ParticleOptions& options, vtkPolyData* output)
{
  const std::vector<vtkIdType> offsets = PlaneOffsets(samples, bg);
  const vtkIdType total = offsets.back();
  const ParticleArrays arrays(total, samples.Comps >= 3, options.GradientNormals && samples.Comps == 1);
  WriteParticles(samples, bg, lattice, offsets, arrays);
  arrays.AttachTo(output);
  if (options.GenerateVertices)
  {
    output->SetVerts(octoray::VertexCells(total));
  }
}

// The samples along each axis: the region of interest (-1: to the edge)
// with its stride and, with filling, the planes between slices so that the
// particles are no farther apart along the slice axis than across it
// (octorayLattice.h). False when the region is empty.
bool SelectAxes(const int dims[3], const double spacing[3], const ParticleOptions& options,
  Axis axes[3])
{
  for (int a = 0; a < 3; ++a)
  {
    const int lo = options.RegionOfInterest[2 * a];
    const int hi = options.RegionOfInterest[2 * a + 1];
    const int first = lo < 0 ? 0 : std::min(lo, dims[a] - 1);
    const int last = hi < 0 ? dims[a] - 1 : std::min(hi, dims[a] - 1);
    if (last < first)
    {
      return false;
    }
    axes[a].First = first;
    axes[a].Stride = std::max(1, options.Stride[a]);
    axes[a].Count = (last - first) / axes[a].Stride + 1;
  }
  if (options.FillBetweenSlices)
  {
    octoray::lattice::FillAxes(spacing, axes);
  }
  return true;
}
} // namespace

//------------------------------------------------------------------------------
std::string ParticleOptionsProblem(const int dims[3], const ParticleOptions& options)
{
  const char* axis[3] = { "x (pixels across)", "y (pixels up)", "z (slices)" };
  for (int a = 0; a < 3; ++a)
  {
    const int lo = options.RegionOfInterest[2 * a], hi = options.RegionOfInterest[2 * a + 1];
    const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
    if (options.Stride[a] < 1)
    {
      return "Stride " + std::to_string(options.Stride[a]) + " on " + axis[a] + ": a stride is at least 1";
    }
    if (lo >= 0 && hi >= 0 && lo > hi)
    {
      return "RegionOfInterest " + range + " on " + axis[a] + ": its minimum lies above its maximum";
    }
    if (lo >= dims[a] || hi >= dims[a])
    {
      return "RegionOfInterest " + range + " on " + axis[a] + " reaches past the stack's " +
        std::to_string(dims[a]) + " (indices 0.." + std::to_string(dims[a] - 1) + "; -1: to the edge)";
    }
  }
  return std::string();
}

//------------------------------------------------------------------------------
void MakeParticles(vtkImageData* image, const ParticleOptions& options, vtkPolyData* output)
{
  int dims[3];
  double first[3];
  octoray::lattice::ImageSamples(image, false, dims, first);
  const double* spacing = image->GetSpacing();
  Axis axes[3];
  if (!SelectAxes(dims, spacing, options, axes))
  {
    output->SetPoints(vtkSmartPointer<vtkPoints>::New());
    return;
  }
  const octoray::lattice::Lattice lattice =
    octoray::lattice::LatticeOf(axes, first, spacing, image->GetDirectionMatrix()->GetData());
  const long long size[3] = { dims[0], dims[1], dims[2] };
  const int comps = image->GetNumberOfScalarComponents();
  const Background bg{ comps, options.BackgroundRange };
  const double* direction = image->GetDirectionMatrix()->GetData();
  switch (image->GetScalarType())
  {
    vtkTemplateMacro(Extract(Samples<VTK_TT>{ static_cast<const VTK_TT*>(image->GetScalarPointer()), comps,
                               axes, size, spacing, direction },
      bg, lattice, options, output));
  }
  // The lattice of the particles, for the octree mapper's leaf grid.
  auto field = vtkSmartPointer<vtkDoubleArray>::New();
  field->SetName(octoray::lattice::kFieldArrayName);
  field->SetNumberOfComponents(octoray::lattice::kFieldArrayComponents);
  field->SetNumberOfTuples(1);
  octoray::lattice::ToTuple(lattice, field->GetPointer(0));
  output->GetFieldData()->AddArray(field);
}
} // namespace slices
} // namespace octoray
