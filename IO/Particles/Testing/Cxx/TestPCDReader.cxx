// vtkPCDReader on PCD files this test writes itself, from known values, in
// all three DATA forms (binary_compressed through an LZF compressor of its
// own that also makes overlapping back-references): every value read back,
// rgb/rgba packing, an organised cloud with NaN cells, each error by its
// message, the previous output kept after a failure, abort, and random,
// truncated and bit-flipped files that must give an error, never a crash.
#include "octorayLZF.h"
#include "octorayTestCheck.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkPCDReader.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkTestUtilities.h"
#include "vtkUnsignedCharArray.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace
{
std::string Dir;

std::string Path(const std::string& name)
{
  return Dir + "/" + name;
}

void WriteFile(const std::string& path, const std::string& bytes)
{
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// ---- An LZF compressor (the test's own, from the format's description):
// greedy matches of at least 3 bytes found through a hash of the next three
// bytes, distances up to 8192, lengths up to 264, literal runs up to 32.
// Runs of one repeated byte become back-references of distance 1 that
// overlap the bytes they write.
struct LzfStats
{
  size_t Literals = 0;
  size_t References = 0;
  size_t Overlapping = 0; // distance < length
  size_t Long = 0;        // length >= 9 (the 3-byte form)
};

std::string LzfCompress(const std::string& in, LzfStats* stats = nullptr)
{
  const size_t n = in.size();
  const unsigned char* s = reinterpret_cast<const unsigned char*>(in.data());
  std::string out;
  std::string literal;
  auto flush = [&]() {
    for (size_t i = 0; i < literal.size(); i += 32)
    {
      const size_t run = std::min<size_t>(32, literal.size() - i);
      out += static_cast<char>(run - 1);
      out.append(literal, i, run);
      if (stats)
        ++stats->Literals;
    }
    literal.clear();
  };
  std::vector<int64_t> table(1 << 14, -1);
  auto hash = [&](size_t i) { return ((s[i] << 16 | s[i + 1] << 8 | s[i + 2]) * 2654435761u) >> 18; };
  size_t i = 0;
  while (i < n)
  {
    if (i + 3 <= n)
    {
      const size_t hv = hash(i) & ((1 << 14) - 1);
      const int64_t cand = table[hv];
      table[hv] = static_cast<int64_t>(i);
      if (cand >= 0 && i - static_cast<size_t>(cand) <= 8192 &&
        std::memcmp(s + cand, s + i, 3) == 0)
      {
        size_t len = 3;
        while (i + len < n && len < 264 && s[cand + len] == s[i + len])
        {
          ++len;
        }
        flush();
        const size_t distance = i - static_cast<size_t>(cand);
        const size_t d = distance - 1;
        const size_t l = len - 2;
        if (l < 7)
        {
          out += static_cast<char>((l << 5) | (d >> 8));
        }
        else
        {
          out += static_cast<char>((7 << 5) | (d >> 8));
          out += static_cast<char>(l - 7);
        }
        out += static_cast<char>(d & 255);
        if (stats)
        {
          ++stats->References;
          stats->Overlapping += distance < len;
          stats->Long += len >= 9;
        }
        i += len;
        continue;
      }
    }
    literal += static_cast<char>(s[i]);
    ++i;
  }
  flush();
  return out;
}

// The test's own LZF decoder is not used: the reader's decoding of the
// compressed files, compared value by value with what was written, is the
// check of both.

// ---- A PCD writer for known values.
struct FieldSpec
{
  std::string Name;
  char Type;
  int Size;
  int Count;
};

// values[point][k]: the k-th value of the point over all fields and counts.
using Values = std::vector<std::vector<double>>;

void Put(std::string& out, char type, int size, double v)
{
  unsigned char b[8];
  switch (type == 'F' ? size : type == 'I' ? -size : 16 + size)
  {
    case 4:
    {
      float f = static_cast<float>(v);
      std::memcpy(b, &f, 4);
      break;
    }
    case 8:
      std::memcpy(b, &v, 8);
      break;
    case -1:
    {
      int8_t x = static_cast<int8_t>(v);
      std::memcpy(b, &x, 1);
      break;
    }
    case -2:
    {
      int16_t x = static_cast<int16_t>(v);
      std::memcpy(b, &x, 2);
      break;
    }
    case -4:
    {
      int32_t x = static_cast<int32_t>(v);
      std::memcpy(b, &x, 4);
      break;
    }
    case -8:
    {
      int64_t x = static_cast<int64_t>(v);
      std::memcpy(b, &x, 8);
      break;
    }
    case 17:
    {
      uint8_t x = static_cast<uint8_t>(v);
      std::memcpy(b, &x, 1);
      break;
    }
    case 18:
    {
      uint16_t x = static_cast<uint16_t>(v);
      std::memcpy(b, &x, 2);
      break;
    }
    case 20:
    {
      uint32_t x = static_cast<uint32_t>(v);
      std::memcpy(b, &x, 4);
      break;
    }
    default:
    {
      uint64_t x = static_cast<uint64_t>(v);
      std::memcpy(b, &x, 8);
      break;
    }
  }
  out.append(reinterpret_cast<char*>(b), static_cast<size_t>(size));
}

std::string Text(char type, int size, double v)
{
  char buf[64];
  if (std::isnan(v))
    return "nan";
  if (type == 'F')
    std::snprintf(buf, sizeof(buf), size == 4 ? "%.9g" : "%.17g", size == 4 ? static_cast<double>(static_cast<float>(v)) : v);
  else if (type == 'I')
    std::snprintf(buf, sizeof(buf), "%lld", static_cast<long long>(v));
  else
    std::snprintf(buf, sizeof(buf), "%llu", static_cast<unsigned long long>(v));
  return buf;
}

// A packed colour as the float whose bits it is (how PCL stores rgb).
double PackedFloat(uint32_t bits)
{
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}

std::string Header(const std::vector<FieldSpec>& fields, size_t width, size_t height,
  const std::string& data)
{
  std::string h = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS";
  for (auto& f : fields)
    h += " " + f.Name;
  h += "\nSIZE";
  for (auto& f : fields)
    h += " " + std::to_string(f.Size);
  h += "\nTYPE";
  for (auto& f : fields)
    h += std::string(" ") + f.Type;
  h += "\nCOUNT";
  for (auto& f : fields)
    h += " " + std::to_string(f.Count);
  h += "\nWIDTH " + std::to_string(width) + "\nHEIGHT " + std::to_string(height) +
    "\nVIEWPOINT 1 2 3 1 0 0 0\nPOINTS " + std::to_string(width * height) + "\nDATA " + data +
    "\n";
  return h;
}

// rgb/rgba values are given as their packed uint32; written as the declared
// type's bits (F: the float with those bits).
bool IsColour(const FieldSpec& f)
{
  return (f.Name == "rgb" || f.Name == "rgba") && f.Size == 4;
}

std::string Encode(const std::vector<FieldSpec>& fields, size_t width, size_t height,
  const Values& values, const std::string& form, LzfStats* stats = nullptr)
{
  std::string out = Header(fields, width, height, form);
  const size_t n = width * height;
  if (form == "ascii")
  {
    for (size_t p = 0; p < n; ++p)
    {
      size_t k = 0;
      std::string line;
      for (auto& f : fields)
      {
        for (int c = 0; c < f.Count; ++c, ++k)
        {
          const double v = values[p][k];
          // PCL writes a packed colour as its uint32, whatever its TYPE.
          line += (line.empty() ? "" : " ") +
            (IsColour(f) ? std::to_string(static_cast<uint32_t>(v)) : Text(f.Type, f.Size, v));
        }
      }
      out += line + "\n";
    }
    return out;
  }
  auto put = [&](std::string& s, const FieldSpec& f, double v) {
    if (IsColour(f))
    {
      const uint32_t bits = static_cast<uint32_t>(v);
      s.append(reinterpret_cast<const char*>(&bits), 4);
    }
    else
    {
      Put(s, f.Type, f.Size, v);
    }
  };
  if (form == "binary")
  {
    for (size_t p = 0; p < n; ++p)
    {
      size_t k = 0;
      for (auto& f : fields)
        for (int c = 0; c < f.Count; ++c, ++k)
          put(out, f, values[p][k]);
    }
    return out;
  }
  // binary_compressed: one array per field (padding left out), compressed.
  std::string block;
  size_t first = 0;
  for (auto& f : fields)
  {
    if (f.Name != "_")
    {
      for (size_t p = 0; p < n; ++p)
        for (int c = 0; c < f.Count; ++c)
          put(block, f, values[p][first + c]);
    }
    first += f.Count;
  }
  const std::string z = LzfCompress(block, stats);
  const uint32_t sizes[2] = { static_cast<uint32_t>(z.size()), static_cast<uint32_t>(block.size()) };
  out.append(reinterpret_cast<const char*>(sizes), 8);
  return out + z;
}

// ---- Reading with the messages captured.
struct Run
{
  vtkNew<vtkPCDReader> Reader;
  std::vector<std::string> Errors, Warnings;
  vtkNew<vtkCallbackCommand> Callback;
  Run()
  {
    this->Callback->SetClientData(this);
    this->Callback->SetCallback([](vtkObject*, unsigned long event, void* self, void* text) {
      auto* run = static_cast<Run*>(self);
      (event == vtkCommand::ErrorEvent ? run->Errors : run->Warnings)
        .push_back(text ? static_cast<const char*>(text) : "");
    });
    this->Reader->AddObserver(vtkCommand::ErrorEvent, this->Callback);
    this->Reader->AddObserver(vtkCommand::WarningEvent, this->Callback);
    // The executive's own report of the failed request ("Algorithm ...
    // returned failure") is expected with every error: kept out of the log.
    this->Reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, this->Quiet);
  }
  vtkNew<vtkCallbackCommand> Quiet;
  vtkPolyData* Read(const std::string& path)
  {
    this->Errors.clear();
    this->Warnings.clear();
    this->Reader->SetFileName(path.c_str());
    this->Reader->Update();
    return this->Reader->GetOutput();
  }
  std::string Error() const { return this->Reader->GetErrorMessage(); }
};

// A file that must fail with exactly `message` (the file name is prefixed).
void ExpectError(const std::string& name, const std::string& bytes, const std::string& message)
{
  const std::string path = Path(name);
  WriteFile(path, bytes);
  Run run;
  vtkPolyData* out = run.Read(path);
  CHECK_EQ_STR(run.Error(), path + message);
  CHECK(out->GetNumberOfPoints() == 0);
  CHECK(run.Errors.size() == 1);
}

// ---- The main cloud: every kind of field, organised 5 x 4 with NaN cells.
std::vector<FieldSpec> RichFields()
{
  return { { "x", 'F', 4, 1 }, { "y", 'F', 4, 1 }, { "z", 'F', 4, 1 }, { "rgb", 'F', 4, 1 },
    { "intensity", 'F', 4, 1 }, { "normal_x", 'F', 4, 1 }, { "normal_y", 'F', 4, 1 },
    { "normal_z", 'F', 4, 1 }, { "curvature", 'F', 4, 1 }, { "_", 'U', 1, 3 },
    { "label", 'U', 4, 1 }, { "ring", 'U', 2, 1 }, { "flag", 'U', 1, 1 }, { "delta", 'I', 2, 1 },
    { "tiny", 'I', 1, 1 }, { "offset", 'I', 4, 1 }, { "big", 'I', 8, 1 }, { "ubig", 'U', 8, 1 },
    { "time", 'F', 8, 1 }, { "fpfh", 'F', 4, 5 } };
}

Values RichValues(size_t n, const std::vector<size_t>& nanCells)
{
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1000, 1000);
  Values v(n);
  for (size_t p = 0; p < n; ++p)
  {
    const double x = u(rng), y = u(rng), z = u(rng);
    const uint32_t rgb = (static_cast<uint32_t>(p * 37 % 256) << 16) |
      (static_cast<uint32_t>(p * 91 % 256) << 8) | static_cast<uint32_t>(p * 13 % 256);
    v[p] = { x, y, z, static_cast<double>(rgb), u(rng) / 10, 0.6, -0.8, 0.0, u(rng) / 1000,
      1, 2, 3, // padding
      static_cast<double>(4294967295u - p), static_cast<double>(65535 - p), static_cast<double>(p % 256),
      p % 2 ? -32768.0 : 32767.0, p % 2 ? -128.0 : 127.0, -2147483648.0 + static_cast<double>(p),
      -static_cast<double>(int64_t(1) << 40) - static_cast<double>(p), static_cast<double>(uint64_t(1) << 50),
      1.0e9 + p * 0.125, 0.5 * p, 1.0 * p, 2.0 * p, 3.0 * p, -1.0 * p };
    // Non-finite values of other fields stay as they are.
    if (p == 1)
      v[p][4] = std::numeric_limits<double>::quiet_NaN();
    if (p == 2)
      v[p][8] = std::numeric_limits<double>::infinity();
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (size_t c : nanCells)
  {
    v[c][0] = v[c][1] = v[c][2] = nan;
  }
  return v;
}

void CheckRich(vtkPolyData* out, const Values& v, const std::vector<size_t>& nanCells,
  bool doublePoints, const std::string& form)
{
  const size_t n = v.size();
  const size_t kept = n - nanCells.size();
  CHECK(static_cast<size_t>(out->GetNumberOfPoints()) == kept);
  CHECK(static_cast<size_t>(out->GetNumberOfVerts()) == kept);
  CHECK(out->GetPoints()->GetDataType() == (doublePoints ? VTK_DOUBLE : VTK_FLOAT));
  vtkPointData* pd = out->GetPointData();
  auto* colors = vtkUnsignedCharArray::SafeDownCast(pd->GetArray("Colors"));
  CHECK(colors && colors->GetNumberOfComponents() == 3);
  CHECK(pd->GetScalars() == colors);
  CHECK(pd->GetNormals() && pd->GetNormals()->GetNumberOfComponents() == 3 &&
    std::string(pd->GetNormals()->GetName()) == "Normals");
  CHECK(pd->GetArray("Intensity") && pd->GetArray("curvature") && pd->GetArray("fpfh"));
  CHECK(!pd->GetArray("_") && !pd->GetArray("rgb") && !pd->GetArray("normal_x") &&
    !pd->GetArray("intensity"));
  // Arrays: Colors, Normals, Intensity, curvature, label ring flag delta
  // tiny offset big ubig time, fpfh.
  CHECK(pd->GetNumberOfArrays() == 14);
  if (!colors || !pd->GetNormals() || !pd->GetArray("fpfh") || !pd->GetArray("Intensity"))
  {
    return;
  }
  CHECK(pd->GetArray("fpfh")->GetNumberOfComponents() == 5);
  // Each in the type the file stores, its values exact (into float arrays
  // they were rounded: a uint32 label of 4294967295 read 4294967296).
  const char* scalars[] = { "label", "ring", "flag", "delta", "tiny", "offset", "big", "ubig",
    "time" };
  const int scalarIndex[] = { 12, 13, 14, 15, 16, 17, 18, 19, 20 };
  const int scalarType[] = { VTK_UNSIGNED_INT, VTK_UNSIGNED_SHORT, VTK_UNSIGNED_CHAR, VTK_SHORT, VTK_SIGNED_CHAR,
    VTK_INT, VTK_LONG_LONG, VTK_UNSIGNED_LONG_LONG, VTK_DOUBLE };
  size_t bad = 0;
  vtkIdType o = 0;
  for (size_t p = 0; p < n; ++p)
  {
    bool skipped = false;
    for (size_t c : nanCells)
      skipped = skipped || c == p;
    if (skipped)
      continue;
    double pt[3];
    out->GetPoint(o, pt);
    for (int a = 0; a < 3; ++a)
    {
      // The file stores F 4: the same value in float and double output.
      bad += pt[a] != static_cast<double>(static_cast<float>(v[p][a]));
    }
    const uint32_t rgb = static_cast<uint32_t>(v[p][3]);
    bad += colors->GetValue(3 * o) != ((rgb >> 16) & 255);
    bad += colors->GetValue(3 * o + 1) != ((rgb >> 8) & 255);
    bad += colors->GetValue(3 * o + 2) != (rgb & 255);
    auto same = [](double got, double want) {
      const float w = static_cast<float>(want);
      return (std::isnan(got) && std::isnan(w)) || got == static_cast<double>(w);
    };
    bad += !same(pd->GetArray("Intensity")->GetComponent(o, 0), v[p][4]);
    for (int c = 0; c < 3; ++c)
      bad += !same(pd->GetNormals()->GetComponent(o, c), v[p][5 + c]);
    bad += !same(pd->GetArray("curvature")->GetComponent(o, 0), v[p][8]);
    for (int s = 0; s < 9; ++s)
    {
      vtkDataArray* a = pd->GetArray(scalars[s]);
      if (!a || a->GetDataType() != scalarType[s])
      {
        ++bad;
        continue;
      }
      const double want = v[p][scalarIndex[s]];
      if (a->GetComponent(o, 0) != want)
      {
        std::cerr << form << ": point " << p << " " << scalars[s] << " = " << a->GetComponent(o, 0)
                  << ", expected " << want << "\n";
        ++bad;
      }
    }
    for (int c = 0; c < 5; ++c)
      bad += !same(pd->GetArray("fpfh")->GetComponent(o, c), v[p][21 + c]);
    ++o;
  }
  if (bad)
    std::cerr << form << ": " << bad << " value(s) differ\n";
  CHECK(bad == 0);
  vtkFieldData* fd = out->GetFieldData();
  CHECK(fd->GetArray("SkippedPointCount") &&
    fd->GetArray("SkippedPointCount")->GetComponent(0, 0) == static_cast<double>(nanCells.size()));
  CHECK(fd->GetArray("PCDWidth") && fd->GetArray("PCDWidth")->GetComponent(0, 0) == 5);
  CHECK(fd->GetArray("PCDHeight") && fd->GetArray("PCDHeight")->GetComponent(0, 0) == 4);
  CHECK(fd->GetArray("PCDViewpoint") && fd->GetArray("PCDViewpoint")->GetNumberOfTuples() == 7 &&
    fd->GetArray("PCDViewpoint")->GetComponent(2, 0) == 3);
}

void TestRichCloud()
{
  const std::vector<size_t> nanCells = { 0, 7, 19 };
  const Values v = RichValues(20, nanCells);
  for (const char* form : { "ascii", "binary", "binary_compressed" })
  {
    for (bool doublePoints : { false, true })
    {
      const std::string path = Path(std::string("rich_") + form + ".pcd");
      WriteFile(path, Encode(RichFields(), 5, 4, v, form));
      Run run;
      run.Reader->SetOutputPointsPrecision(
        doublePoints ? vtkAlgorithm::DOUBLE_PRECISION : vtkAlgorithm::SINGLE_PRECISION);
      vtkPolyData* out = run.Read(path);
      CHECK_EQ_STR(run.Error(), "");
      CHECK_EQ_STR(run.Reader->GetDataEncoding(), form);
      CheckRich(out, v, nanCells, doublePoints, form);
      CHECK(run.Reader->GetNumberOfSkippedPoints() == 3);
      // One warning: the file and the count.
      CHECK(run.Warnings.size() == 1);
      if (run.Warnings.size() == 1)
      {
        CHECK(run.Warnings[0].find(path + ": skipped 3 of 20 points whose x, y or z is NaN or "
                                          "infinite (empty cells of the organised 5 x 4 cloud); "
                                          "kept 17") != std::string::npos);
      }
    }
  }
}

// Double coordinates far from the origin: exact in double precision.
void TestDoubleCoordinates()
{
  const std::vector<FieldSpec> fields = { { "x", 'F', 8, 1 }, { "y", 'F', 8, 1 },
    { "z", 'F', 8, 1 } };
  Values v = { { 637012.345678901, 849123.987654321, 430.123456789 },
    { -637012.5, 1e-300, 1e300 } };
  for (const char* form : { "ascii", "binary", "binary_compressed" })
  {
    const std::string path = Path(std::string("utm_") + form + ".pcd");
    WriteFile(path, Encode(fields, 2, 1, v, form));
    Run run;
    run.Reader->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
    vtkPolyData* out = run.Read(path);
    CHECK(out->GetNumberOfPoints() == 2);
    for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
    {
      double p[3];
      out->GetPoint(i, p);
      CHECK(p[0] == v[i][0] && p[1] == v[i][1] && p[2] == v[i][2]);
    }
    // Float: rounded, and 1e300 (beyond float) becomes infinity, which is
    // then no position: left out.
    run.Reader->SetOutputPointsPrecision(vtkAlgorithm::SINGLE_PRECISION);
    out = run.Read(path);
    CHECK(out->GetNumberOfPoints() == 1);
    CHECK(run.Reader->GetNumberOfSkippedPoints() == 1);
    double p[3];
    out->GetPoint(0, p);
    CHECK(p[0] == static_cast<float>(v[0][0]) && p[1] == static_cast<float>(v[0][1]));
  }
}

// rgba (U 4) -> RGBA colours; rgb as U 4 and as I 4; alpha of rgb ignored.
void TestColours()
{
  const uint32_t c0 = 0xFF102030u, c1 = 0x80FFFFFFu, c2 = 0x00000000u;
  for (const char* name : { "rgba", "rgb" })
  {
    for (char type : { 'U', 'F', 'I' })
    {
      const std::vector<FieldSpec> fields = { { "x", 'F', 4, 1 }, { "y", 'F', 4, 1 },
        { "z", 'F', 4, 1 }, { name, type, 4, 1 } };
      Values v = { { 1, 2, 3, static_cast<double>(c0) }, { 4, 5, 6, static_cast<double>(c1) },
        { 7, 8, 9, static_cast<double>(c2) } };
      for (const char* form : { "ascii", "binary", "binary_compressed" })
      {
        const std::string path = Path(std::string("colour_") + name + type + form + ".pcd");
        std::string bytes = Encode(fields, 3, 1, v, form);
        if (type == 'I' && std::string(form) == "ascii")
        {
          // An I 4 colour in ascii is the signed value of the same bits.
          bytes = Header(fields, 3, 1, "ascii") + "1 2 3 " +
            std::to_string(static_cast<int32_t>(c0)) + "\n4 5 6 " +
            std::to_string(static_cast<int32_t>(c1)) + "\n7 8 9 0\n";
        }
        WriteFile(path, bytes);
        Run run;
        vtkPolyData* out = run.Read(path);
        CHECK_EQ_STR(run.Error(), "");
        auto* colors = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("Colors"));
        const int comps = std::string(name) == "rgba" ? 4 : 3;
        CHECK(colors && colors->GetNumberOfComponents() == comps && colors->GetNumberOfTuples() == 3);
        if (!colors || colors->GetNumberOfComponents() != comps)
          continue;
        const unsigned char want[3][4] = { { 0x10, 0x20, 0x30, 0xFF }, { 0xFF, 0xFF, 0xFF, 0x80 },
          { 0, 0, 0, 0 } };
        for (int i = 0; i < 3; ++i)
          for (int c = 0; c < comps; ++c)
            CHECK(colors->GetValue(i * comps + c) == want[i][c]);
        CHECK(out->GetPointData()->GetScalars() == colors);
      }
    }
  }
  // Old writers printed a packed rgb declared F as the float itself.
  {
    const std::string path = Path("colour_float_text.pcd");
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.9g", PackedFloat(0x00336699u));
    WriteFile(path, Header({ { "x", 'F', 4, 1 }, { "y", 'F', 4, 1 }, { "z", 'F', 4, 1 },
                             { "rgb", 'F', 4, 1 } },
                      1, 1, "ascii") +
        "0 0 0 " + buf + "\n");
    Run run;
    vtkPolyData* out = run.Read(path);
    auto* colors = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("Colors"));
    CHECK(colors && colors->GetValue(0) == 0x33 && colors->GetValue(1) == 0x66 &&
      colors->GetValue(2) == 0x99);
  }
}

