#include "vtkOctreeInputHelper.h"

#include "vtkAbstractMapper.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkMath.h"
#include "vtkOctreeVolumeMapper.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace
{
using ArrayStamp = vtkOctreeInputHelper::ArrayStamp;

ArrayStamp Stamp(vtkAbstractArray* a)
{
  return a ? ArrayStamp{ a, a->GetMTime() } : ArrayStamp{};
}

// The first `components` components of an array as floats (the engine
// takes float attributes): the array's own memory when it is a float array
// of exactly that many components, else a converted copy in `storage`.
const float* FloatComponents(vtkDataArray* array, int components, std::vector<float>& storage)
{
  if (array->GetNumberOfComponents() == components)
  {
    if (auto* f = vtkFloatArray::FastDownCast(array))
    {
      return f->GetPointer(0);
    }
  }
  const vtkIdType n = array->GetNumberOfTuples();
  storage.resize(static_cast<std::size_t>(n) * components);
  for (vtkIdType i = 0; i < n; ++i)
  {
    for (int c = 0; c < components; ++c)
    {
      storage[i * components + c] = static_cast<float>(array->GetComponent(i, c));
    }
  }
  return storage.data();
}

// Positions as the engine takes them: float or double without a copy, any
// other type converted to double in `storage`.
void PositionArrays(vtkDataArray* xyz, const float*& f, const double*& d, std::vector<double>& storage)
{
  f = nullptr;
  d = nullptr;
  if (auto* fa = vtkFloatArray::FastDownCast(xyz))
  {
    f = fa->GetPointer(0);
    return;
  }
  if (auto* da = vtkDoubleArray::FastDownCast(xyz))
  {
    d = da->GetPointer(0);
    return;
  }
  const vtkIdType n = xyz->GetNumberOfTuples();
  storage.resize(3 * static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    xyz->GetTuple(i, &storage[3 * i]);
  }
  d = storage.data();
}
}

//------------------------------------------------------------------------------
vtkOctreeInputHelper::Request vtkOctreeInputHelper::MakeRequest(vtkDataSet* input,
  vtkOctreeVolumeMapper* mapper, vtkVolumeProperty* property, unsigned long engineGeneration)
{
  Request r;
  r.Input = input;
  // The active scalars as the volume property reads them: colours when they
  // have 3 or 4 components and the components are not independent, else
  // component 0 through the transfer functions.
  int cellFlag = 0;
  r.Scalars = vtkAbstractMapper::GetScalars(input, mapper->GetScalarMode(), mapper->GetArrayAccessMode(),
    mapper->GetArrayId(), mapper->GetArrayName(), cellFlag);
  if (r.Scalars && cellFlag)
  {
    r.CellScalars = true;
    r.Scalars = nullptr;
  }
  const int components = r.Scalars ? r.Scalars->GetNumberOfComponents() : 0;
  r.Colours = r.Scalars && !property->GetIndependentComponents() && (components == 3 || components == 4);
  if (vtkPointSet::SafeDownCast(input))
  {
    vtkPointData* pd = input->GetPointData();
    const char* reflectivity = mapper->GetReflectivityArrayName();
    const char* refraction = mapper->GetRefractionArrayName();
    r.Reflectivity = reflectivity ? pd->GetArray(reflectivity) : nullptr;
    r.Refraction = refraction ? pd->GetArray(refraction) : nullptr;
    r.Normals = pd->GetNormals();
    if (r.Normals && r.Normals->GetNumberOfComponents() != 3)
    {
      r.Normals = nullptr;
    }
  }
  r.ImageBackground = mapper->GetImageBackground();
  r.ImageGradientNormals = mapper->GetImageGradientNormals();
  r.LeafDepth = mapper->GetLeafDepth();
  std::copy(mapper->GetRootBounds(), mapper->GetRootBounds() + 6, r.RootBounds.begin());
  r.EngineGeneration = engineGeneration;
  return r;
}

