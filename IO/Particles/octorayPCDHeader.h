// The header of PCL's PCD point cloud files, without VTK: VERSION, FIELDS,
// SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS and DATA read and
// checked against each other. vtkPCDReader reads with it, and the fuzz target
// in Testing/Fuzz reaches it through the reader. The body is read by
// octorayPCDBody.h (with octorayPCDAscii.h and octorayLZF.h), its values
// converted by octorayPCDValues.h. Private to the module; not wrapped.
//
// The format, as PCL 1.13 writes and reads it:
//
//   # comment lines anywhere in the header
//   VERSION 0.7                  (.7, 0.6, .5 ...; not checked, as PCL)
//   FIELDS x y z rgb             (COLUMNS in v0.5 files; "_" names padding)
//   SIZE 4 4 4 4                 (bytes of one value: 1, 2, 4, 8; default 4)
//   TYPE F F F U                 (I signed, U unsigned, F float; default F)
//   COUNT 1 1 1 1                (values per field, e.g. 33 for an FPFH; default 1)
//   WIDTH 640                    (points per row; default POINTS)
//   HEIGHT 480                   (rows: > 1 is an organised cloud; default 1)
//   VIEWPOINT 0 0 0 1 0 0 0      (tx ty tz qw qx qy qz)
//   POINTS 307200                (= WIDTH x HEIGHT)
//   DATA ascii | binary | binary_compressed
//
// and then the body, starting right after the DATA line's newline:
//   ascii              one point a line, COUNT values per field, blank separated
//   binary             POINTS x point-size bytes, the fields of a point together
//                      (array of structures), native (little-endian) byte order
//   binary_compressed  two uint32 (compressed size C, uncompressed size U),
//                      then C bytes of LZF; the U bytes it inflates to hold each
//                      field as one contiguous array of POINTS values (structure
//                      of arrays), in FIELDS order, padding fields left out
#ifndef octorayPCDHeader_h
#define octorayPCDHeader_h

#include "octorayTextScan.h"

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

namespace octoray
{
namespace pcd
{

enum class Encoding
{
  Ascii,
  Binary,
  BinaryCompressed
};

inline const char* EncodingName(Encoding e)
{
  return e == Encoding::Ascii ? "ascii" : e == Encoding::Binary ? "binary" : "binary_compressed";
}

struct Field
{
  std::string Name;
  char Type = 'F';    // I, U or F
  int Size = 4;       // bytes of one value: 1, 2, 4 or 8
  uint64_t Count = 1; // values per point
  size_t Offset = 0;  // byte offset in an interleaved point (ascii, binary)
  // Bytes per point of the fields before this one, padding left out: the
  // field's array starts at Points x PackedOffset in a decompressed
  // binary_compressed block.
  size_t PackedOffset = 0;
  size_t Line = 0; // the header line that named it
  bool Padding() const { return this->Name == "_"; }
  size_t Bytes() const { return static_cast<size_t>(this->Size) * this->Count; }
};

struct Header
{
  std::vector<Field> Fields;
  size_t PointStep = 0;      // bytes per point, every field
  size_t PackedStep = 0;     // bytes per point without the padding fields
  size_t ValuesPerPoint = 0; // values on an ascii line, padding included
  uint64_t Width = 0;
  uint64_t Height = 0;
  uint64_t Points = 0;
  double Viewpoint[7] = { 0, 0, 0, 1, 0, 0, 0 }; // tx ty tz qw qx qy qz
  Encoding Data = Encoding::Ascii;
  size_t DataOffset = 0; // the first byte after the DATA line
  size_t DataLine = 0;   // 1-based line number of the DATA line
  std::string Version;
  std::vector<std::string> Warnings;