// Old headers (v0.5: COLUMNS, no SIZE/TYPE/COUNT/WIDTH/HEIGHT; v0.6: no
// VIEWPOINT), keywords in another order, comments and blank lines, CRLF.
void TestHeaders()
{
  struct Case
  {
    const char* Name;
    std::string Bytes;
    vtkIdType Points;
  };
  const Case cases[] = {
    { "v5.pcd", "# .PCD v.5 - Point Cloud Data file format\nVERSION .5\nCOLUMNS x y z\nPOINTS 2\n"
                "DATA ascii\n1 2 3\n4 5 6\n",
      2 },
    { "v6.pcd", "# .PCD v.6\nVERSION .6\nFIELDS x y z i\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
                "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3 9\n4 5 6 9\n",
      2 },
    { "order.pcd", "# comment first\n\nWIDTH 1\nVIEWPOINT 0 0 0 1 0 0 0\n  # indented comment\n"
                   "POINTS 2\nFIELDS x y z\nHEIGHT 2\nCOUNT 1 1 1\nTYPE F F F\nSIZE 4 4 4\n"
                   "VERSION 0.7\nDATA ascii\n1 2 3\n\n  \n4 5 6\n",
      2 },
    { "crlf.pcd", "VERSION 0.7\r\nFIELDS x y z\r\nSIZE 4 4 4\r\nTYPE F F F\r\nCOUNT 1 1 1\r\n"
                  "WIDTH 2\r\nHEIGHT 1\r\nPOINTS 2\r\nDATA ascii\r\n1 2 3\r\n4\t5  6\r\n",
      2 },
    { "no_newline.pcd", "FIELDS x y z\nPOINTS 1\nDATA ascii\n-1e3 +2 .5", 1 },
    { "empty_cloud.pcd", "FIELDS x y z\nWIDTH 0\nHEIGHT 0\nPOINTS 0\nDATA binary\n", 0 },
  };
  for (const Case& c : cases)
  {
    const std::string path = Path(c.Name);
    WriteFile(path, c.Bytes);
    Run run;
    vtkPolyData* out = run.Read(path);
    CHECK_EQ_STR(run.Error(), "");
    CHECK(out->GetNumberOfPoints() == c.Points);
    if (c.Points == 2 && out->GetNumberOfPoints() == 2)
    {
      double p[3];
      out->GetPoint(1, p);
      CHECK(p[0] == 4 && p[1] == 5 && p[2] == 6);
    }
  }
  {
    Run run;
    vtkPolyData* out = run.Read(Path("no_newline.pcd"));
    double p[3];
    out->GetPoint(0, p);
    CHECK(p[0] == -1000 && p[1] == 2 && p[2] == 0.5);
  }
  // An unusual VERSION and lines after the points: read, with warnings.
  {
    const std::string path = Path("warn.pcd");
    WriteFile(path, "VERSION 0.9\nFIELDS x y z\nPOINTS 1\nDATA ascii\n1 2 3\n4 5 6\n");
    Run run;
    vtkPolyData* out = run.Read(path);
    CHECK(out->GetNumberOfPoints() == 1);
    CHECK(run.Warnings.size() == 2);
    if (run.Warnings.size() == 2)
    {
      CHECK(run.Warnings[0].find(path + ":1: VERSION '0.9' is not one of 0.5, 0.6, 0.7") !=
        std::string::npos);
      CHECK(run.Warnings[1].find(path + ":6: 1 line(s) after the 1 point(s) of POINTS were ignored") !=
        std::string::npos);
    }
  }
  // Bytes after the body: zeros (PCL's writer leaves some after a
  // compressed block) pass quietly; anything else is read, with a warning.
  {
    const std::vector<FieldSpec> fields = { { "x", 'F', 4, 1 }, { "y", 'F', 4, 1 },
      { "z", 'F', 4, 1 } };
    const Values v = { { 1, 2, 3 }, { 4, 5, 6 } };
    for (const char* form : { "binary", "binary_compressed" })
    {
      const std::string good = Encode(fields, 2, 1, v, form);
      const std::string path = Path(std::string("trailing_") + form + ".pcd");
      WriteFile(path, good + std::string(3900, '\0'));
      Run run;
      CHECK(run.Read(path)->GetNumberOfPoints() == 2 && run.Warnings.empty());
      WriteFile(path, good + "junk");
      CHECK(run.Read(path)->GetNumberOfPoints() == 2 && run.Warnings.size() == 1);
      if (run.Warnings.size() == 1)
      {
        CHECK(run.Warnings[0].find(path + ": 4 bytes (not all zero) after the ") !=
          std::string::npos);
      }
    }
  }
  // GenerateVertices off: no cells.
  {
    Run run;
    run.Reader->GenerateVerticesOff();
    vtkPolyData* out = run.Read(Path("v5.pcd"));
    CHECK(out->GetNumberOfPoints() == 2 && out->GetNumberOfCells() == 0);
  }
}

