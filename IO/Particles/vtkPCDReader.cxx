#include "vtkPCDReader.h"

#include "octorayPCDBody.h"
#include "octorayPCDHeader.h"
#include "octorayPCDValues.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

vtkStandardNewMacro(vtkPCDReader);

namespace
{
using namespace octoray::pcd;

// Points converted between two progress reports (and abort checks).
constexpr size_t ChunkPoints = size_t(1) << 16;

// An output array filled from one or more fields.
struct Sink
{
  enum Kind
  {
    Points,
    Colors,
    Values // arrays of numbers, component by component
  };
  Kind What = Values;
  std::vector<int> Fields; // Points / Normals: 3 fields of one value; else one field
  vtkSmartPointer<vtkDataArray> Array;
  int Components = 1;
};

// The output arrays; Sinks lists each with the fields it is made of.
struct Arrays
{
  std::vector<Sink> Sinks;
  vtkSmartPointer<vtkDataArray> Points;
  vtkSmartPointer<vtkUnsignedCharArray> Colors;
  vtkSmartPointer<vtkFloatArray> Normals;
  vtkSmartPointer<vtkDataArray> Intensity;
  std::vector<vtkSmartPointer<vtkDataArray>> Extras;
};

// The VTK type that holds a field's values as they are stored: a float
// array made a double timestamp of 1700000000.1 read 1700000000, a uint32
// label of 16777217 read 16777216.
int VTKTypeOf(const Field& f)
{
  switch (f.Type == 'F' ? f.Size : f.Type == 'I' ? -f.Size : 16 + f.Size)
  {
    case 8:
      return VTK_DOUBLE;
    case -1:
      return VTK_SIGNED_CHAR;
    case -2:
      return VTK_SHORT;
    case -4:
      return VTK_INT;
    case -8:
      return VTK_LONG_LONG;
    case 17:
      return VTK_UNSIGNED_CHAR;
    case 18:
      return VTK_UNSIGNED_SHORT;
    case 20:
      return VTK_UNSIGNED_INT;
    case 24:
      return VTK_UNSIGNED_LONG_LONG;
    default:
      return VTK_FLOAT;
  }
}

// Points from x y z; Colors from rgba or rgb (4 bytes, one value); Normals
// from normal_x normal_y normal_z; every other field but padding an array of
// its name and its own type (Intensity for intensity).
Arrays MakeArrays(const Header& h, bool real64)
{
  Arrays a;
  if (real64)
  {
    a.Points = vtkSmartPointer<vtkDoubleArray>::New();
  }
  else
  {
    a.Points = vtkSmartPointer<vtkFloatArray>::New();
  }
  a.Points->SetName("Points");
  a.Sinks.push_back({ Sink::Points, { h.Find("x"), h.Find("y"), h.Find("z") }, a.Points, 3 });
  for (const char* name : { "rgba", "rgb" })
  {
    const int k = h.Find(name);
    if (!a.Colors && k >= 0 && h.Fields[k].Size == 4 && h.Fields[k].Count == 1)
    {
      a.Colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
      a.Colors->SetName("Colors");
      a.Sinks.push_back({ Sink::Colors, { k }, a.Colors, std::strcmp(name, "rgba") == 0 ? 4 : 3 });
    }
  }
  const int nx = h.Find("normal_x"), ny = h.Find("normal_y"), nz = h.Find("normal_z");
  if (nx >= 0 && ny >= 0 && nz >= 0 && h.Fields[nx].Count == 1 && h.Fields[ny].Count == 1 &&
    h.Fields[nz].Count == 1)
  {
    a.Normals = vtkSmartPointer<vtkFloatArray>::New();
    a.Normals->SetName("Normals");
    a.Sinks.push_back({ Sink::Values, { nx, ny, nz }, a.Normals, 3 });
  }
  std::vector<bool> used(h.Fields.size(), false);
  for (const Sink& s : a.Sinks)
  {
    for (int k : s.Fields)
    {
      used[k] = true;
    }
  }
  for (size_t f = 0; f < h.Fields.size(); ++f)
  {
    const Field& fd = h.Fields[f];
    if (used[f] || fd.Padding())
    {
      continue;
    }
    auto array = vtk::TakeSmartPointer(vtkDataArray::CreateDataArray(VTKTypeOf(fd)));
    array->SetName(fd.Name == "intensity" ? "Intensity" : fd.Name.c_str());
    a.Sinks.push_back({ Sink::Values, { static_cast<int>(f) }, array, static_cast<int>(fd.Count) });
    if (fd.Name == "intensity")
    {
      a.Intensity = array;
    }
    else
    {
      a.Extras.push_back(array);
    }
  }
  return a;
}

// Converts points [i0, i0 + m) of the fields of s into its array.
void Convert(const Header& h, const Body& body, const Sink& s, size_t i0, size_t m)
{
  const size_t comps = static_cast<size_t>(s.Components);
  if (s.What == Sink::Colors)
  {
    const Source& src = body.Sources[s.Fields[0]];
    UnpackColors(src.Base + i0 * src.Stride, src.Stride, m,
      static_cast<vtkUnsignedCharArray*>(s.Array.Get())->GetPointer(0) + i0 * comps, s.Components);
    return;
  }
  // Three fields of one value each (points, normals), or one field of
  // `comps` values.
  const bool perField = s.Fields.size() > 1;
  for (size_t c = 0; c < comps; ++c)
  {
    const int k = perField ? s.Fields[c] : s.Fields[0];
    const Field& fd = h.Fields[k];
    const Source& src = body.Sources[k];
    const unsigned char* base =
      src.Base + i0 * src.Stride + (perField ? 0 : c * static_cast<size_t>(fd.Size));
    switch (s.Array->GetDataType())
    {
      vtkTemplateMacro(Gather(fd.Type, fd.Size, base, src.Stride, m,
        static_cast<VTK_TT*>(s.Array->GetVoidPointer(0)) + i0 * comps + c, comps));
    }
  }
}

// Leaves out the points without a position (x, y or z NaN or infinite: the
// empty cells of organised clouds) from every array; returns how many.
template <typename Real>
size_t DropPointsWithoutPosition(const Arrays& a, const Real* p, size_t n)
{
  std::vector<unsigned char> valid;
  size_t bad = 0;
  for (size_t i = 0; i < n; ++i)
  {
    if (!(std::isfinite(p[3 * i]) && std::isfinite(p[3 * i + 1]) && std::isfinite(p[3 * i + 2])))
    {
      if (valid.empty())
      {
        valid.assign(n, 1);
      }
      valid[i] = 0;
      ++bad;
    }
  }
  for (const Sink& s : a.Sinks)
  {
    if (!bad)
    {
      break;
    }
    vtkDataArray* array = s.Array;
    const size_t tuple = static_cast<size_t>(array->GetDataTypeSize()) * s.Components;
    unsigned char* bytes = static_cast<unsigned char*>(array->GetVoidPointer(0));
    size_t w = 0;
    for (size_t i = 0; i < n; ++i)
    {
      if (valid[i])
      {
        if (w != i)
        {
          std::memcpy(bytes + w * tuple, bytes + i * tuple, tuple);
        }
        ++w;
      }
    }
    array->SetNumberOfTuples(static_cast<vtkIdType>(n - bad));
    array->Squeeze();
  }
  return bad;
}

// Sizes every output array for n points; false, with the message, where
// the memory cannot be had.
bool AllocateArrays(const Arrays& a, size_t n, const std::string& file, std::string& error)
{
  for (const Sink& s : a.Sinks)
  {
    s.Array->SetNumberOfComponents(s.Components);
    s.Array->SetNumberOfTuples(static_cast<vtkIdType>(n));
    if (static_cast<size_t>(s.Array->GetNumberOfTuples()) != n)
    {
      error = file + ": cannot allocate memory for " + Plural(n, "point", "points") + " (array " +
        s.Array->GetName() + " of " + std::to_string(s.Components) + " component(s))";
      return false;
    }
  }
  return true;
}

// What the reader says of the `bad` points of n it left out
// (DropPointsWithoutPosition).
std::string SkippedPointsWarning(const std::string& file, const Header& h, size_t n, size_t bad)
{
  const std::string organised = h.Height > 1
    ? " (empty cells of the organised " + std::to_string(h.Width) + " x " + std::to_string(h.Height) +
      " cloud)"
    : std::string();
  return file + ": skipped " + std::to_string(bad) + " of " + Plural(n, "point", "points") +
    " whose x, y or z is NaN or infinite" + organised + "; kept " + std::to_string(n - bad) +
    " (field data SkippedPointCount)";
}

void AddPointData(vtkPolyData* output, const Arrays& a)
{
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetData(a.Points);
  output->SetPoints(points);
  vtkPointData* pd = output->GetPointData();
  if (a.Colors)
  {
    pd->AddArray(a.Colors);
    pd->SetScalars(a.Colors);
  }
  if (a.Normals)
  {
    pd->SetNormals(a.Normals);
  }
  if (a.Intensity)
  {
    pd->AddArray(a.Intensity);
    if (!a.Colors)
    {
      pd->SetActiveScalars(a.Intensity->GetName());
    }
  }
  for (auto& extra : a.Extras)
  {
    pd->AddArray(extra);
  }
}

// SkippedPointCount, and what the header says of the cloud: PCDWidth,
// PCDHeight, PCDViewpoint.
void AddFieldData(vtkPolyData* output, const Header& h, vtkIdType skipped)
{
  vtkFieldData* fd = output->GetFieldData();
  for (const auto& value : { std::make_pair("SkippedPointCount", skipped),
         std::make_pair("PCDWidth", static_cast<vtkIdType>(h.Width)),
         std::make_pair("PCDHeight", static_cast<vtkIdType>(h.Height)) })
  {
    auto a = vtkSmartPointer<vtkIdTypeArray>::New();
    a->SetName(value.first);
    a->InsertNextValue(value.second);
    fd->AddArray(a);
  }
  auto viewpoint = vtkSmartPointer<vtkDoubleArray>::New();
  viewpoint->SetName("PCDViewpoint");
  for (double v : h.Viewpoint)
  {
    viewpoint->InsertNextValue(v);
  }
  fd->AddArray(viewpoint);
}
} // namespace