//------------------------------------------------------------------------------
vtkOctreeInputHelper::Signature vtkOctreeInputHelper::Sign(const Request& r)
{
  Signature s;
  s.Input = r.Input;
  s.Count = r.Input->GetNumberOfPoints();
  s.Layout = std::string(r.Colours ? "colours" : (r.Scalars ? "scalars" : "plain")) +
    (r.Reflectivity ? "+reflectivity" : "") + (r.Refraction ? "+refraction" : "") + (r.Normals ? "+normals" : "");
  auto* pointSet = vtkPointSet::SafeDownCast(r.Input);
  if (!pointSet)
  {
    s.Layout += "+image:" + std::to_string(r.ImageBackground) + (r.ImageGradientNormals ? "+gradient" : "");
  }
  s.Arrays = { Stamp(r.Scalars), Stamp(r.Reflectivity), Stamp(r.Refraction), Stamp(r.Normals) };
  // An image's points are its grid: any change of the image is a rebuild.
  s.Points = pointSet ? Stamp(pointSet->GetPoints() ? pointSet->GetPoints()->GetData() : nullptr)
                      : ArrayStamp{ r.Input, r.Input->GetMTime() };
  s.LeafDepth = r.LeafDepth;
  s.RootBounds = r.RootBounds;
  s.EngineGeneration = r.EngineGeneration;
  return s;
}

bool vtkOctreeInputHelper::Signature::SameExceptPoints(const Signature& o) const
{
  return this->Input == o.Input && this->Count == o.Count && this->Layout == o.Layout &&
    this->Arrays == o.Arrays && this->LeafDepth == o.LeafDepth && this->RootBounds == o.RootBounds &&
    this->EngineGeneration == o.EngineGeneration;
}

//------------------------------------------------------------------------------
vtkOctreeInputHelper::Change vtkOctreeInputHelper::Compare(const Request& request) const
{
  const Signature next = Sign(request);
  if (!this->Built || !next.SameExceptPoints(this->Current))
  {
    return Change::All;
  }
  if (next.Points == this->Current.Points)
  {
    return Change::None;
  }
  // The same point array, modified in place (an animation): an update.
  const bool samePointArray = vtkPointSet::SafeDownCast(request.Input) && next.Points.Array == this->Current.Points.Array;
  return samePointArray ? Change::Positions : Change::All;
}

//------------------------------------------------------------------------------
void vtkOctreeInputHelper::Remember(const Request& request)
{
  this->Current = Sign(request);
  this->Built = true;
}

//------------------------------------------------------------------------------
octoray::PositionsView vtkOctreeInputHelper::Positions(const Request& request)
{
  auto* pointSet = vtkPointSet::SafeDownCast(request.Input);
  octoray::PositionsView moved;
  moved.count = static_cast<std::size_t>(pointSet->GetNumberOfPoints());
  PositionArrays(pointSet->GetPoints()->GetData(), moved.xyzFloat, moved.xyzDouble, this->Xyz);
  return moved;
}

//------------------------------------------------------------------------------
octoray::PointCloudView vtkOctreeInputHelper::PointCloud(
  const Request& request, const std::function<void(double)>& progress)
{
  octoray::PointCloudView view;
  this->Xyz.clear();
  this->Normal.clear();
  this->Scalar.clear();
  this->Color8.clear();
  this->ColorFloat.clear();
  if (vtkPointSet::SafeDownCast(request.Input))
  {
    this->PointSetView(request, view);
  }
  else
  {
    this->ImageView(request, view, progress);
  }
  this->FindScalarRange(view);
  return view;
}

//------------------------------------------------------------------------------
void vtkOctreeInputHelper::PointSetView(const Request& r, octoray::PointCloudView& view)
{
  auto* pointSet = vtkPointSet::SafeDownCast(r.Input);
  if (!pointSet->GetPoints())
  {
    return;
  }
  view.count = static_cast<std::size_t>(pointSet->GetNumberOfPoints());
  PositionArrays(pointSet->GetPoints()->GetData(), view.xyzFloat, view.xyzDouble, this->Xyz);
  if (r.Colours)
  {
    const int comps = r.Scalars->GetNumberOfComponents();
    view.colorComponents = comps;
    if (auto* uc = vtkUnsignedCharArray::FastDownCast(r.Scalars))
    {
      view.color8 = uc->GetPointer(0);
    }
    else
    {
      // Float or double colours are taken as 0..1 (HDR allowed).
      view.colorFloat = FloatComponents(r.Scalars, comps, this->ColorFloat);
    }
  }
  else if (r.Scalars)
  {
    view.scalar = FloatComponents(r.Scalars, 1, this->Scalar); // component 0
  }
  view.reflectivity = r.Reflectivity ? FloatComponents(r.Reflectivity, 1, this->Reflectivity) : nullptr;
  view.refraction = r.Refraction ? FloatComponents(r.Refraction, 1, this->Refraction) : nullptr;
  view.normal = r.Normals ? FloatComponents(r.Normals, 3, this->Normal) : nullptr;
}