void TestHeaderErrors()
{
  const std::string xyz = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  ExpectError("e_empty.pcd", "",
    ": the file is empty (0 bytes); expected a PCD header (VERSION, FIELDS, SIZE, TYPE, COUNT, "
    "WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA)");
  ExpectError("e_trunc.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4",
    ":3: the header is truncated: the file ends after line 3 without a DATA line (a PCD header "
    "ends with DATA ascii, binary or binary_compressed)");
  ExpectError("e_size.pcd", "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4\nTYPE F F F F\nPOINTS 1\nDATA ascii\n",
    ":3: SIZE lists 3 value(s), FIELDS (line 2) lists 4 field(s)");
  ExpectError("e_type.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n",
    ":3: TYPE lists 2 value(s), FIELDS (line 1) lists 3 field(s)");
  ExpectError("e_count.pcd", xyz.substr(0, xyz.size() - 12) + "COUNT 1 1 1 1\nPOINTS 1\nDATA ascii\n",
    ":4: COUNT lists 4 value(s), FIELDS (line 1) lists 3 field(s)");
  ExpectError("e_wh.pcd", xyz + "WIDTH 3\nHEIGHT 2\nPOINTS 5\nDATA ascii\n",
    ":7: WIDTH x HEIGHT (3 x 2 = 6) differs from POINTS 5");
  ExpectError("e_data.pcd", xyz + "POINTS 1\nDATA binary_lz4\n1 2 3\n",
    ":6: unknown DATA 'binary_lz4': expected ascii, binary or binary_compressed");
  ExpectError("e_noz.pcd", "FIELDS x y intensity\nPOINTS 1\nDATA ascii\n1 2 3\n",
    ":1: no field 'z': FIELDS lists 'x y intensity'; the points need x, y and z");
  ExpectError("e_key.pcd", "FIELDS x y z\nPOINTZ 1\nDATA ascii\n",
    ":2: unknown header keyword 'POINTZ' (expected VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, "
    "HEIGHT, VIEWPOINT, POINTS or DATA before the data)");
  ExpectError("e_sizev.pcd", "FIELDS x y z\nSIZE 4 3 4\nPOINTS 1\nDATA ascii\n",
    ":2: SIZE of field 2 (y) is '3'; expected 1, 2, 4 or 8");
  ExpectError("e_f2.pcd", "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nPOINTS 1\nDATA ascii\n",
    ":3: TYPE of field 3 (z) is F with SIZE 2; floats have SIZE 4 or 8");
  ExpectError("e_typev.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F D\nPOINTS 1\nDATA ascii\n",
    ":3: TYPE of field 3 (z) is 'D'; expected I (signed), U (unsigned) or F (float)");
  ExpectError("e_points.pcd", "FIELDS x y z\nPOINTS -4\nDATA ascii\n",
    ":2: POINTS expects one non-negative integer, found '-4'");
  ExpectError("e_nopoints.pcd", "FIELDS x y z\nDATA ascii\n",
    ":2: the header has no POINTS line before DATA");
  ExpectError("e_nofields.pcd", "POINTS 1\nDATA ascii\n1 2 3\n",
    ":2: the header has no FIELDS line before DATA");
  ExpectError("e_twice.pcd", "FIELDS x y z\nPOINTS 1\nPOINTS 1\nDATA ascii\n",
    ":3: POINTS is given twice (first on line 2)");
  ExpectError("e_dup.pcd", "FIELDS x y z x\nPOINTS 1\nDATA ascii\n",
    ":1: FIELDS names the field 'x' twice");
  ExpectError("e_viewpoint.pcd", "FIELDS x y z\nVIEWPOINT 0 0 0 1\nPOINTS 1\nDATA ascii\n",
    ":2: VIEWPOINT expects 7 numbers (tx ty tz qw qx qy qz), found 4");
  ExpectError("e_xcount.pcd", "FIELDS x y z\nCOUNT 2 1 1\nPOINTS 1\nDATA ascii\n",
    ":2: field 'x' has COUNT 2; a coordinate needs COUNT 1");
  ExpectError("e_height.pcd", "FIELDS x y z\nHEIGHT 2\nPOINTS 2\nDATA ascii\n",
    ":2: HEIGHT is given (2) but WIDTH is not");
  ExpectError("e_binary_header.pcd", std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16),
    ":1: unknown header keyword '\\x89PNG' (expected VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, "
    "HEIGHT, VIEWPOINT, POINTS or DATA before the data)");
}

