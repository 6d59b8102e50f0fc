#include "vtkOctreeInputHelper.h"

#include "vtkAbstractMapper.h"
#include "vtkCellData.h"
#include "vtkColorTransferFunction.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkOctreeVolumeMapper.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numeric>
#include <sstream>

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

// The value the transfer functions read from a tuple of `comps` values: one
// component, or the tuple's length (Request::ScalarComponent).
double ScalarValue(const double* tuple, int comps, int component)
{
  if (component != vtkOctreeInputHelper::kMagnitude)
  {
    return tuple[component];
  }
  double sum = 0.0;
  for (int c = 0; c < comps; ++c)
  {
    sum += tuple[c] * tuple[c];
  }
  return std::sqrt(sum);
}

// One float a point for the transfer functions: the array's own memory
// where it is one float component, else each tuple's ScalarValue.
const float* ScalarValues(vtkDataArray* array, int component, std::vector<float>& storage)
{
  if (component == 0)
  {
    return FloatComponents(array, 1, storage);
  }
  const int comps = array->GetNumberOfComponents();
  storage.resize(static_cast<std::size_t>(array->GetNumberOfTuples()));
  vtkSMPTools::For(0, array->GetNumberOfTuples(), [&](vtkIdType begin, vtkIdType end) {
    std::vector<double> tuple(comps);
    for (vtkIdType i = begin; i < end; ++i)
    {
      array->GetTuple(i, tuple.data());
      storage[i] = static_cast<float>(ScalarValue(tuple.data(), comps, component));
    }
  });
  return storage.data();
}

std::string ComponentName(int component)
{
  return component == vtkOctreeInputHelper::kMagnitude ? "magnitude" : "component " + std::to_string(component);
}