  // The index of the first field of that name, or -1.
  int Find(const char* name) const
  {
    for (size_t i = 0; i < this->Fields.size(); ++i)
    {
      if (this->Fields[i].Name == name)
      {
        return static_cast<int>(i);
      }
    }
    return -1;
  }
};

// Limits that keep a damaged header from asking for absurd work: far beyond
// any real file (PCL's own descriptors have one field of COUNT 352 or so).
constexpr size_t MaximumHeaderLine = 1 << 20;
constexpr size_t MaximumFields = 10000;

struct Token
{
  const char* Begin;
  const char* End;
  std::string Str() const { return std::string(this->Begin, this->End); }
};

inline std::vector<Token> Split(const char* b, const char* e)
{
  std::vector<Token> t;
  const char* p = b;
  while (true)
  {
    p = SkipBlanks(p, e);
    if (p == e)
    {
      return t;
    }
    const char* s = p;
    while (p < e && !IsBlank(*p))
    {
      ++p;
    }
    t.push_back({ s, p });
  }
}

inline bool ParseUnsigned(const Token& t, uint64_t& v)
{
  auto r = std::from_chars(t.Begin, t.End, v);
  return r.ec == std::errc() && r.ptr == t.End;
}

inline bool ParseDouble(const Token& t, double& v)
{
  const char* b = t.Begin;
  if (b < t.End && *b == '+')
  {
    ++b;
  }
  auto r = std::from_chars(b, t.End, v);
  return b < t.End && r.ec == std::errc() && r.ptr == t.End;
}

inline bool CheckedMultiply(uint64_t a, uint64_t b, uint64_t& r)
{
  return !__builtin_mul_overflow(a, b, &r);
}

// Reads a header in two steps: its lines up to DATA, each keyword on its
// own (ReadLines), then the checks that need all of them (the per-field
// SIZE, TYPE and COUNT, the coordinates, the point count). Errors name the
// file and the line: "scan.pcd:4: SIZE lists 3 values, FIELDS (line 3)
// lists 4 fields".
class HeaderParser
{
public:
  HeaderParser(const std::string& file, Header& h, std::string& error)
    : File(file)
    , H(h)
    , Error(error)
  {
  }

  bool Parse(const char* data, size_t size)
  {
    this->H = Header();
    if (!this->ReadLines(data, size) || !this->CheckFields() || !this->ReadFieldTypes())
    {
      return false;
    }
    this->LayOutFields();
    return this->CheckCoordinates() && this->CheckPoints();
  }

private:
  bool Fail(size_t line, const std::string& what)
  {
    this->Error = this->File + ":" + std::to_string(line) + ": " + what;
    return false;
  }

  // The header's lines from the start of the file up to and including its
  // DATA line, each handed to ReadKeyword.
  bool ReadLines(const char* data, size_t size)
  {
    const char* const end = data + size;
    const char* p = data;
    size_t line = 0;
    while (true)
    {
      if (p >= end)
      {
        if (line == 0)
        {
          this->Error = this->File + ": the file is empty (0 bytes); expected a PCD header "
                                     "(VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, "
                                     "VIEWPOINT, POINTS, DATA)";
          return false;
        }
        return this->Fail(line, "the header is truncated: the file ends after line " +
            std::to_string(line) + " without a DATA line (a PCD header ends with DATA ascii, "
            "binary or binary_compressed)");
      }
      ++line;
      const size_t look = std::min<size_t>(static_cast<size_t>(end - p), MaximumHeaderLine + 1);
      const char* nl = static_cast<const char*>(std::memchr(p, '\n', look));
      if (!nl && look > MaximumHeaderLine)
      {
        return this->Fail(line, "a header line longer than " +
            std::to_string(MaximumHeaderLine) + " bytes: this is not a PCD header (it starts '" +
            Printable(p, p + 40) + "')");
      }
      const char* e = nl ? nl : end;
      const char* next = nl ? nl + 1 : end;
      const std::vector<Token> t = Split(p, e);
      p = next;
      if (t.empty() || *t[0].Begin == '#')
      {
        continue; // blank line or comment
      }
      if (!this->ReadKeyword(t, line))
      {
        return false;
      }
      if (this->DataLine)
      {
        this->H.DataOffset = static_cast<size_t>(next - data);
        this->H.DataLine = line;
        return true;
      }
    }
  }