void TestBodyErrors()
{
  const std::vector<FieldSpec> fields = { { "x", 'F', 4, 1 }, { "y", 'F', 4, 1 },
    { "z", 'F', 4, 1 }, { "label", 'U', 1, 1 } };
  const std::string head = Header(fields, 4, 1, "ascii"); // 11 lines
  const std::string more = "1 2 3 4\n1 2 3 4\n1 2 3 4\n";
  ExpectError("a_few.pcd", head + "1 2 3 4\n1 2 3\n" + more,
    ":13:6: expected 4 values (x y z label), found 3");
  ExpectError("a_nan.pcd", head + "1 2 3 4\n1 2 abc 4\n" + more,
    ":13:5: expected a number for value 3 (z), found 'abc'");
  ExpectError("a_many.pcd", head + "1 2 3 4 5 6\n" + more,
    ":12:9: expected 4 values (x y z label), found 6");
  ExpectError("a_range.pcd", head + "1 2 3 256\n" + more,
    ":12:7: expected an integer of type U 1 for value 4 (label), found '256'");
  ExpectError("a_frac.pcd", head + "1 2 3 2.5\n" + more,
    ":12:7: expected an integer of type U 1 for value 4 (label), found '2.5'");
  ExpectError("a_short.pcd", head + "1.000000 2.000000 3.000000 4\n\n1.000000 2.000000 3.000000 4\n",
    ": the ascii data ends at line 14 after 2 point(s); the header promises POINTS 4");
  ExpectError("a_tiny.pcd", head + "1 2 3 4\n",
    ": the ascii data after the DATA line (line 11) has 1 line in 8 bytes; the header promises "
    "POINTS 4 of 4 value(s) each");

  // binary: shorter than promised, by bytes and whole points.
  Values v(4, { 1, 2, 3, 4 });
  const std::string bin = Encode(fields, 4, 1, v, "binary");
  const size_t dataStart = bin.size() - 4 * 13;
  ExpectError("b_short.pcd", bin.substr(0, bin.size() - 20),
    ": the binary data is shorter than the header promises: POINTS 4 x 13 bytes = 52 bytes after "
    "the header (from byte " +
      std::to_string(dataStart) + "), the file has 32 bytes (2 whole points)");

  // binary_compressed: each inconsistency of the block.
  const std::string comp = Encode(fields, 4, 1, v, "binary_compressed");
  const size_t blockAt = Header(fields, 4, 1, "binary_compressed").size();
  uint32_t sizes[2];
  std::memcpy(sizes, comp.data() + blockAt, 8);
  const std::string said = " (the block header at byte " + std::to_string(blockAt) + " says ";
  ExpectError("c_cut.pcd", comp.substr(0, blockAt + 5),
    ": the binary_compressed data is cut off: its 8-byte block header (compressed and "
    "uncompressed sizes) needs 8 bytes after the header, the file has 5 bytes");
  ExpectError("c_short.pcd", comp.substr(0, comp.size() - 3),
    ": the binary_compressed data is shorter than its block header says: " +
      std::to_string(sizes[0]) + " bytes of LZF data expected after the 8-byte block header, the "
                                 "file has " +
      std::to_string(sizes[0] - 3) + " bytes" + said + std::to_string(sizes[0]) +
      " bytes compressed, 52 uncompressed)");
  auto withSizes = [&](uint32_t c, uint32_t u) {
    std::string s = comp;
    std::memcpy(&s[blockAt], &c, 4);
    std::memcpy(&s[blockAt + 4], &u, 4);
    return s;
  };
  ExpectError("c_usize.pcd", withSizes(sizes[0], 60),
    ": the binary_compressed block does not match the header: it inflates to 60 bytes, POINTS 4 "
    "x 13 bytes (the fields without padding) = 52" +
      said + std::to_string(sizes[0]) + " bytes compressed, 60 uncompressed)");
  // A header that promises far more than the block can hold.
  {
    const std::string big = Header(fields, 1000000, 1, "binary_compressed");
    std::string s = big;
    const uint32_t c = 16, u = 13000000;
    s.append(reinterpret_cast<const char*>(&c), 4);
    s.append(reinterpret_cast<const char*>(&u), 4);
    s += std::string(16, '\0');
    ExpectError("c_ratio.pcd", s,
      ": the binary_compressed block is inconsistent: 16 bytes of LZF cannot inflate to 13000000 "
      "(at most 88 times as many) (the block header at byte " +
        std::to_string(big.size()) + " says 16 bytes compressed, 13000000 uncompressed)");
  }
  // Corrupt LZF streams: a back-reference before the start, a literal run
  // past the end, a stream that stops short, one that writes too much.
  {
    const std::string head2 = Header(fields, 4, 1, "binary_compressed");
    auto block = [&](const std::string& z, uint32_t u = 52) {
      std::string s = head2;
      const uint32_t c = static_cast<uint32_t>(z.size());
      s.append(reinterpret_cast<const char*>(&c), 4);
      s.append(reinterpret_cast<const char*>(&u), 4);
      return s + z;
    };
    const std::string at = " (the block header at byte " + std::to_string(head2.size()) + " says ";
    ExpectError("z_back.pcd", block(std::string("\x01" "ab" "\x20\x05", 5)),
      ": corrupt binary_compressed data (LZF): a back-reference reaches 6 bytes back, before the "
      "start of the output (instruction at compressed byte 3, output byte 2)" +
        at + "5 bytes compressed, 52 uncompressed)");
    ExpectError("z_lit.pcd", block(std::string("\x1f" "abc", 4)),
      ": corrupt binary_compressed data (LZF): a literal run of 32 bytes goes past the end of the "
      "compressed data (3 byte(s) left) (instruction at compressed byte 0, output byte 0)" +
        at + "4 bytes compressed, 52 uncompressed)");
    ExpectError("z_few.pcd", block(std::string("\x03" "abcd" "\xe0\x10\x03", 8)),
      ": corrupt binary_compressed data (LZF): the compressed data ends after 29 of the 52 bytes "
      "it should inflate to" +
        at + "8 bytes compressed, 52 uncompressed)");
    ExpectError("z_much.pcd", block(std::string("\x03" "abcd" "\xe0\xff\x03", 8)),
      ": corrupt binary_compressed data (LZF): a back-reference of 264 bytes goes past the 52 "
      "bytes the block should inflate to (instruction at compressed byte 5, output byte 4)" +
        at + "8 bytes compressed, 52 uncompressed)");
    ExpectError("z_cut.pcd", block(std::string("\x03" "abcd" "\xe0", 6)),
      ": corrupt binary_compressed data (LZF): a back-reference is cut off by the end of the "
      "compressed data (instruction at compressed byte 5, output byte 4)" +
        at + "6 bytes compressed, 52 uncompressed)");
  }
}