// Which value of multi-component scalars the transfer functions read, as
// vtkScalarsToColors maps vectors and ParaView's colour map offers them
// (Magnitude, X, Y, Z): the colour function's VectorMode and
// VectorComponent; component 0 under a grey function, which has neither.
// What VTK's mappers would draw otherwise goes to `notices`.
int ScalarComponentOf(vtkVolumeProperty* property, vtkDataArray* scalars, std::vector<std::string>& notices)
{
  const int comps = scalars->GetNumberOfComponents();
  if (comps < 2 || property->GetColorChannels(0) != 3)
  {
    return 0;
  }
  const std::string name = std::string("'") + (scalars->GetName() ? scalars->GetName() : "(unnamed)") + "'";
  vtkColorTransferFunction* colour = property->GetRGBTransferFunction(0);
  int component = vtkOctreeInputHelper::kMagnitude;
  if (colour->GetVectorMode() != vtkScalarsToColors::MAGNITUDE)
  {
    component = std::clamp(colour->GetVectorComponent(), 0, comps - 1);
    if (component != colour->GetVectorComponent())
    {
      notices.push_back("The colour function's VectorComponent " + std::to_string(colour->GetVectorComponent()) +
        " is not one of the " + std::to_string(comps) + " components of the scalars " + name + "; " +
        ComponentName(component) + " is drawn.");
    }
  }
  if (!property->GetIndependentComponents())
  {
    notices.push_back("The scalars " + name + " have " + std::to_string(comps) +
      " dependent components (IndependentComponents off), which the octree draws only as 3 or 4 (colours); it "
      "draws their " + ComponentName(component) + " through the transfer functions.");
  }
  return component;
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

// The points of an image: every sample of `axes` (the voxels and, with
// filling, the planes between slices; octorayLattice.h) whose value is
// above the background: the value the transfer functions read
// (ScalarValue), or with colours, which become RGBA, the largest
// component. Two passes over the planes (count, then fill at each plane's
// offset), each in parallel.
struct ImageOutput
{
  std::vector<double>& Xyz;
  std::vector<float>& Scalar;
  std::vector<std::uint8_t>& Color8;
  std::vector<float>& ColorFloat;
  std::vector<float>* Normal; // gradient normals (ImageGradientNormals), or null
};

template <typename T>
void ImagePoints(const T* data, int comps, const octoray::lattice::Axis axes[3], const long long dims[3],
  const octoray::lattice::Lattice& lattice, double background, bool colours, bool bytes, int component,
  ImageOutput out, const std::function<void(double)>& progress, const double* spacing = nullptr,
  const double* direction = nullptr)
{
  // Gradient normals: one-component scalars, and the caller asked for them.
  const bool normals = out.Normal && data && !colours && comps == 1 && spacing && direction;
  const vtkIdType planes = static_cast<vtkIdType>(axes[2].Samples());
  auto above = [&](const double* v) {
    if (comps == 0)
    {
      return 1.0 > background; // no scalars: the whole grid
    }
    if (!colours)
    {
      return ScalarValue(v, comps, component) > background;
    }
    return *std::max_element(v, v + comps) > background;
  };
  // Planes in blocks, so that progress is reported from this thread.
  const vtkIdType block = std::max<vtkIdType>(1, planes / 20);
  auto blocks = [&](double from, double to, const std::function<void(vtkIdType, vtkIdType)>& work) {
    for (vtkIdType b = 0; b < planes; b += block)
    {
      vtkSMPTools::For(b, std::min(planes, b + block), work);
      progress(from + (to - from) * static_cast<double>(std::min(planes, b + block)) / planes);
    }
  };
  std::vector<vtkIdType> counts(planes + 1, 0);
  blocks(0.0, 0.2, [&](vtkIdType b, vtkIdType e) {
    std::vector<double> values(std::max(comps, 1));
    for (vtkIdType k = b; k < e; ++k)
    {
      vtkIdType n = 0;
      octoray::lattice::ForEachSampleInPlane(axes, data, dims, comps, k, values.data(),
        [&](long long, long long, const double* v) { n += above(v); });
      counts[k + 1] = n;
    }
  });
  std::partial_sum(counts.begin(), counts.end(), counts.begin());
  const std::size_t total = static_cast<std::size_t>(counts[planes]);
  out.Xyz.resize(3 * total);
  if (colours)
  {
    (bytes ? out.Color8.resize(4 * total) : out.ColorFloat.resize(4 * total));
  }
  else if (comps > 0)
  {
    out.Scalar.resize(total);
  }
  if (normals)
  {
    out.Normal->resize(3 * total);
  }
  blocks(0.2, 0.5, [&](vtkIdType b, vtkIdType e) {
    std::vector<double> values(std::max(comps, 1));
    for (vtkIdType k = b; k < e; ++k)
    {
      std::size_t n = static_cast<std::size_t>(counts[k]);
      octoray::lattice::ForEachSampleInPlane(axes, data, dims, comps, k, values.data(),
        [&](long long r0, long long r1, const double* v) {
          if (!above(v))
          {
            return;
          }
          lattice.Position(r0, r1, k, &out.Xyz[3 * n]);
          if (colours)
          {
            for (int c = 0; c < 4; ++c)
            {
              const double x = c < comps ? v[c] : (bytes ? 255.0 : 1.0);
              if (bytes)
              {
                out.Color8[4 * n + c] = static_cast<std::uint8_t>(std::lround(std::clamp(x, 0.0, 255.0)));
              }
              else
              {
                out.ColorFloat[4 * n + c] = static_cast<float>(x);
              }
            }
          }
          else if (comps > 0)
          {
            out.Scalar[n] = static_cast<float>(ScalarValue(v, comps, component));
          }
          if (normals)
          {
            const long long r[3] = { r0, r1, static_cast<long long>(k) };
            octoray::lattice::GradientNormal(data, comps, dims, axes, spacing, direction, r, &(*out.Normal)[3 * n]);
          }
          ++n;
        });
    }
  });
}

//------------------------------------------------------------------------------
// A selected point array with fewer tuples than the input has points: the
// engine reads one tuple a point, so the input is refused, naming the array.
std::string ShortArray(const vtkOctreeInputHelper::Request& r)
{
  for (vtkDataArray* a : { r.Scalars, r.Reflectivity, r.Refraction, r.Normals })
  {
    const bool cellArray = a == r.Scalars && r.CellCentred;
    const vtkIdType needed = cellArray ? r.Input->GetNumberOfCells() : r.Input->GetNumberOfPoints();
    if (a && a->GetNumberOfTuples() < needed)
    {
      const std::string name = a->GetName() ? a->GetName() : "(unnamed)";
      const std::string what = cellArray ? "cell" : "point";
      return "The " + what + " array '" + name + "' has " + std::to_string(a->GetNumberOfTuples()) +
        " tuples for " + std::to_string(needed) + " " + what + "s; nothing to draw.";
    }
  }
  return "";
}

//------------------------------------------------------------------------------
// An array name the user set (`property`, not the default) that names no
// `kind` ("point", "cell") array of `data`: what the frame goes without,
// with the arrays there are, so a misspelt name is seen. "" where it names
// one, or is the default.
std::string MissingNamedArray(vtkDataSetAttributes* data, const char* kind, const char* property, const char* name,
  const char* defaultName, const char* effect)
{
  if (!name || std::strcmp(name, defaultName) == 0 || data->GetArray(name))
  {
    return "";
  }
  std::string arrays;
  for (int i = 0; i < data->GetNumberOfArrays(); ++i)
  {
    const char* other = data->GetArrayName(i);
    arrays += (i ? ", " : "") + std::string(other ? other : "(unnamed)");
  }
  return std::string(property) + " '" + name + "' names no " + kind + " array of the input (its arrays: " +
    (arrays.empty() ? "none" : arrays) + "); " + effect + ".";
}

//------------------------------------------------------------------------------
// A scalar array selected by name (SelectScalarArray, ParaView's colour
// array) that the input lacks, which the frame is drawn without: said, as
// the other named arrays are. "" where there is none to say.
std::string MissingScalarArray(vtkDataSet* input, vtkOctreeVolumeMapper* mapper)
{
  const int mode = mapper->GetScalarMode();
  if (mapper->GetArrayAccessMode() != VTK_GET_ARRAY_BY_NAME ||
    (mode != VTK_SCALAR_MODE_USE_POINT_FIELD_DATA && mode != VTK_SCALAR_MODE_USE_CELL_FIELD_DATA))
  {
    return "";
  }
  const bool cells = mode == VTK_SCALAR_MODE_USE_CELL_FIELD_DATA;
  return MissingNamedArray(cells ? static_cast<vtkDataSetAttributes*>(input->GetCellData()) : input->GetPointData(),
    cells ? "cell" : "point", "SelectScalarArray", mapper->GetArrayName(), "",
    "the voxels are drawn in their own colours, or white");
}

//------------------------------------------------------------------------------
// RootBounds that are set (min <= max) must be finite, have a size and hold
// the input's bounds; "" where they do or are not set.
std::string RootBoundsProblem(const vtkOctreeInputHelper::Request& r)
{
  const std::array<double, 6>& b = r.RootBounds;
  if (b[0] > b[1] || b[2] > b[3] || b[4] > b[5])
  {
    return ""; // not set: the cube is fitted to the points
  }
  auto text = [](const double* v) {
    std::ostringstream t;
    t << "(" << v[0] << ", " << v[1] << ", " << v[2] << ", " << v[3] << ", " << v[4] << ", " << v[5] << ")";
    return t.str();
  };
  const bool finite = std::all_of(b.begin(), b.end(), [](double v) { return std::isfinite(v); });
  if (!finite || std::max({ b[1] - b[0], b[3] - b[2], b[5] - b[4] }) <= 0.0)
  {
    return "RootBounds " + text(b.data()) + " must be finite and wider than a point; nothing to draw.";
  }
  double in[6];
  r.Input->GetBounds(in);
  for (int a = 0; a < 3; ++a)
  {
    if (in[2 * a] < b[2 * a] || in[2 * a + 1] > b[2 * a + 1])
    {
      return "RootBounds " + text(b.data()) + " do not hold the input's bounds " + text(in) +
        "; nothing to draw.";
    }
  }
  return "";
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
  // one value a point through the transfer functions (ScalarComponentOf).
  int cellFlag = 0;
  r.Scalars = vtkAbstractMapper::GetScalars(input, mapper->GetScalarMode(), mapper->GetArrayAccessMode(),
    mapper->GetArrayId(), mapper->GetArrayName(), cellFlag);
  if (r.Scalars && cellFlag && vtkImageData::SafeDownCast(input))
  {
    // An image's cells are voxels too, as VTK's GPU ray caster draws them.
    r.CellCentred = true;
  }
  else if (r.Scalars && cellFlag)
  {
    r.CellScalars = true;
    r.Scalars = nullptr;
  }
  if (!r.Scalars)
  {
    const std::string missing = MissingScalarArray(input, mapper);
    if (!missing.empty())
    {
      r.Notices.push_back(missing);
    }
  }
  const int components = r.Scalars ? r.Scalars->GetNumberOfComponents() : 0;
  r.Colours = r.Scalars && !property->GetIndependentComponents() && (components == 3 || components == 4);
  if (r.Scalars && !r.Colours)
  {
    r.ScalarComponent = ScalarComponentOf(property, r.Scalars, r.Notices);
  }
  if (vtkPointSet::SafeDownCast(input))
  {
    vtkPointData* pd = input->GetPointData();
    const char* reflectivity = mapper->GetReflectivityArrayName();
    const char* refraction = mapper->GetRefractionArrayName();
    r.Reflectivity = reflectivity ? pd->GetArray(reflectivity) : nullptr;
    r.Refraction = refraction ? pd->GetArray(refraction) : nullptr;
    const std::string missing[2] = {
      MissingNamedArray(pd, "point", "ReflectivityArrayName", reflectivity, DefaultReflectivityArrayName,
        "nothing reflects"),
      MissingNamedArray(pd, "point", "RefractionArrayName", refraction, DefaultRefractionArrayName,
        "nothing refracts")
    };
    for (const std::string& notice : missing)
    {
      if (!notice.empty())
      {
        r.Notices.push_back(notice);
      }
    }
    r.Normals = pd->GetNormals();
    if (r.Normals && r.Normals->GetNumberOfComponents() != 3)
    {
      r.Normals = nullptr;
    }
  }
  r.ImageBackground = mapper->GetImageBackground();
  r.FillBetweenSlices = mapper->GetFillBetweenSlices();
  r.ImageGradientNormals = mapper->GetImageGradientNormals();
  if (vtkPointSet::SafeDownCast(input))
  {
    vtkDataArray* lattice = input->GetFieldData()->GetArray(octoray::lattice::kFieldArrayName);
    if (lattice && lattice->GetNumberOfComponents() == octoray::lattice::kFieldArrayComponents &&
      lattice->GetNumberOfTuples() >= 1)
    {
      r.Lattice = lattice;
    }
  }
  r.LeafDepth = mapper->GetLeafDepth();
  std::copy(mapper->GetRootBounds(), mapper->GetRootBounds() + 6, r.RootBounds.begin());
  r.EngineGeneration = engineGeneration;
  r.Problem = ShortArray(r);
  if (r.Problem.empty())
  {
    r.Problem = RootBoundsProblem(r);
  }
  return r;
}

//------------------------------------------------------------------------------
vtkOctreeInputHelper::Signature vtkOctreeInputHelper::Sign(const Request& r)
{
  Signature s;
  s.Input = r.Input;
  s.Count = r.Input->GetNumberOfPoints();
  const std::string scalars = r.Scalars ? "scalars:" + ComponentName(r.ScalarComponent) : "plain";
  s.Layout = (r.Colours ? "colours" : scalars) +
    (r.Reflectivity ? "+reflectivity" : "") + (r.Refraction ? "+refraction" : "") + (r.Normals ? "+normals" : "");
  auto* pointSet = vtkPointSet::SafeDownCast(r.Input);
  if (!pointSet)
  {
    char background[32]; // exact: a change in the sixth decimal still rebuilds
    std::snprintf(background, sizeof(background), "%a", r.ImageBackground);
    s.Layout += std::string("+image:") + background + (r.FillBetweenSlices ? "+fill" : "") +
      (r.ImageGradientNormals ? "+gradient" : "");
  }
  s.Arrays = { Stamp(r.Scalars), Stamp(r.Reflectivity), Stamp(r.Refraction), Stamp(r.Normals), Stamp(r.Lattice) };
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
  this->Failed = false;
}

void vtkOctreeInputHelper::RememberFailure(const Request& request)
{
  this->FailedBuild = Sign(request);
  this->Failed = true;
}

bool vtkOctreeInputHelper::FailedBefore(const Request& request) const
{
  return this->Failed && Sign(request) == this->FailedBuild;
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
  this->HasLattice = false;
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
    view.scalar = ScalarValues(r.Scalars, r.ScalarComponent, this->Scalar);
  }
  view.reflectivity = r.Reflectivity ? FloatComponents(r.Reflectivity, 1, this->Reflectivity) : nullptr;
  view.refraction = r.Refraction ? FloatComponents(r.Refraction, 1, this->Refraction) : nullptr;
  view.normal = r.Normals ? FloatComponents(r.Normals, 3, this->Normal) : nullptr;

  // The lattice the field data names (the slice-stack reader's particles),
  // as long as the points still lie on it: a filter that moved them (a
  // transform) passes the array on unchanged. Up to 1000 points checked.
  if (r.Lattice && view.count > 0)
  {
    double tuple[octoray::lattice::kFieldArrayComponents];
    r.Lattice->GetTuple(0, tuple);
    const octoray::lattice::Lattice lattice = octoray::lattice::FromTuple(tuple);
    const vtkIdType n = pointSet->GetNumberOfPoints();
    const vtkIdType step = std::max<vtkIdType>(1, n / 1000);
    bool on = true;
    for (vtkIdType i = 0; on && i < n; i += step)
    {
      double p[3];
      pointSet->GetPoint(i, p);
      on = octoray::lattice::OnLattice(lattice, p);
    }
    if (on)
    {
      this->HasLattice = true;
      this->Lattice = lattice;
      pointSet->GetBounds(this->LatticeBounds);
    }
  }
}