//------------------------------------------------------------------------------
octoray::BuildOptions vtkOctreeInputHelper::Options(const Request& r) const
{
  if (vtkImageData::SafeDownCast(r.Input))
  {
    return Layout(r).Options;
  }
  octoray::BuildOptions options;
  options.depth = r.LeafDepth;
  if (vtkMath::AreBoundsInitialized(r.RootBounds.data()))
  {
    // The caller's cube (e.g. global bounds over parallel ranks): the same
    // voxel grid on every rank.
    const double* b = r.RootBounds.data();
    const double lo[3] = { b[0], b[2], b[4] }, hi[3] = { b[1], b[3], b[5] };
    options.fixedCube = true;
    options.cube = octoray::RootCube::FromBounds(lo, hi);
  }
  return options;
}

//------------------------------------------------------------------------------
vtkOctreeInputHelper::ImageLayout vtkOctreeInputHelper::Layout(const Request& r)
{
  ImageLayout layout;
  octoray::BuildOptions& options = layout.Options;
  options.depth = r.LeafDepth;
  auto* image = vtkImageData::SafeDownCast(r.Input);
  int extent[6];
  image->GetExtent(extent);
  const double* spacing = image->GetSpacing();
  // The voxels' boxes: continuous indices from -0.5 to n - 0.5 along each
  // axis (through the direction matrix, so any orientation is covered).
  double lo[3] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX };
  double hi[3] = { -VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX };
  for (int corner = 0; corner < 8; ++corner)
  {
    const double index[3] = { (corner & 1) ? extent[1] + 0.5 : extent[0] - 0.5,
      (corner & 2) ? extent[3] + 0.5 : extent[2] - 0.5, (corner & 4) ? extent[5] + 0.5 : extent[4] - 0.5 };
    double p[3];
    image->TransformContinuousIndexToPhysicalPoint(index, p);
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  double finest = VTK_DOUBLE_MAX;
  for (int a = 0; a < 3; ++a)
  {
    if (std::abs(spacing[a]) > 0.0)
    {
      finest = std::min(finest, std::abs(spacing[a]));
    }
  }
  const bool fixed = vtkMath::AreBoundsInitialized(r.RootBounds.data());
  if (fixed)
  {
    const double* b = r.RootBounds.data();
    const double blo[3] = { b[0], b[2], b[4] }, bhi[3] = { b[1], b[3], b[5] };
    options.cube = octoray::RootCube::FromBounds(blo, bhi);
  }
  else
  {
    options.cube = octoray::RootCube::FromBounds(lo, hi);
  }
  options.fixedCube = true;
  if (options.depth == 0 && finest < VTK_DOUBLE_MAX)
  {
    // The shallowest level whose leaf is no wider than the finest spacing
    // (a relative 1e-6 of slack: 256 voxels of 0.957 mm are depth 8, not 9,
    // whatever the rounding of their bounds).
    const double extent = std::max({ hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] });
    const double levels = std::ceil(std::log2((fixed ? options.cube.size : extent) / finest) - 1e-6);
    options.depth = static_cast<int>(std::min(21.0, std::max(1.0, levels)));
    const double size = finest * std::ldexp(1.0, options.depth);
    if (!fixed && size >= extent * (1.0 - 1e-6))
    {
      // A cube of 2^depth finest spacings, placed so that the voxel centres
      // along the finest axes are leaf centres: leaves and voxels coincide.
      options.cube.size = std::max(size, extent * (1.0 + 0x1p-20));
      for (int a = 0; a < 3; ++a)
      {
        const double margin = std::max(0.0, std::floor(0.5 * (size - (hi[a] - lo[a])) / finest) * finest);
        options.cube.origin[a] = lo[a] - margin;
      }
    }
  }
  if (options.depth == 0)
  {
    options.depth = 1; // a single voxel without spacing
  }
  // Points per voxel along each axis: enough that neighbouring points are
  // at most a leaf apart, so every leaf a voxel's box covers gets one. At
  // most 64 points per voxel (a depth chosen far finer than the spacing
  // leaves gaps rather than exhausting memory).
  const double leaf = options.cube.size / std::ldexp(1.0, options.depth);
  int total = 1;
  for (int a = 0; a < 3; ++a)
  {
    const int n = extent[2 * a + 1] - extent[2 * a] + 1;
    const double s = std::abs(spacing[a]);
    layout.Split[a] = 1;
    if (s > 0.0 && leaf > 0.0 && n >= 1)
    {
      layout.Split[a] = static_cast<int>(std::min(64.0, std::max(1.0, std::ceil(s / leaf - 1e-6))));
    }
    total *= layout.Split[a];
  }
  while (total > 64)
  {
    int widest = 0;
    for (int a = 1; a < 3; ++a)
    {
      widest = layout.Split[a] > layout.Split[widest] ? a : widest;
    }
    total /= layout.Split[widest];
    layout.Split[widest] = std::max(1, layout.Split[widest] / 2);
    total *= layout.Split[widest];
  }
  return layout;
}