// The output of the last good update stays when the file goes bad.
void TestKeepsPreviousOutput()
{
  const std::string path = Path("keep.pcd");
  WriteFile(path, "FIELDS x y z\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6\n7 8 9\n");
  Run run;
  vtkPolyData* out = run.Read(path);
  CHECK(out->GetNumberOfPoints() == 3);
  WriteFile(path, "FIELDS x y z\nPOINTS 3\nDATA ascii\n10 20 30\n4 5 6\n7 8\n");
  out = run.Read(path);
  CHECK_EQ_STR(run.Error(), path + ":6:4: expected 3 values (x y z), found 2");
  CHECK(out->GetNumberOfPoints() == 3);
  double p[3];
  out->GetPoint(2, p);
  CHECK(p[0] == 7 && p[1] == 8 && p[2] == 9);
  run.Reader->SetFileName(Path("does_not_exist.pcd").c_str());
  run.Reader->Update();
  CHECK(std::string(run.Reader->GetErrorMessage()).find("cannot open the file") != std::string::npos);
  CHECK(run.Reader->GetOutput()->GetNumberOfPoints() == 3);
}

// A large compressed cloud: progress rises to 1; an observer that aborts
// stops the read with an error, the previous output kept.
void TestProgressAndAbort()
{
  const size_t n = 300000;
  const std::vector<FieldSpec> fields = { { "x", 'F', 4, 1 }, { "y", 'F', 4, 1 },
    { "z", 'F', 4, 1 }, { "intensity", 'F', 4, 1 } };
  Values v(n);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (size_t i = 0; i < n; ++i)
    v[i] = { static_cast<double>(i % 1000), static_cast<double>(i / 1000), u(rng), 0.0 };
  LzfStats stats;
  const std::string path = Path("large.pcd");
  WriteFile(path, Encode(fields, n, 1, v, "binary_compressed", &stats));
  // The compressor made every kind of instruction.
  CHECK(stats.Literals > 0 && stats.References > 0 && stats.Overlapping > 0 && stats.Long > 0);
  Run run;
  std::vector<double> progress;
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetClientData(&progress);
  onProgress->SetCallback([](vtkObject* caller, unsigned long, void* data, void* p) {
    static_cast<std::vector<double>*>(data)->push_back(*static_cast<double*>(p));
    (void)caller;
  });
  run.Reader->AddObserver(vtkCommand::ProgressEvent, onProgress);
  vtkPolyData* out = run.Read(path);
  CHECK(out->GetNumberOfPoints() == static_cast<vtkIdType>(n));
  CHECK(progress.size() > 5 && progress.back() == 1.0);
  bool rising = true;
  for (size_t i = 1; i < progress.size(); ++i)
    rising = rising && progress[i] >= progress[i - 1];
  CHECK(rising);
  double p[3];
  out->GetPoint(123456, p);
  CHECK(p[0] == 456 && p[1] == 123 && p[2] == static_cast<float>(v[123456][2]));

  // Abort during decoding or conversion, at every stage.
  for (double at : { 0.05, 0.3, 0.7 })
  {
    for (const char* form : { "binary_compressed", "binary", "ascii" })
    {
      const std::string other = Path(std::string("abort_") + form + ".pcd");
      WriteFile(other, Encode(fields, n, 1, v, form));
      Run aborting;
      vtkPolyData* before = aborting.Read(Path("v5.pcd"));
      CHECK(before->GetNumberOfPoints() == 2);
      struct Stop
      {
        vtkPCDReader* Reader;
        double At;
      } stop = { aborting.Reader, at };
      vtkNew<vtkCallbackCommand> cb;
      cb->SetClientData(&stop);
      cb->SetCallback([](vtkObject*, unsigned long, void* data, void* p) {
        auto* s = static_cast<Stop*>(data);
        if (*static_cast<double*>(p) >= s->At)
          s->Reader->SetAbortExecute(1);
      });
      aborting.Reader->AddObserver(vtkCommand::ProgressEvent, cb);
      vtkPolyData* after = aborting.Read(other);
      CHECK_EQ_STR(aborting.Error(), other + ": reading was aborted");
      CHECK(after->GetNumberOfPoints() == 2);
    }
  }
}