//------------------------------------------------------------------------------
bool vtkOctreeInputHelper::PointLattice(octoray::lattice::Lattice& lattice, double bounds[6]) const
{
  if (!this->HasLattice)
  {
    return false;
  }
  lattice = this->Lattice;
  std::copy(this->LatticeBounds, this->LatticeBounds + 6, bounds);
  return true;
}

//------------------------------------------------------------------------------
// The lattice of an image's voxels (its points, or with cell scalars its
// cells; octorayLattice.h's ImageSamples), with the planes between slices
// where FillBetweenSlices asks for them; `axes` and `size` as ImagePoints
// takes them.
static octoray::lattice::Lattice ImageLattice(vtkImageData* image, const vtkOctreeInputHelper::Request& r,
  octoray::lattice::Axis axes[3], long long size[3])
{
  int dims[3];
  double first[3];
  octoray::lattice::ImageSamples(image, r.CellCentred, dims, first);
  for (int a = 0; a < 3; ++a)
  {
    size[a] = axes[a].Count = dims[a];
  }
  if (r.FillBetweenSlices)
  {
    octoray::lattice::FillAxes(image->GetSpacing(), axes);
  }
  return octoray::lattice::LatticeOf(axes, first, image->GetSpacing(), image->GetDirectionMatrix()->GetData());
}