//------------------------------------------------------------------------------
vtkPCDReader::vtkPCDReader() = default;

//------------------------------------------------------------------------------
vtkPCDReader::~vtkPCDReader() = default;

//------------------------------------------------------------------------------
int vtkPCDReader::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  this->FieldNames.clear();
  this->DataEncoding.clear();
  this->NumberOfSkippedPoints = 0;
  return this->Superclass::RequestData(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
bool vtkPCDReader::ReadPoints(const char* data, size_t size, vtkPolyData* output)
{
  const std::string file = this->FileName;
  Header h;
  std::string error;
  if (!ParseHeader(data, size, file, h, error))
  {
    this->Fail(error);
    return false;
  }
  for (const Field& f : h.Fields)
  {
    this->FieldNames += (this->FieldNames.empty() ? "" : " ") + f.Name;
  }
  this->DataEncoding = EncodingName(h.Data);
  std::vector<std::string> warnings = h.Warnings;

  // Progress [0, decoded] decodes the body (ascii, LZF), the rest converts.
  const double decoded = DecodingShare(h.Data);
  bool aborted = false;
  Body body;
  if (!ReadBody(data, size, h, file, body, error, warnings, [&](double done) {
        aborted = aborted || !this->ContinueReading(decoded * done);
        return !aborted;
      }))
  {
    aborted ? this->FailAborted() : this->Fail(error);
    return false;
  }
  this->UpdateProgress(decoded);

  const size_t n = static_cast<size_t>(h.Points);
  const bool real64 = this->OutputPointsPrecision == DOUBLE_PRECISION;
  Arrays arrays = MakeArrays(h, real64);
  if (!AllocateArrays(arrays, n, file, error))
  {
    this->Fail(error);
    return false;
  }
  for (size_t i0 = 0; i0 < n; i0 += ChunkPoints)
  {
    const size_t m = std::min(ChunkPoints, n - i0);
    for (const Sink& s : arrays.Sinks)
    {
      Convert(h, body, s, i0, m);
    }
    if (!this->ContinueReading(
          decoded + (0.95 - decoded) * static_cast<double>(i0 + m) / static_cast<double>(n)))
    {
      this->FailAborted();
      return false;
    }
  }

  const size_t bad = real64
    ? DropPointsWithoutPosition(arrays, vtkDoubleArray::SafeDownCast(arrays.Points)->GetPointer(0), n)
    : DropPointsWithoutPosition(arrays, vtkFloatArray::SafeDownCast(arrays.Points)->GetPointer(0), n);
  if (bad)
  {
    this->NumberOfSkippedPoints = static_cast<vtkIdType>(bad);
    warnings.push_back(SkippedPointsWarning(file, h, n, bad));
  }
  AddPointData(output, arrays);
  AddFieldData(output, h, this->NumberOfSkippedPoints);
  for (const std::string& w : warnings)
  {
    vtkWarningMacro(<< w);
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkPCDReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfSkippedPoints: " << this->NumberOfSkippedPoints << "\n";
  os << indent << "FieldNames: " << this->FieldNames << "\n";
  os << indent << "DataEncoding: " << this->DataEncoding << "\n";
}