  // One keyword line: its values kept for the checks once DATA is reached.
  bool ReadKeyword(const std::vector<Token>& t, size_t line)
  {
    const std::string key = t[0].Str();
    Header& h = this->H;
    if (key == "VERSION")
    {
      return this->Once(this->VersionLine, key, line) && this->ReadVersion(t, line);
    }
    if (key == "FIELDS" || key == "COLUMNS")
    {
      return this->Once(this->FieldsLine, key, line) && this->ReadFieldNames(t, key, line);
    }
    if (key == "SIZE" || key == "TYPE" || key == "COUNT")
    {
      size_t& seen = key == "SIZE" ? this->SizeLine : key == "TYPE" ? this->TypeLine : this->CountLine;
      std::vector<Token>& values =
        key == "SIZE" ? this->SizeTokens : key == "TYPE" ? this->TypeTokens : this->CountTokens;
      if (!this->Once(seen, key, line))
      {
        return false;
      }
      values.assign(t.begin() + 1, t.end());
      return true;
    }
    if (key == "WIDTH")
    {
      return this->Once(this->WidthLine, key, line) && this->OneUnsigned(t, line, h.Width);
    }
    if (key == "HEIGHT")
    {
      return this->Once(this->HeightLine, key, line) && this->OneUnsigned(t, line, h.Height);
    }
    if (key == "POINTS")
    {
      return this->Once(this->PointsLine, key, line) && this->OneUnsigned(t, line, h.Points);
    }
    if (key == "VIEWPOINT")
    {
      return this->Once(this->ViewpointLine, key, line) && this->ReadViewpoint(t, line);
    }
    if (key == "DATA")
    {
      return this->ReadData(t, line);
    }
    return this->Fail(line, "unknown header keyword '" + Printable(t[0].Begin, t[0].End) +
        "' (expected VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS or "
        "DATA before the data)");
  }

  // Each keyword is given once: its line, kept in `seen`.
  bool Once(size_t& seen, const std::string& key, size_t line)
  {
    if (seen)
    {
      return this->Fail(
        line, key + " is given twice (first on line " + std::to_string(seen) + ")");
    }
    seen = line;
    return true;
  }

  bool OneUnsigned(const std::vector<Token>& t, size_t line, uint64_t& v)
  {
    if (t.size() != 2 || !ParseUnsigned(t[1], v))
    {
      return this->Fail(line, t[0].Str() + " expects one non-negative integer, found '" +
          (t.size() > 1 ? Printable(t[1].Begin, t.back().End) : std::string()) + "'");
    }
    return true;
  }

  bool ReadVersion(const std::vector<Token>& t, size_t line)
  {
    Header& h = this->H;
    h.Version = t.size() > 1 ? t[1].Str() : std::string();
    static const char* const known[] = { "0.7", ".7", "0.6", ".6", "0.5", ".5", "7", "6", "5" };
    bool ok = false;
    for (const char* k : known)
    {
      ok = ok || h.Version == k;
    }
    if (!ok)
    {
      h.Warnings.push_back(this->File + ":" + std::to_string(line) + ": VERSION '" +
        Printable(h.Version) + "' is not one of 0.5, 0.6, 0.7; read as 0.7");
    }
    return true;
  }

  bool ReadFieldNames(const std::vector<Token>& t, const std::string& key, size_t line)
  {
    const size_t nvalues = t.size() - 1;
    if (nvalues == 0)
    {
      return this->Fail(line, key + " lists no fields");
    }
    if (nvalues > MaximumFields)
    {
      return this->Fail(line, key + " lists " + std::to_string(nvalues) + " fields; at most " +
          std::to_string(MaximumFields) + " are supported");
    }
    for (size_t i = 1; i < t.size(); ++i)
    {
      Field f;
      f.Name = t[i].Str();
      f.Line = line;
      if (!f.Padding() && this->H.Find(f.Name.c_str()) >= 0)
      {
        return this->Fail(line, key + " names the field '" + Printable(f.Name) + "' twice");
      }
      this->H.Fields.push_back(std::move(f));
    }
    return true;
  }