//------------------------------------------------------------------------------
// ImagePoints over the request's scalars, of whatever type and layout they
// come in (none: the whole grid).
static void ImageVoxels(vtkImageData* image, const vtkOctreeInputHelper::Request& r,
  const octoray::lattice::Axis axes[3], const long long size[3], const octoray::lattice::Lattice& lattice,
  ImageOutput out, const std::function<void(double)>& progress)
{
  vtkDataArray* scalars = r.Scalars;
  if (!scalars)
  {
    const double* none = nullptr;
    ImagePoints(none, 0, axes, size, lattice, r.ImageBackground, false, false, 0, out, progress);
    return;
  }
  const int comps = scalars->GetNumberOfComponents();
  const bool bytes = vtkUnsignedCharArray::SafeDownCast(scalars) != nullptr;
  const double* spacing = image->GetSpacing();
  const double* direction = image->GetDirectionMatrix()->GetData();
  if (scalars->HasStandardMemoryLayout())
  {
    switch (scalars->GetDataType())
    {
      vtkTemplateMacro(ImagePoints(static_cast<const VTK_TT*>(scalars->GetVoidPointer(0)), comps, axes, size,
        lattice, r.ImageBackground, r.Colours, bytes, r.ScalarComponent, out, progress, spacing, direction));
    }
    return;
  }
  // Another memory layout (e.g. struct of arrays): the values as doubles.
  std::vector<double> values(static_cast<std::size_t>(scalars->GetNumberOfTuples()) * comps);
  for (vtkIdType i = 0; i < scalars->GetNumberOfTuples(); ++i)
  {
    scalars->GetTuple(i, &values[static_cast<std::size_t>(i) * comps]);
  }
  ImagePoints(values.data(), comps, axes, size, lattice, r.ImageBackground, r.Colours, bytes, r.ScalarComponent,
    out, progress, spacing, direction);
}

