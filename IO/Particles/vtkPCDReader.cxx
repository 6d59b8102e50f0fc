#include "vtkPCDReader.h"

#include "octorayLZF.h"
#include "octorayPCDAscii.h"
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
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <vector>

vtkStandardNewMacro(vtkPCDReader);

namespace
{
using namespace octoray::pcd;

// Points converted between two progress reports (and abort checks).
constexpr size_t ChunkPoints = size_t(1) << 16;

// Where the values of one field are: point i's first value at
// Base + i * Stride, its value c at + c * Size.
struct Source
{
  const unsigned char* Base = nullptr;
  size_t Stride = 0;
};

// An output array filled from one or more fields.
struct Sink
{
  enum Kind
  {
    Points,
    Colors,
    Values // float (or Real for the points) arrays, component by component
  };
  Kind What = Values;
  std::vector<int> Fields; // Points / Normals: 3 fields of one value; else one field
  vtkSmartPointer<vtkDataArray> Array;
  int Components = 1;
};

// PCL's writer leaves zeros after a compressed block (it reserves room for
// the block before it knows its size): those are no data left unread.
bool AllZero(const unsigned char* p, size_t n)
{
  for (size_t i = 0; i < n; ++i)
  {
    if (p[i])
    {
      return false;
    }
  }
  return true;
}

std::string Plural(uint64_t n, const char* one, const char* many)
{
  return std::to_string(n) + " " + (n == 1 ? one : many);
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

  const size_t n = static_cast<size_t>(h.Points);
  const size_t nfields = h.Fields.size();
  const unsigned char* const body = reinterpret_cast<const unsigned char*>(data) + h.DataOffset;
  const size_t available = size - h.DataOffset;
  std::vector<Source> sources(nfields);
  // The ascii values, or the inflated block; not zero-filled (every byte is
  // written before it is read).
  std::unique_ptr<unsigned char[]> buffer;
  bool aborted = false;
  auto aborting = [&]() {
    if (this->GetAbortExecute())
    {
      aborted = true;
    }
    return aborted;
  };
  // Progress [0, decodeEnd] decodes the body (ascii, LZF), the rest converts.
  double decodeEnd = 0.0;

  if (h.Data == Encoding::Ascii)
  {
    decodeEnd = 0.7;
    // Each value takes at least one character and a separator: a body too
    // short for that cannot hold the points (and the buffer is not made).
    uint64_t least = 0;
    if (n > 0 &&
      (!CheckedMultiply(n, 2 * static_cast<uint64_t>(h.ValuesPerPoint), least) ||
        available + 1 < least))
    {
      const size_t lines = CountNonBlankLines(data + h.DataOffset, data + size).Count;
      this->Fail(file + ": the ascii data after the DATA line (line " +
        std::to_string(h.DataLine) + ") has " + Plural(lines, "line", "lines") + " in " +
        Plural(available, "byte", "bytes") + "; the header promises POINTS " +
        std::to_string(n) + " of " + std::to_string(h.ValuesPerPoint) + " value(s) each");
      return false;
    }
    // The parse writes every value but those of padding fields, which
    // nothing reads.
    buffer.reset(new unsigned char[std::max<size_t>(n * h.PointStep, 1)]);
    const bool parsed = ParseAscii(data + h.DataOffset, data + size, h.DataLine + 1, h, file,
      buffer.get(), error, warnings, [&](uint64_t done) {
        this->UpdateProgress(decodeEnd * static_cast<double>(done) / static_cast<double>(n));
        return !aborting();
      });
    if (!parsed)
    {
      aborted ? this->FailAborted() : this->Fail(error);
      return false;
    }
    for (size_t f = 0; f < nfields; ++f)
    {
      sources[f] = { buffer.get() + h.Fields[f].Offset, h.PointStep };
    }
  }
  else if (h.Data == Encoding::Binary)
  {
    const size_t need = n * h.PointStep;
    if (available < need)
    {
      this->Fail(file + ": the binary data is shorter than the header promises: POINTS " +
        std::to_string(n) + " x " + std::to_string(h.PointStep) + " bytes = " +
        std::to_string(need) + " bytes after the header (from byte " +
        std::to_string(h.DataOffset) + "), the file has " + Plural(available, "byte", "bytes") +
        " (" + Plural(h.PointStep ? available / h.PointStep : 0, "whole point", "whole points") +
        ")");
      return false;
    }
    if (available > need && !AllZero(body + need, available - need))
    {
      warnings.push_back(file + ": " + Plural(available - need, "byte", "bytes") +
        " (not all zero) after the binary data of the " + Plural(n, "point", "points") +
        " were ignored");
    }
    for (size_t f = 0; f < nfields; ++f)
    {
      sources[f] = { body + h.Fields[f].Offset, h.PointStep };
    }
  }
  else
  {
    decodeEnd = 0.6;
    if (available < 8)
    {
      this->Fail(file + ": the binary_compressed data is cut off: its 8-byte block header "
                        "(compressed and uncompressed sizes) needs 8 bytes after the header, "
                        "the file has " +
        Plural(available, "byte", "bytes"));
      return false;
    }
    uint32_t compressed = 0, uncompressed = 0;
    std::memcpy(&compressed, body, 4);
    std::memcpy(&uncompressed, body + 4, 4);
    const size_t expected = n * h.PackedStep;
    const std::string sizes = " (the block header at byte " + std::to_string(h.DataOffset) +
      " says " + std::to_string(compressed) + " bytes compressed, " +
      std::to_string(uncompressed) + " uncompressed)";
    if (compressed > available - 8)
    {
      this->Fail(file + ": the binary_compressed data is shorter than its block header says: " +
        std::to_string(compressed) + " bytes of LZF data expected after the 8-byte block "
                                     "header, the file has " +
        Plural(available - 8, "byte", "bytes") + sizes);
      return false;
    }
    if (uncompressed != expected)
    {
      this->Fail(file + ": the binary_compressed block does not match the header: it inflates "
                        "to " +
        std::to_string(uncompressed) + " bytes, POINTS " + std::to_string(n) + " x " +
        std::to_string(h.PackedStep) + " bytes (the fields without padding) = " +
        std::to_string(expected) + sizes);
      return false;
    }
    if (uncompressed > static_cast<uint64_t>(compressed) * LzfMaximumExpansion)
    {
      this->Fail(file + ": the binary_compressed block is inconsistent: " +
        std::to_string(compressed) + " bytes of LZF cannot inflate to " +
        std::to_string(uncompressed) + " (at most " + std::to_string(LzfMaximumExpansion) +
        " times as many)" + sizes);
      return false;
    }
    if (available - 8 > compressed && !AllZero(body + 8 + compressed, available - 8 - compressed))
    {
      warnings.push_back(file + ": " + Plural(available - 8 - compressed, "byte", "bytes") +
        " (not all zero) after the compressed block were ignored");
    }
    buffer.reset(new unsigned char[std::max<size_t>(uncompressed, 1)]);
    const bool inflated = LzfDecompress(body + 8, compressed, buffer.get(), uncompressed,
      error, [&](size_t done) {
        this->UpdateProgress(
          decodeEnd * static_cast<double>(done) / static_cast<double>(uncompressed));
        return !aborting();
      });
    if (!inflated)
    {
      aborted ? this->FailAborted()
              : this->Fail(file + ": corrupt binary_compressed data (LZF): " + error + sizes);
      return false;
    }
    for (size_t f = 0; f < nfields; ++f)
    {
      const Field& fd = h.Fields[f];
      // Padding fields are not in the block; nothing reads them.
      sources[f] = { fd.Padding() ? nullptr : buffer.get() + n * fd.PackedOffset, fd.Bytes() };
    }
  }
  this->UpdateProgress(decodeEnd);

  // ---- Output arrays.
  std::vector<Sink> sinks;
  std::vector<bool> used(nfields, false);
  auto field = [&](const char* name) { return h.Find(name); };
  vtkSmartPointer<vtkDataArray> pointsArray;
  if (this->OutputPointsPrecision == DOUBLE_PRECISION)
  {
    pointsArray = vtkSmartPointer<vtkDoubleArray>::New();
  }
  else
  {
    pointsArray = vtkSmartPointer<vtkFloatArray>::New();
  }
  pointsArray->SetName("Points");
  {
    Sink s;
    s.What = Sink::Points;
    s.Fields = { field("x"), field("y"), field("z") };
    s.Array = pointsArray;
    s.Components = 3;
    sinks.push_back(s);
  }
  vtkSmartPointer<vtkUnsignedCharArray> colors;
  for (const char* name : { "rgba", "rgb" })
  {
    const int k = field(name);
    if (!colors && k >= 0 && h.Fields[k].Size == 4 && h.Fields[k].Count == 1)
    {
      colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
      colors->SetName("Colors");
      Sink s;
      s.What = Sink::Colors;
      s.Fields = { k };
      s.Array = colors;
      s.Components = std::strcmp(name, "rgba") == 0 ? 4 : 3;
      sinks.push_back(s);
    }
  }
  vtkSmartPointer<vtkFloatArray> normals;
  {
    const int nx = field("normal_x"), ny = field("normal_y"), nz = field("normal_z");
    if (nx >= 0 && ny >= 0 && nz >= 0 && h.Fields[nx].Count == 1 && h.Fields[ny].Count == 1 &&
      h.Fields[nz].Count == 1)
    {
      normals = vtkSmartPointer<vtkFloatArray>::New();
      normals->SetName("Normals");
      Sink s;
      s.Fields = { nx, ny, nz };
      s.Array = normals;
      s.Components = 3;
      sinks.push_back(s);
    }
  }
  for (const Sink& s : sinks)
  {
    for (int k : s.Fields)
    {
      used[k] = true;
    }
  }
  vtkSmartPointer<vtkFloatArray> intensity;
  std::vector<vtkSmartPointer<vtkFloatArray>> extras;
  for (size_t f = 0; f < nfields; ++f)
  {
    const Field& fd = h.Fields[f];
    if (used[f] || fd.Padding())
    {
      continue;
    }
    auto a = vtkSmartPointer<vtkFloatArray>::New();
    a->SetName(fd.Name == "intensity" ? "Intensity" : fd.Name.c_str());
    Sink s;
    s.Fields = { static_cast<int>(f) };
    s.Array = a;
    s.Components = static_cast<int>(fd.Count);
    sinks.push_back(s);
    if (fd.Name == "intensity")
    {
      intensity = a;
    }
    else
    {
      extras.push_back(a);
    }
  }
  for (Sink& s : sinks)
  {
    s.Array->SetNumberOfComponents(s.Components);
    s.Array->SetNumberOfTuples(static_cast<vtkIdType>(n));
    if (static_cast<size_t>(s.Array->GetNumberOfTuples()) != n)
    {
      this->Fail(file + ": cannot allocate memory for " + Plural(n, "point", "points") +
        " (array " + s.Array->GetName() + " of " + std::to_string(s.Components) +
        " component(s))");
      return false;
    }
  }

  // ---- Conversion, chunk by chunk of points.
  const bool real64 = this->OutputPointsPrecision == DOUBLE_PRECISION;
  for (size_t i0 = 0; i0 < n; i0 += ChunkPoints)
  {
    const size_t m = std::min(ChunkPoints, n - i0);
    for (const Sink& s : sinks)
    {
      const size_t comps = static_cast<size_t>(s.Components);
      if (s.What == Sink::Colors)
      {
        const Source& src = sources[s.Fields[0]];
        UnpackColors(src.Base + i0 * src.Stride, src.Stride, m,
          static_cast<vtkUnsignedCharArray*>(s.Array.Get())->GetPointer(0) + i0 * comps,
          s.Components);
        continue;
      }
      // Three fields of one value each (points, normals), or one field of
      // `comps` values.
      const bool perField = s.Fields.size() > 1;
      for (size_t c = 0; c < comps; ++c)
      {
        const Field& fd = h.Fields[perField ? s.Fields[c] : s.Fields[0]];
        const Source& src = sources[perField ? s.Fields[c] : s.Fields[0]];
        const unsigned char* base =
          src.Base + i0 * src.Stride + (perField ? 0 : c * static_cast<size_t>(fd.Size));
        if (s.What == Sink::Points && real64)
        {
          double* out = static_cast<vtkDoubleArray*>(s.Array.Get())->GetPointer(0);
          Gather(fd.Type, fd.Size, base, src.Stride, m, out + i0 * comps + c, comps);
        }
        else
        {
          float* out = static_cast<vtkFloatArray*>(s.Array.Get())->GetPointer(0);
          Gather(fd.Type, fd.Size, base, src.Stride, m, out + i0 * comps + c, comps);
        }
      }
    }
    this->UpdateProgress(decodeEnd +
      (0.95 - decodeEnd) * static_cast<double>(i0 + m) / static_cast<double>(n));
    if (aborting())
    {
      this->FailAborted();
      return false;
    }
  }

  // ---- Points without a position (NaN cells of organised clouds): left out.
  size_t kept = n;
  {
    std::vector<unsigned char> valid;
    size_t bad = 0;
    auto check = [&](auto* p) {
      for (size_t i = 0; i < n; ++i)
      {
        if (!(std::isfinite(p[3 * i]) && std::isfinite(p[3 * i + 1]) &&
              std::isfinite(p[3 * i + 2])))
        {
          if (valid.empty())
          {
            valid.assign(n, 1);
          }
          valid[i] = 0;
          ++bad;
        }
      }
    };
    if (real64)
    {
      check(static_cast<vtkDoubleArray*>(pointsArray.Get())->GetPointer(0));
    }
    else
    {
      check(static_cast<vtkFloatArray*>(pointsArray.Get())->GetPointer(0));
    }
    if (bad)
    {
      kept = n - bad;
      for (const Sink& s : sinks)
      {
        vtkDataArray* a = s.Array;
        const size_t tuple = static_cast<size_t>(a->GetDataTypeSize()) * s.Components;
        unsigned char* p = static_cast<unsigned char*>(a->GetVoidPointer(0));
        size_t w = 0;
        for (size_t i = 0; i < n; ++i)
        {
          if (valid[i])
          {
            if (w != i)
            {
              std::memcpy(p + w * tuple, p + i * tuple, tuple);
            }
            ++w;
          }
        }
        a->SetNumberOfTuples(static_cast<vtkIdType>(kept));
        a->Squeeze();
      }
      this->NumberOfSkippedPoints = static_cast<vtkIdType>(bad);
      warnings.push_back(file + ": skipped " + std::to_string(bad) + " of " +
        Plural(n, "point", "points") + " whose x, y or z is NaN or infinite" +
        (h.Height > 1 ? " (empty cells of the organised " + std::to_string(h.Width) + " x " +
              std::to_string(h.Height) + " cloud)"
                      : std::string()) +
        "; kept " + std::to_string(kept) + " (field data SkippedPointCount)");
    }
  }

  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetData(pointsArray);
  output->SetPoints(points);
  vtkPointData* pd = output->GetPointData();
  if (colors)
  {
    pd->AddArray(colors);
    pd->SetScalars(colors);
  }
  if (normals)
  {
    pd->SetNormals(normals);
  }
  if (intensity)
  {
    pd->AddArray(intensity);
    if (!colors)
    {
      pd->SetActiveScalars(intensity->GetName());
    }
  }
  for (auto& a : extras)
  {
    pd->AddArray(a);
  }
  vtkFieldData* fd = output->GetFieldData();
  auto skipped = vtkSmartPointer<vtkIdTypeArray>::New();
  skipped->SetName("SkippedPointCount");
  skipped->InsertNextValue(this->NumberOfSkippedPoints);
  fd->AddArray(skipped);
  auto width = vtkSmartPointer<vtkIdTypeArray>::New();
  width->SetName("PCDWidth");
  width->InsertNextValue(static_cast<vtkIdType>(h.Width));
  fd->AddArray(width);
  auto height = vtkSmartPointer<vtkIdTypeArray>::New();
  height->SetName("PCDHeight");
  height->InsertNextValue(static_cast<vtkIdType>(h.Height));
  fd->AddArray(height);
  auto viewpoint = vtkSmartPointer<vtkDoubleArray>::New();
  viewpoint->SetName("PCDViewpoint");
  for (double v : h.Viewpoint)
  {
    viewpoint->InsertNextValue(v);
  }
  fd->AddArray(viewpoint);

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