// Random bytes, every truncation and bit flips of good files: an error that
// names the file, or a cloud whose arrays agree with its points; no crash.
void TestDamagedFiles()
{
  const std::vector<size_t> nanCells = { 3 };
  const Values v = RichValues(20, nanCells);
  const std::string path = Path("damaged.pcd");
  size_t runs = 0, failures = 0;
  // A fresh reader each time, so that an error leaves an empty output.
  auto consistent = [&]() {
    ++runs;
    Run run;
    vtkPolyData* out = run.Read(path);
    const vtkIdType n = out->GetNumberOfPoints();
    if (!std::string(run.Error()).empty())
    {
      ++failures;
      CHECK(std::string(run.Error()).find(path + ":") == 0);
      CHECK(n == 0 && run.Errors.size() == 1);
      return run.Error();
    }
    vtkPointData* pd = out->GetPointData();
    for (int a = 0; a < pd->GetNumberOfArrays(); ++a)
      CHECK(pd->GetArray(a)->GetNumberOfTuples() == n);
    CHECK(out->GetNumberOfVerts() == n);
    return std::string();
  };
  for (const char* form : { "ascii", "binary", "binary_compressed" })
  {
    const std::string good = Encode(RichFields(), 5, 4, v, form);
    const bool text = std::string(form) == "ascii";
    // Every truncation: binary bodies must fail; an ascii body cut inside
    // its last number may still be a (shorter) number.
    for (size_t cut = 0; cut < good.size(); ++cut)
    {
      WriteFile(path, good.substr(0, cut));
      const std::string error = consistent();
      if (!text)
      {
        CHECK(!error.empty());
      }
    }
    // Bit flips anywhere.
    std::mt19937 rng(99);
    for (int k = 0; k < 400; ++k)
    {
      std::string bad = good;
      for (int f = 0; f < 1 + k % 4; ++f)
        bad[rng() % bad.size()] ^= static_cast<char>(1u << (rng() % 8));
      WriteFile(path, bad);
      consistent();
    }
  }
  // Random bytes, and a valid header over random bodies.
  std::mt19937 rng(2024);
  for (int k = 0; k < 300; ++k)
  {
    std::string bytes(rng() % 2048, '\0');
    for (char& c : bytes)
      c = static_cast<char>(rng());
    if (k % 3 == 1)
      bytes = Header(RichFields(), 5, 4, "binary_compressed") + bytes;
    else if (k % 3 == 2)
      bytes = Header(RichFields(), 5, 4, k % 2 ? "ascii" : "binary") + bytes;
    WriteFile(path, bytes);
    consistent();
  }
  std::cout << "damaged files: " << runs << " reads, " << failures << " errors\n";
}