  bool ReadViewpoint(const std::vector<Token>& t, size_t line)
  {
    if (t.size() < 8)
    {
      return this->Fail(line, "VIEWPOINT expects 7 numbers (tx ty tz qw qx qy qz), found " +
          std::to_string(t.size() - 1));
    }
    for (int i = 0; i < 7; ++i)
    {
      if (!ParseDouble(t[i + 1], this->H.Viewpoint[i]))
      {
        return this->Fail(line, "VIEWPOINT value " + std::to_string(i + 1) +
            " is not a number: '" + Printable(t[i + 1].Begin, t[i + 1].End) + "'");
      }
    }
    return true;
  }

  bool ReadData(const std::vector<Token>& t, size_t line)
  {
    const std::string form = t.size() == 2 ? t[1].Str() : std::string();
    if (form == "ascii")
      this->H.Data = Encoding::Ascii;
    else if (form == "binary")
      this->H.Data = Encoding::Binary;
    else if (form == "binary_compressed")
      this->H.Data = Encoding::BinaryCompressed;
    else
    {
      return this->Fail(line, "unknown DATA '" +
          (t.size() > 1 ? Printable(t[1].Begin, t.back().End) : std::string()) +
          "': expected ascii, binary or binary_compressed");
    }
    this->DataLine = line;
    return true;
  }

  // ---- The header is complete: check that its parts agree.

  bool CheckFields()
  {
    if (!this->FieldsLine)
    {
      return this->Fail(this->DataLine, "the header has no FIELDS line before DATA");
    }
    const size_t nfields = this->H.Fields.size();
    auto lengthsAgree = [&](const char* what, size_t where, const std::vector<Token>& v) {
      if (where && v.size() != nfields)
      {
        return this->Fail(where, std::string(what) + " lists " + std::to_string(v.size()) +
            " value(s), FIELDS (line " + std::to_string(this->FieldsLine) + ") lists " +
            std::to_string(nfields) + " field(s)");
      }
      return true;
    };
    return lengthsAgree("SIZE", this->SizeLine, this->SizeTokens) &&
      lengthsAgree("TYPE", this->TypeLine, this->TypeTokens) &&
      lengthsAgree("COUNT", this->CountLine, this->CountTokens);
  }

  // SIZE, TYPE and COUNT of each field, where the header gives them.
  bool ReadFieldTypes()
  {
    for (size_t i = 0; i < this->H.Fields.size(); ++i)
    {
      Field& f = this->H.Fields[i];
      const std::string which = "field " + std::to_string(i + 1) + " (" + Printable(f.Name) + ")";
      if (this->SizeLine)
      {
        const Token& t = this->SizeTokens[i];
        uint64_t s = 0;
        if (!ParseUnsigned(t, s) || (s != 1 && s != 2 && s != 4 && s != 8))
        {
          return this->Fail(this->SizeLine, "SIZE of " + which + " is '" +
              Printable(t.Begin, t.End) + "'; expected 1, 2, 4 or 8");
        }
        f.Size = static_cast<int>(s);
      }
      if (this->TypeLine)
      {
        const Token& t = this->TypeTokens[i];
        if (t.End - t.Begin != 1 || (*t.Begin != 'I' && *t.Begin != 'U' && *t.Begin != 'F'))
        {
          return this->Fail(this->TypeLine, "TYPE of " + which + " is '" +
              Printable(t.Begin, t.End) + "'; expected I (signed), U (unsigned) or F (float)");
        }
        f.Type = *t.Begin;
      }
      if (f.Type == 'F' && f.Size != 4 && f.Size != 8)
      {
        return this->Fail(this->TypeLine ? this->TypeLine : this->SizeLine, "TYPE of " + which +
            " is F with SIZE " + std::to_string(f.Size) + "; floats have SIZE 4 or 8");
      }
      if (this->CountLine)
      {
        const Token& t = this->CountTokens[i];
        uint64_t c = 0;
        if (!ParseUnsigned(t, c) || c > (uint64_t(1) << 24))
        {
          return this->Fail(this->CountLine, "COUNT of " + which + " is '" +
              Printable(t.Begin, t.End) + "'; expected a non-negative integer (at most 16777216)");
        }
        f.Count = c;
      }
    }
    return true;
  }