//------------------------------------------------------------------------------
// Every voxel above the background is a point at the voxel's position, with
// its value as scalar (or its components as colour); with FillBetweenSlices,
// so are the samples interpolated between slices (octorayLattice.h: along
// the coarsest axis, down to the second-coarsest spacing). The voxels are
// the image's points, or with cell scalars its cells.
void vtkOctreeInputHelper::ImageView(
  const Request& r, octoray::PointCloudView& view, const std::function<void(double)>& progress)
{
  auto* image = vtkImageData::SafeDownCast(r.Input);
  octoray::lattice::Axis axes[3];
  long long size[3];
  const octoray::lattice::Lattice lattice = ImageLattice(image, r, axes, size);
  this->Normal.clear();
  const ImageOutput out{ this->Xyz, this->Scalar, this->Color8, this->ColorFloat,
    r.ImageGradientNormals ? &this->Normal : nullptr };
  ImageVoxels(image, r, axes, size, lattice, out, progress);
  view.count = this->Xyz.size() / 3;
  view.xyzDouble = this->Xyz.data();
  view.color8 = this->Color8.empty() ? nullptr : this->Color8.data();
  view.colorFloat = this->ColorFloat.empty() ? nullptr : this->ColorFloat.data();
  view.colorComponents = r.Colours ? 4 : 0;
  view.scalar = this->Scalar.empty() ? nullptr : this->Scalar.data();
  view.normal = this->Normal.empty() ? nullptr : this->Normal.data();
  if (view.count > 0)
  {
    this->RememberImageLattice(lattice);
  }
}