// The LZF decoder on its own: streams the compressor made, and the
// instructions at the edges of the buffers.
void TestLzf()
{
  std::mt19937 rng(5);
  for (int k = 0; k < 200; ++k)
  {
    std::string data(rng() % 20000, '\0');
    // Runs, repeats at random distances, noise.
    for (size_t i = 0; i < data.size(); ++i)
    {
      const unsigned r = rng() % 10;
      data[i] = r < 3 && i > 0 ? data[i - 1]
        : r < 7 && i > 300      ? data[i - 1 - rng() % 300]
                                : static_cast<char>(rng());
    }
    const std::string z = LzfCompress(data);
    std::vector<unsigned char> out(data.size());
    std::string error;
    const bool ok = octoray::pcd::LzfDecompress(reinterpret_cast<const unsigned char*>(z.data()),
      z.size(), out.data(), out.size(), error, [](size_t) { return true; });
    CHECK(ok && std::memcmp(out.data(), data.data(), data.size()) == 0);
    // One byte too little room: an error, nothing written past the end.
    if (!data.empty())
    {
      std::vector<unsigned char> small(data.size() - 1 + 16, 0xAB);
      const bool fits = octoray::pcd::LzfDecompress(reinterpret_cast<const unsigned char*>(z.data()),
        z.size(), small.data(), data.size() - 1, error, [](size_t) { return true; });
      CHECK(!fits);
      bool guard = true;
      for (size_t i = data.size() - 1; i < small.size(); ++i)
        guard = guard && small[i] == 0xAB;
      CHECK(guard);
    }
  }
  // Distance 1 overlap by hand: 'a' then 10 more copies.
  {
    // A literal 'a', then a long back-reference (control 0xe0: length 7 +
    // the next byte, 1, plus 2 = 10) at distance 1 (third byte 0).
    const unsigned char stream[] = { 0x00, 'a', 0xe0, 0x01, 0x00 };
    std::vector<unsigned char> out(11);
    std::string error;
    CHECK(octoray::pcd::LzfDecompress(stream, sizeof(stream), out.data(), out.size(), error,
      [](size_t) { return true; }));
    CHECK(std::string(out.begin(), out.end()) == "aaaaaaaaaaa");
  }
}
} // namespace

int TestPCDReader(int argc, char* argv[])
{
  char* dir = vtkTestUtilities::GetArgOrEnvOrDefault("-T", argc, argv, "VTK_TEMP_DIR", ".");
  Dir = dir;
  delete[] dir;

  TestLzf();
  TestRichCloud();
  TestDoubleCoordinates();
  TestColours();
  TestHeaders();
  TestHeaderErrors();
  TestBodyErrors();
  TestKeepsPreviousOutput();
  TestProgressAndAbort();
  TestDamagedFiles();

  return octoray_test::Result();
}
