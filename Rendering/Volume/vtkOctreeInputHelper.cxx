#include "vtkOctreeInputHelper.h"

#include "vtkAbstractMapper.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkOctreeVolumeMapper.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolumeProperty.h"

#include <algorithm>

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
    s.Layout += "+image:" + std::to_string(r.ImageBackground);
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
// Every voxel above the background is a point at the voxel's position, with
// its value as scalar (or its components as colour).
void vtkOctreeInputHelper::ImageView(
  const Request& r, octoray::PointCloudView& view, const std::function<void(double)>& progress)
{
  auto* image = vtkImageData::SafeDownCast(r.Input);
  vtkDataArray* scalars = r.Scalars;
  const int comps = scalars ? scalars->GetNumberOfComponents() : 0;
  const bool bytes = vtkUnsignedCharArray::SafeDownCast(scalars) != nullptr;
  const vtkIdType n = image->GetNumberOfPoints();
  for (vtkIdType i = 0; i < n; ++i)
  {
    double value = scalars ? scalars->GetComponent(i, 0) : 1.0; // no scalars: the whole grid
    for (int c = 1; c < comps; ++c)
    {
      value = std::max(value, scalars->GetComponent(i, c));
    }
    if (!(value > r.ImageBackground))
    {
      continue;
    }
    double p[3];
    image->GetPoint(i, p);
    this->Xyz.insert(this->Xyz.end(), p, p + 3);
    if (r.Colours)
    {
      for (int c = 0; c < 4; ++c)
      {
        const double v = c < comps ? scalars->GetComponent(i, c) : (bytes ? 255.0 : 1.0);
        bytes ? this->Color8.push_back(static_cast<std::uint8_t>(v))
              : this->ColorFloat.push_back(static_cast<float>(v));
      }
    }
    else if (scalars)
    {
      this->Scalar.push_back(static_cast<float>(scalars->GetComponent(i, 0)));
    }
    if (i % 65536 == 0)
    {
      progress(0.5 * static_cast<double>(i) / n);
    }
  }
  view.count = this->Xyz.size() / 3;
  view.xyzDouble = this->Xyz.data();
  view.color8 = this->Color8.empty() ? nullptr : this->Color8.data();
  view.colorFloat = this->ColorFloat.empty() ? nullptr : this->ColorFloat.data();
  view.colorComponents = r.Colours ? 4 : 0;
  view.scalar = this->Scalar.empty() ? nullptr : this->Scalar.data();
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