//------------------------------------------------------------------------------
// The image points' lattice and bounds, for the leaf grid (PointLattice).
void vtkOctreeInputHelper::RememberImageLattice(const octoray::lattice::Lattice& lattice)
{
  double* b = this->LatticeBounds;
  for (int a = 0; a < 3; ++a)
  {
    b[2 * a] = b[2 * a + 1] = this->Xyz[a];
  }
  for (std::size_t i = 0; i < this->Xyz.size(); i += 3)
  {
    for (int a = 0; a < 3; ++a)
    {
      b[2 * a] = std::min(b[2 * a], this->Xyz[i + a]);
      b[2 * a + 1] = std::max(b[2 * a + 1], this->Xyz[i + a]);
    }
  }
  this->Lattice = lattice;
  this->HasLattice = true;
}

//------------------------------------------------------------------------------
void vtkOctreeInputHelper::FindScalarRange(const octoray::PointCloudView& view)
{
  this->ScalarPresent = view.scalar && view.count > 0;
  if (!this->ScalarPresent)
  {
    return;
  }
  // The finite values' range, as the engine codes them (NaN and infinities
  // have codes of their own): one NaN or inf would leave the transfer
  // function no range, or an infinite one.
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < view.count; ++i)
  {
    if (std::isfinite(view.scalar[i]))
    {
      lo = std::min<double>(lo, view.scalar[i]);
      hi = std::max<double>(hi, view.scalar[i]);
    }
  }
  this->Range[0] = lo <= hi ? lo : 0.0;
  this->Range[1] = lo <= hi ? hi : 0.0;
}