  // Drops the fields of COUNT 0 (as PCL does, with a warning) and places
  // the others in a point: interleaved (ascii, binary) and packed
  // (binary_compressed).
  void LayOutFields()
  {
    Header& h = this->H;
    for (size_t i = 0; i < h.Fields.size();)
    {
      if (h.Fields[i].Count == 0)
      {
        h.Warnings.push_back(this->File + ":" + std::to_string(this->CountLine) + ": field '" +
          Printable(h.Fields[i].Name) + "' has COUNT 0 and no values; it is left out");
        h.Fields.erase(h.Fields.begin() + static_cast<std::ptrdiff_t>(i));
      }
      else
      {
        ++i;
      }
    }
    size_t offset = 0, packed = 0, values = 0;
    for (Field& f : h.Fields)
    {
      f.Offset = offset;
      f.PackedOffset = packed;
      offset += f.Bytes();
      values += f.Count;
      if (!f.Padding())
      {
        packed += f.Bytes();
      }
    }
    h.PointStep = offset;
    h.PackedStep = packed;
    h.ValuesPerPoint = values;
  }

  bool CheckCoordinates()
  {
    const Header& h = this->H;
    for (const char* axis : { "x", "y", "z" })
    {
      const int k = h.Find(axis);
      if (k < 0)
      {
        std::string names;
        for (const Field& f : h.Fields)
        {
          names += (names.empty() ? "" : " ") + f.Name;
        }
        return this->Fail(this->FieldsLine, std::string("no field '") + axis +
            "': FIELDS lists '" + Printable(names) + "'; the points need x, y and z");
      }
      if (h.Fields[k].Count != 1)
      {
        return this->Fail(this->CountLine, std::string("field '") + axis + "' has COUNT " +
            std::to_string(h.Fields[k].Count) + "; a coordinate needs COUNT 1");
      }
    }
    return true;
  }

  // POINTS, and WIDTH and HEIGHT as PCL completes them: neither given, an
  // unorganised cloud of POINTS; no HEIGHT, one row.
  bool CheckPoints()
  {
    Header& h = this->H;
    if (!this->PointsLine)
    {
      return this->Fail(this->DataLine, "the header has no POINTS line before DATA");
    }
    if (!this->WidthLine && !this->HeightLine)
    {
      h.Width = h.Points;
      h.Height = 1;
    }
    else if (!this->HeightLine)
    {
      h.Height = 1;
    }
    else if (!this->WidthLine && h.Points != 0)
    {
      return this->Fail(this->HeightLine, "HEIGHT is given (" + std::to_string(h.Height) +
          ") but WIDTH is not");
    }
    uint64_t product = 0;
    const bool fits = CheckedMultiply(h.Width, h.Height, product);
    if (!fits || product != h.Points)
    {
      return this->Fail(this->PointsLine, "WIDTH x HEIGHT (" + std::to_string(h.Width) + " x " +
          std::to_string(h.Height) + (fits ? " = " + std::to_string(product) : ", too large") +
          ") differs from POINTS " + std::to_string(h.Points));
    }
    uint64_t total = 0;
    if (!CheckedMultiply(h.Points, h.PointStep, total) || total > (uint64_t(1) << 62))
    {
      return this->Fail(this->PointsLine, "POINTS " + std::to_string(h.Points) + " of " +
          std::to_string(h.PointStep) + " bytes each is more data than can be addressed");
    }
    return true;
  }

  const std::string& File;
  Header& H;
  std::string& Error;
  // Lines of each keyword, 0 when absent; values kept for the checks at DATA.
  size_t FieldsLine = 0, SizeLine = 0, TypeLine = 0, CountLine = 0, WidthLine = 0,
         HeightLine = 0, PointsLine = 0, ViewpointLine = 0, VersionLine = 0, DataLine = 0;
  std::vector<Token> SizeTokens, TypeTokens, CountTokens;
};

// Reads the header from the start of the file up to and including its DATA
// line into h. On failure, `error` names the file and (where there is one)
// the line.
inline bool ParseHeader(
  const char* data, size_t size, const std::string& file, Header& h, std::string& error)
{
  return HeaderParser(file, h, error).Parse(data, size);
}

} // namespace pcd
} // namespace octoray

#endif
