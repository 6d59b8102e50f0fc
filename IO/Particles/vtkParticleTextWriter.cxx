#include "vtkParticleTextWriter.h"

#include "vtkDataArray.h"
#include "vtkErrorCode.h"
#include "vtkInformation.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkParticleTextWriter);

namespace
{
// Shortest round-trip text of a value in the array's own precision.
inline char* Put(char* p, char* end, double v, bool isFloat)
{
  auto r = isFloat ? std::to_chars(p, end, static_cast<float>(v)) : std::to_chars(p, end, v);
  return r.ptr;
}

// One column of the file: a component of an array, written as an integer
// (colours) or in the array's own precision.
struct Column
{
  std::string Name;
  vtkDataArray* Array;
  int Component;
  bool IsFloat;
  bool IsColor;
};

// The columns the file gets: x y z; r g b from "Colors"; the attributes the
// reader knows by name; with writeAll every other named one-component
// array whose name can stand in a header line.
std::vector<Column> ColumnsOf(vtkPointSet* input, bool writeAll)
{
  std::vector<Column> cols;
  vtkPoints* pts = input->GetPoints();
  if (input->GetNumberOfPoints() > 0 && pts)
  {
    const bool f = pts->GetDataType() != VTK_DOUBLE;
    for (int c = 0; c < 3; ++c)
    {
      cols.push_back({ std::string(1, "xyz"[c]), pts->GetData(), c, f, false });
    }
  }
  vtkPointData* pd = input->GetPointData();
  vtkDataArray* colors = pd->GetArray("Colors");
  if (colors && colors->GetNumberOfComponents() >= 3)
  {
    for (int c = 0; c < 3; ++c)
    {
      cols.push_back({ std::string(1, "rgb"[c]), colors, c, false, true });
    }
  }
  std::vector<std::string> used = { "Colors" };
  for (const char* name : { "Reflectivity", "Refraction", "Scalars" })
  {
    vtkDataArray* a = pd->GetArray(name);
    if (a && a->GetNumberOfComponents() == 1)
    {
      std::string lower = name;
      lower[0] = static_cast<char>(std::tolower(lower[0]));
      if (lower == "scalars")
      {
        lower = "scalar";
      }
      cols.push_back({ lower, a, 0, a->GetDataType() != VTK_DOUBLE, false });
      used.emplace_back(name);
    }
  }
  for (int i = 0; writeAll && i < pd->GetNumberOfArrays(); ++i)
  {
    vtkDataArray* a = pd->GetArray(i);
    if (!a || !a->GetName() || a->GetNumberOfComponents() != 1)
    {
      continue;
    }
    const std::string name = a->GetName();
    if (std::find(used.begin(), used.end(), name) == used.end() &&
      name.find_first_of(" \t,#") == std::string::npos)
    {
      cols.push_back({ name, a, 0, a->GetDataType() != VTK_DOUBLE, false });
      used.push_back(name);
    }
  }
  return cols;
}

// The header line and a line per point, through a 1 MiB buffer; false when
// a write failed. progress(fraction) every 65536 points.
bool WriteRows(std::FILE* f, const std::vector<Column>& cols, vtkIdType n, const std::function<void(double)>& progress)
{
  std::string header = "#";
  for (const auto& c : cols)
  {
    header += " " + c.Name;
  }
  header += "\n";
  bool ok = std::fwrite(header.data(), 1, header.size(), f) == header.size();
  std::vector<char> buf(1 << 20);
  char* p = buf.data();
  char* end = buf.data() + buf.size();
  auto flush = [&] {
    ok = ok && std::fwrite(buf.data(), 1, p - buf.data(), f) == static_cast<size_t>(p - buf.data());
    p = buf.data();
  };
  for (vtkIdType i = 0; i < n && ok; ++i)
  {
    if (end - p < static_cast<ptrdiff_t>(32 * cols.size() + 2))
    {
      flush();
    }
    for (size_t c = 0; c < cols.size(); ++c)
    {
      if (c)
      {
        *p++ = ' ';
      }
      const double v = cols[c].Array->GetComponent(i, cols[c].Component);
      p = cols[c].IsColor ? std::to_chars(p, end, static_cast<int>(v)).ptr : Put(p, end, v, cols[c].IsFloat);
    }
    *p++ = '\n';
    if ((i & 0xffff) == 0)
    {
      progress(static_cast<double>(i) / n);
    }
  }
  flush();
  return ok;
}
} // namespace

//------------------------------------------------------------------------------
vtkParticleTextWriter::vtkParticleTextWriter() = default;

//------------------------------------------------------------------------------
vtkParticleTextWriter::~vtkParticleTextWriter()
{
  this->SetFileName(nullptr);
}

//------------------------------------------------------------------------------
int vtkParticleTextWriter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return 1;
}

//------------------------------------------------------------------------------
void vtkParticleTextWriter::WriteData()
{
  vtkPointSet* input = vtkPointSet::SafeDownCast(this->GetInput());
  if (!input || !this->FileName)
  {
    vtkErrorMacro(<< "a point set input and a file name are needed");
    return;
  }
  const std::vector<Column> cols = ColumnsOf(input, this->WriteAllArrays);
  std::FILE* f = std::fopen(this->FileName, "wb");
  if (!f)
  {
    // The error code makes Write() return 0, as VTK's own writers do.
    this->SetErrorCode(vtkErrorCode::CannotOpenFileError);
    vtkErrorMacro(<< this->FileName << ": cannot open for writing");
    return;
  }
  bool ok = WriteRows(f, cols, input->GetNumberOfPoints(), [this](double done) { this->UpdateProgress(done); });
  ok = (std::fclose(f) == 0) && ok;
  if (!ok)
  {
    this->SetErrorCode(vtkErrorCode::OutOfDiskSpaceError);
    vtkErrorMacro(<< this->FileName << ": write failed (disk full?)");
  }
}

//------------------------------------------------------------------------------
void vtkParticleTextWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "WriteAllArrays: " << this->WriteAllArrays << "\n";
}