//------------------------------------------------------------------------------
// Every voxel above the background becomes a point at the voxel's position,
// with its value as scalar (or its components as colour). Along axes whose
// spacing is wider than a leaf a voxel becomes several points across its
// box; one-component scalars are then interpolated linearly between the
// voxel and its neighbours at each point (as resampling the image finer
// would), so surfaces are as smooth across slices as within them, and a
// point is kept where its interpolated value is above the background. With
// ImageGradientNormals, one-component scalars also give each point the
// normal of the field, interpolated the same way.
void vtkOctreeInputHelper::ImageView(
  const Request& r, octoray::PointCloudView& view, const std::function<void(double)>& progress)
{
  auto* image = vtkImageData::SafeDownCast(r.Input);
  vtkDataArray* scalars = r.Scalars;
  const int comps = scalars ? scalars->GetNumberOfComponents() : 0;
  const bool bytes = vtkUnsignedCharArray::SafeDownCast(scalars) != nullptr;
  const ImageLayout layout = Layout(r);
  const int* split = layout.Split;
  const int copies = split[0] * split[1] * split[2];
  // Sub-voxel offsets in index units.
  std::vector<std::array<double, 3>> offsets;
  for (int k = 0; k < split[2]; ++k)
  {
    for (int j = 0; j < split[1]; ++j)
    {
      for (int i = 0; i < split[0]; ++i)
      {
        offsets.push_back({ (i + 0.5) / split[0] - 0.5, (j + 0.5) / split[1] - 0.5, (k + 0.5) / split[2] - 0.5 });
      }
    }
  }
  const octoray::RootCube& cube = layout.Options.cube;
  const double inside = cube.size * (1.0 - 0x1p-20);
  int extent[6];
  image->GetExtent(extent);
  const vtkIdType size[3] = { extent[1] - extent[0] + 1, extent[3] - extent[2] + 1, extent[5] - extent[4] + 1 };
  const vtkIdType stride[3] = { 1, size[0], size[0] * size[1] };
  const vtkIdType n = image->GetNumberOfPoints();
  const double* spacing = image->GetSpacing();
  const double* direction = image->GetDirectionMatrix()->GetData();

  // One-component scalars: a float copy to interpolate and differentiate.
  const bool field = scalars && !r.Colours && comps == 1;
  const bool gradient = field && r.ImageGradientNormals;
  std::vector<float> values;
  if (field)
  {
    values.resize(static_cast<std::size_t>(n));
    for (vtkIdType id = 0; id < n; ++id)
    {
      values[id] = static_cast<float>(scalars->GetComponent(id, 0));
    }
  }
  // The field's gradient at a voxel, per unit length along the index axes:
  // central differences, one-sided at the border.
  auto gradientAt = [&](const vtkIdType ijk[3], double g[3]) {
    const vtkIdType id = ijk[0] + stride[1] * ijk[1] + stride[2] * ijk[2];
    for (int a = 0; a < 3; ++a)
    {
      g[a] = 0.0;
      if (size[a] < 2 || spacing[a] == 0.0)
      {
        continue;
      }
      const vtkIdType below = ijk[a] > 0 ? id - stride[a] : id;
      const vtkIdType above = ijk[a] + 1 < size[a] ? id + stride[a] : id;
      const double steps = (ijk[a] > 0 && ijk[a] + 1 < size[a]) ? 2.0 : 1.0;
      g[a] = (values[above] - values[below]) / (steps * spacing[a]);
    }
  };

  for (vtkIdType id = 0; id < n; ++id)
  {
    const vtkIdType ijk[3] = { id % size[0], (id / size[0]) % size[1], id / stride[2] };
    double value = scalars ? (field ? values[id] : scalars->GetComponent(id, 0)) : 1.0; // no scalars: the whole grid
    for (int c = 1; c < comps; ++c)
    {
      value = std::max(value, scalars->GetComponent(id, c));
    }
    if (id % 65536 == 0)
    {
      progress(0.5 * static_cast<double>(id) / n);
    }
    // Interpolated points may lie above the background where the voxel
    // does not, next to one that does.
    double reach = value;
    if (field && copies > 1)
    {
      for (int a = 0; a < 3; ++a)
      {
        if (split[a] > 1)
        {
          if (ijk[a] > 0)
          {
            reach = std::max(reach, static_cast<double>(values[id - stride[a]]));
          }
          if (ijk[a] + 1 < size[a])
          {
            reach = std::max(reach, static_cast<double>(values[id + stride[a]]));
          }
        }
      }
    }
    if (!(reach > r.ImageBackground))
    {
      continue;
    }
    for (const auto& offset : offsets)
    {
      double sample = value;
      double g[3] = { 0.0, 0.0, 0.0 };
      if (field)
      {
        // Linear interpolation towards the neighbours the offset leans to
        // (at most 8 corners; 1 when the voxel is not split).
        sample = 0.0;
        for (int corner = 0; corner < 8; ++corner)
        {
          double weight = 1.0;
          vtkIdType at[3] = { ijk[0], ijk[1], ijk[2] };
          for (int a = 0; a < 3 && weight > 0.0; ++a)
          {
            const double o = offset[a];
            const bool toNeighbour = (corner >> a) & 1;
            if (o == 0.0)
            {
              weight *= toNeighbour ? 0.0 : 1.0;
              continue;
            }
            weight *= toNeighbour ? std::abs(o) : 1.0 - std::abs(o);
            if (toNeighbour)
            {
              at[a] = std::min(std::max<vtkIdType>(at[a] + (o > 0.0 ? 1 : -1), 0), size[a] - 1);
            }
          }
          if (weight <= 0.0)
          {
            continue;
          }
          sample += weight * values[at[0] + stride[1] * at[1] + stride[2] * at[2]];
          if (gradient)
          {
            double gc[3];
            gradientAt(at, gc);
            g[0] += weight * gc[0], g[1] += weight * gc[1], g[2] += weight * gc[2];
          }
        }
        if (!(sample > r.ImageBackground))
        {
          continue;
        }
      }
      const double index[3] = { extent[0] + ijk[0] + offset[0], extent[2] + ijk[1] + offset[1],
        extent[4] + ijk[2] + offset[2] };
      double p[3];
      image->TransformContinuousIndexToPhysicalPoint(index, p);
      if (copies > 1)
      {
        // A voxel's box may reach past a caller's cube (RootBounds around
        // the voxel centres): keep its points inside.
        for (int a = 0; a < 3; ++a)
        {
          p[a] = std::min(std::max(p[a], cube.origin[a]), cube.origin[a] + inside);
        }
      }
      this->Xyz.insert(this->Xyz.end(), p, p + 3);
      if (r.Colours)
      {
        for (int c = 0; c < 4; ++c)
        {
          const double v = c < comps ? scalars->GetComponent(id, c) : (bytes ? 255.0 : 1.0);
          bytes ? this->Color8.push_back(static_cast<std::uint8_t>(v))
                : this->ColorFloat.push_back(static_cast<float>(v));
        }
      }
      else if (scalars)
      {
        this->Scalar.push_back(static_cast<float>(field ? sample : scalars->GetComponent(id, 0)));
      }
      if (gradient)
      {
        // Through the direction matrix (row-major); the normal points down
        // the gradient, out of the denser material.
        double world[3];
        for (int row = 0; row < 3; ++row)
        {
          world[row] = direction[3 * row] * g[0] + direction[3 * row + 1] * g[1] + direction[3 * row + 2] * g[2];
        }
        const double length = std::sqrt(world[0] * world[0] + world[1] * world[1] + world[2] * world[2]);
        for (int a = 0; a < 3; ++a)
        {
          this->Normal.push_back(length > 0.0 ? static_cast<float>(-world[a] / length) : 0.0f);
        }
      }
    }
  }
  view.count = this->Xyz.size() / 3;
  view.xyzDouble = this->Xyz.data();
  view.color8 = this->Color8.empty() ? nullptr : this->Color8.data();
  view.colorFloat = this->ColorFloat.empty() ? nullptr : this->ColorFloat.data();
  view.colorComponents = r.Colours ? 4 : 0;
  view.scalar = this->Scalar.empty() ? nullptr : this->Scalar.data();
  view.normal = this->Normal.empty() ? nullptr : this->Normal.data();
}

//------------------------------------------------------------------------------
void vtkOctreeInputHelper::FindScalarRange(const octoray::PointCloudView& view)
{
  this->ScalarPresent = view.scalar && view.count > 0;
  if (!this->ScalarPresent)
  {
    return;
  }
  const auto range = std::minmax_element(view.scalar, view.scalar + view.count);
  this->Range[0] = *range.first;
  this->Range[1] = *range.second;
}
