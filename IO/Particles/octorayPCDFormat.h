// PCL's PCD point cloud format without VTK: the header (VERSION, FIELDS,
// SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA), the ascii body,
// the LZF decompression of binary_compressed bodies and the conversion of the
// declared value types. vtkPCDReader reads with these, and the fuzz target in
// Testing/Fuzz calls them directly (no VTK needed). Private to the module;
// not wrapped.
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
//
// LZF (Marc Lehmann's format, as the PCD writer uses it) is a sequence of
// instructions, each starting with a control byte c:
//   c < 32          a literal run: the next c + 1 bytes are copied to the output
//   c >= 32         a back-reference: length L = c >> 5 (1 to 6, or 7 + the next
//                   byte when it is 7), distance D = ((c & 31) << 8) + the next
//                   byte + 1; L + 2 bytes are copied from D bytes before the
//                   current end of the output, byte by byte, so that a copy may
//                   overlap what it writes (D = 1 repeats one byte)
// The decoder below is written from that description and checks every length
// and distance against both buffers.
#ifndef octorayPCDFormat_h
#define octorayPCDFormat_h

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

namespace octoray
{
namespace pcd
{
static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE floats are assumed");

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

inline bool IsBlank(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// A token for a message: at most 40 characters (longer ones end in "..."),
// bytes that are not printable ASCII as \xNN.
inline std::string Show(const char* b, const char* e)
{
  const bool cut = e - b > 40;
  const char* stop = cut ? b + 37 : e;
  std::string t;
  for (const char* c = b; c < stop; ++c)
  {
    const unsigned char u = static_cast<unsigned char>(*c);
    if (u >= 0x20 && u < 0x7f)
    {
      t += *c;
    }
    else
    {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\x%02x", u);
      t += buf;
    }
  }
  if (cut)
  {
    t += "...";
  }
  return t;
}
inline std::string Show(const std::string& s)
{
  return Show(s.data(), s.data() + s.size());
}

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
    while (p < e && IsBlank(*p))
    {
      ++p;
    }
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

// Reads the header from the start of the file up to and including its DATA
// line. On failure, `error` names the file and (where there is one) the line:
// "scan.pcd:4: SIZE lists 3 values, FIELDS (line 3) lists 4 fields".
inline bool ParseHeader(
  const char* data, size_t size, const std::string& file, Header& h, std::string& error)
{
  h = Header();
  auto fail = [&](size_t line, const std::string& what) {
    error = file + ":" + std::to_string(line) + ": " + what;
    return false;
  };
  // Lines of each keyword, 0 when absent; values kept for the checks at DATA.
  size_t fieldsLine = 0, sizeLine = 0, typeLine = 0, countLine = 0, widthLine = 0,
         heightLine = 0, pointsLine = 0, viewpointLine = 0, versionLine = 0;
  std::vector<Token> sizeTokens, typeTokens, countTokens;
  const char* const end = data + size;
  const char* p = data;
  size_t line = 0;
  while (true)
  {
    if (p >= end)
    {
      if (line == 0)
      {
        error = file + ": the file is empty (0 bytes); expected a PCD header (VERSION, FIELDS, "
                       "SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA)";
        return false;
      }
      return fail(line, "the header is truncated: the file ends after line " +
          std::to_string(line) + " without a DATA line (a PCD header ends with DATA ascii, "
          "binary or binary_compressed)");
    }
    ++line;
    const size_t look = std::min<size_t>(static_cast<size_t>(end - p), MaximumHeaderLine + 1);
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', look));
    if (!nl && look > MaximumHeaderLine)
    {
      return fail(line, "a header line longer than " + std::to_string(MaximumHeaderLine) +
          " bytes: this is not a PCD header (it starts '" + Show(p, p + 40) + "')");
    }
    const char* e = nl ? nl : end;
    const char* next = nl ? nl + 1 : end;
    std::vector<Token> t = Split(p, e);
    p = next;
    if (t.empty() || *t[0].Begin == '#')
    {
      continue; // blank line or comment
    }
    const std::string key = t[0].Str();
    const size_t nvalues = t.size() - 1;
    auto once = [&](size_t& seen) {
      if (seen)
      {
        fail(line, key + " is given twice (first on line " + std::to_string(seen) + ")");
        return false;
      }
      seen = line;
      return true;
    };
    auto oneUnsigned = [&](uint64_t& v) {
      if (nvalues != 1 || !ParseUnsigned(t[1], v))
      {
        return fail(line, key + " expects one non-negative integer, found '" +
            (nvalues ? Show(t[1].Begin, t.back().End) : std::string()) + "'");
      }
      return true;
    };
    if (key == "VERSION")
    {
      if (!once(versionLine))
        return false;
      h.Version = nvalues ? t[1].Str() : std::string();
      static const char* const known[] = { "0.7", ".7", "0.6", ".6", "0.5", ".5", "7", "6", "5" };
      bool ok = false;
      for (const char* k : known)
      {
        ok = ok || h.Version == k;
      }
      if (!ok)
      {
        h.Warnings.push_back(file + ":" + std::to_string(line) + ": VERSION '" +
          Show(h.Version) + "' is not one of 0.5, 0.6, 0.7; read as 0.7");
      }
    }
    else if (key == "FIELDS" || key == "COLUMNS")
    {
      if (fieldsLine)
      {
        return fail(line, key + " is given twice (first on line " + std::to_string(fieldsLine) +
            ")");
      }
      fieldsLine = line;
      if (nvalues == 0)
      {
        return fail(line, key + " lists no fields");
      }
      if (nvalues > MaximumFields)
      {
        return fail(line, key + " lists " + std::to_string(nvalues) + " fields; at most " +
            std::to_string(MaximumFields) + " are supported");
      }
      for (size_t i = 1; i < t.size(); ++i)
      {
        Field f;
        f.Name = t[i].Str();
        f.Line = line;
        if (!f.Padding())
        {
          for (const Field& g : h.Fields)
          {
            if (g.Name == f.Name)
            {
              return fail(line, key + " names the field '" + Show(f.Name) + "' twice");
            }
          }
        }
        h.Fields.push_back(std::move(f));
      }
    }
    else if (key == "SIZE")
    {
      if (!once(sizeLine))
        return false;
      sizeTokens.assign(t.begin() + 1, t.end());
    }
    else if (key == "TYPE")
    {
      if (!once(typeLine))
        return false;
      typeTokens.assign(t.begin() + 1, t.end());
    }
    else if (key == "COUNT")
    {
      if (!once(countLine))
        return false;
      countTokens.assign(t.begin() + 1, t.end());
    }
    else if (key == "WIDTH")
    {
      if (!once(widthLine) || !oneUnsigned(h.Width))
        return false;
    }
    else if (key == "HEIGHT")
    {
      if (!once(heightLine) || !oneUnsigned(h.Height))
        return false;
    }
    else if (key == "POINTS")
    {
      if (!once(pointsLine) || !oneUnsigned(h.Points))
        return false;
    }
    else if (key == "VIEWPOINT")
    {
      if (!once(viewpointLine))
        return false;
      if (nvalues < 7)
      {
        return fail(line, "VIEWPOINT expects 7 numbers (tx ty tz qw qx qy qz), found " +
            std::to_string(nvalues));
      }
      for (int i = 0; i < 7; ++i)
      {
        if (!ParseDouble(t[i + 1], h.Viewpoint[i]))
        {
          return fail(line, "VIEWPOINT value " + std::to_string(i + 1) +
              " is not a number: '" + Show(t[i + 1].Begin, t[i + 1].End) + "'");
        }
      }
    }
    else if (key == "DATA")
    {
      const std::string form = nvalues ? t[1].Str() : std::string();
      if (nvalues == 1 && form == "ascii")
        h.Data = Encoding::Ascii;
      else if (nvalues == 1 && form == "binary")
        h.Data = Encoding::Binary;
      else if (nvalues == 1 && form == "binary_compressed")
        h.Data = Encoding::BinaryCompressed;
      else
      {
        return fail(line, "unknown DATA '" +
            (nvalues ? Show(t[1].Begin, t.back().End) : std::string()) +
            "': expected ascii, binary or binary_compressed");
      }
      h.DataOffset = static_cast<size_t>(next - data);
      h.DataLine = line;
      break;
    }
    else
    {
      return fail(line, "unknown header keyword '" + Show(t[0].Begin, t[0].End) +
          "' (expected VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS or "
          "DATA before the data)");
    }
  }

  // ---- The header is complete: check that its parts agree.
  const size_t dataLine = h.DataLine;
  if (!fieldsLine)
  {
    return fail(dataLine, "the header has no FIELDS line before DATA");
  }
  const size_t nfields = h.Fields.size();
  auto lengthsAgree = [&](const char* what, size_t where, const std::vector<Token>& v) {
    if (where && v.size() != nfields)
    {
      return fail(where, std::string(what) + " lists " + std::to_string(v.size()) +
          " value(s), FIELDS (line " + std::to_string(fieldsLine) + ") lists " +
          std::to_string(nfields) + " field(s)");
    }
    return true;
  };
  if (!lengthsAgree("SIZE", sizeLine, sizeTokens) || !lengthsAgree("TYPE", typeLine, typeTokens) ||
    !lengthsAgree("COUNT", countLine, countTokens))
  {
    return false;
  }
  for (size_t i = 0; i < nfields; ++i)
  {
    Field& f = h.Fields[i];
    const std::string which = "field " + std::to_string(i + 1) + " (" + Show(f.Name) + ")";
    if (sizeLine)
    {
      uint64_t s = 0;
      if (!ParseUnsigned(sizeTokens[i], s) || (s != 1 && s != 2 && s != 4 && s != 8))
      {
        return fail(sizeLine, "SIZE of " + which + " is '" +
            Show(sizeTokens[i].Begin, sizeTokens[i].End) + "'; expected 1, 2, 4 or 8");
      }
      f.Size = static_cast<int>(s);
    }
    if (typeLine)
    {
      const Token& tt = typeTokens[i];
      if (tt.End - tt.Begin != 1 || (*tt.Begin != 'I' && *tt.Begin != 'U' && *tt.Begin != 'F'))
      {
        return fail(typeLine, "TYPE of " + which + " is '" + Show(tt.Begin, tt.End) +
            "'; expected I (signed), U (unsigned) or F (float)");
      }
      f.Type = *tt.Begin;
    }
    if (f.Type == 'F' && f.Size != 4 && f.Size != 8)
    {
      return fail(typeLine ? typeLine : sizeLine, "TYPE of " + which + " is F with SIZE " +
          std::to_string(f.Size) + "; floats have SIZE 4 or 8");
    }
    if (countLine)
    {
      uint64_t c = 0;
      if (!ParseUnsigned(countTokens[i], c) || c > (uint64_t(1) << 24))
      {
        return fail(countLine, "COUNT of " + which + " is '" +
            Show(countTokens[i].Begin, countTokens[i].End) +
            "'; expected a non-negative integer (at most 16777216)");
      }
      f.Count = c;
    }
  }
  // COUNT 0: PCL drops the field (and warns); so do we.
  for (size_t i = 0; i < h.Fields.size();)
  {
    if (h.Fields[i].Count == 0)
    {
      h.Warnings.push_back(file + ":" + std::to_string(countLine) + ": field '" +
        Show(h.Fields[i].Name) + "' has COUNT 0 and no values; it is left out");
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
      return fail(fieldsLine, std::string("no field '") + axis + "': FIELDS lists '" +
          Show(names) + "'; the points need x, y and z");
    }
    if (h.Fields[k].Count != 1)
    {
      return fail(countLine, std::string("field '") + axis + "' has COUNT " +
          std::to_string(h.Fields[k].Count) + "; a coordinate needs COUNT 1");
    }
  }
  if (!pointsLine)
  {
    return fail(dataLine, "the header has no POINTS line before DATA");
  }
  // WIDTH and HEIGHT as PCL completes them: neither given, an unorganised
  // cloud of POINTS; no HEIGHT, one row.
  if (!widthLine && !heightLine)
  {
    h.Width = h.Points;
    h.Height = 1;
  }
  else if (!heightLine)
  {
    h.Height = 1;
  }
  else if (!widthLine)
  {
    if (h.Points != 0)
    {
      return fail(heightLine, "HEIGHT is given (" + std::to_string(h.Height) +
          ") but WIDTH is not");
    }
  }
  uint64_t product = 0;
  const bool fits = CheckedMultiply(h.Width, h.Height, product);
  if (!fits || product != h.Points)
  {
    return fail(pointsLine, "WIDTH x HEIGHT (" + std::to_string(h.Width) + " x " +
        std::to_string(h.Height) + (fits ? " = " + std::to_string(product) : ", too large") +
        ") differs from POINTS " + std::to_string(h.Points));
  }
  uint64_t total = 0;
  if (!CheckedMultiply(h.Points, h.PointStep, total) || total > (uint64_t(1) << 62))
  {
    return fail(pointsLine, "POINTS " + std::to_string(h.Points) + " of " +
        std::to_string(h.PointStep) + " bytes each is more data than can be addressed");
  }
  return true;
}

// ---- Values.

// A float from a double, out-of-range values becoming +-infinity (a plain
// conversion of those is undefined behaviour).
template <typename Out>
inline Out Narrow(double v)
{
  if (std::is_same<Out, float>::value && std::isfinite(v) && std::fabs(v) > FLT_MAX)
  {
    return static_cast<Out>(v > 0 ? std::numeric_limits<float>::infinity()
                                  : -std::numeric_limits<float>::infinity());
  }
  return static_cast<Out>(v);
}

template <typename T, typename Out>
inline void GatherAs(const unsigned char* base, size_t stride, size_t n, Out* out, size_t outStride)
{
  for (size_t i = 0; i < n; ++i)
  {
    T v;
    std::memcpy(&v, base + i * stride, sizeof(T));
    if (std::is_same<T, double>::value)
    {
      out[i * outStride] = Narrow<Out>(static_cast<double>(v));
    }
    else
    {
      out[i * outStride] = static_cast<Out>(v);
    }
  }
}

// out[i * outStride] = value i, read at base + i * stride as the declared
// type (a field's values of n points, or one component of them).
template <typename Out>
inline void Gather(
  char type, int size, const unsigned char* base, size_t stride, size_t n, Out* out, size_t outStride)
{
  switch (type == 'F' ? size : type == 'I' ? -size : 16 + size)
  {
    case 4:
      GatherAs<float>(base, stride, n, out, outStride);
      break;
    case 8:
      GatherAs<double>(base, stride, n, out, outStride);
      break;
    case -1:
      GatherAs<int8_t>(base, stride, n, out, outStride);
      break;
    case -2:
      GatherAs<int16_t>(base, stride, n, out, outStride);
      break;
    case -4:
      GatherAs<int32_t>(base, stride, n, out, outStride);
      break;
    case -8:
      GatherAs<int64_t>(base, stride, n, out, outStride);
      break;
    case 17:
      GatherAs<uint8_t>(base, stride, n, out, outStride);
      break;
    case 18:
      GatherAs<uint16_t>(base, stride, n, out, outStride);
      break;
    case 20:
      GatherAs<uint32_t>(base, stride, n, out, outStride);
      break;
    case 24:
      GatherAs<uint64_t>(base, stride, n, out, outStride);
      break;
    default:
      break; // ParseHeader admits no other combination
  }
}

// Packed colours: the 4 bytes of an rgb / rgba value (float or uint32 in the
// file, the same bits) are 0xAARRGGBB as a little-endian uint32.
inline void UnpackColors(
  const unsigned char* base, size_t stride, size_t n, unsigned char* out, int components)
{
  for (size_t i = 0; i < n; ++i)
  {
    uint32_t v;
    std::memcpy(&v, base + i * stride, 4);
    unsigned char* o = out + i * static_cast<size_t>(components);
    o[0] = static_cast<unsigned char>(v >> 16);
    o[1] = static_cast<unsigned char>(v >> 8);
    o[2] = static_cast<unsigned char>(v);
    if (components == 4)
    {
      o[3] = static_cast<unsigned char>(v >> 24);
    }
  }
}

// ---- LZF.

// The most bytes one compressed byte can become: a 3-byte back-reference
// copies at most 264.
constexpr size_t LzfMaximumExpansion = 88;

// GCC 12 warns of the fixed 32-byte moves below when it inlines a call
// with a small constant output (a test's): they are taken only where both
// buffers have 32 bytes of room, which it does not follow.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstringop-overflow"
#endif
// Inflates in[0, inSize) into exactly outSize bytes at out. progress(bytes
// written so far) is called about every megabyte; when it returns false the
// decoding stops (aborted; error left empty). On a corrupt stream, error says
// what is wrong and at which compressed and uncompressed byte.
template <typename Progress>
inline bool LzfDecompress(const unsigned char* in, size_t inSize, unsigned char* out,
  size_t outSize, std::string& error, Progress&& progress)
{
  size_t ip = 0, op = 0;
  size_t nextReport = size_t(1) << 20;
  auto where = [&](size_t at) {
    return " (instruction at compressed byte " + std::to_string(at) + ", output byte " +
      std::to_string(op) + ")";
  };
  while (ip < inSize)
  {
    const size_t at = ip;
    const unsigned ctrl = in[ip++];
    if (ctrl < 32)
    {
      const size_t run = ctrl + 1;
      if (run > inSize - ip)
      {
        error = "a literal run of " + std::to_string(run) + " bytes goes past the end of the " +
          "compressed data (" + std::to_string(inSize - ip) + " byte(s) left)" + where(at);
        return false;
      }
      if (run > outSize - op)
      {
        error = "a literal run of " + std::to_string(run) + " bytes goes past the " +
          std::to_string(outSize) + " bytes the block should inflate to" + where(at);
        return false;
      }
      // A fixed 32-byte copy where both buffers have the room (the bytes
      // past the run are written again by what follows): one wide move
      // instead of a call for a few bytes.
      if (inSize - ip >= 32 && outSize - op >= 32)
      {
        std::memcpy(out + op, in + ip, 32);
      }
      else
      {
        std::memcpy(out + op, in + ip, run);
      }
      ip += run;
      op += run;
    }
    else
    {
      size_t len = ctrl >> 5;
      if (len == 7)
      {
        if (ip >= inSize)
        {
          error = "a back-reference is cut off by the end of the compressed data" + where(at);
          return false;
        }
        len += in[ip++];
      }
      if (ip >= inSize)
      {
        error = "a back-reference is cut off by the end of the compressed data" + where(at);
        return false;
      }
      const size_t distance = ((static_cast<size_t>(ctrl & 31) << 8) | in[ip++]) + 1;
      len += 2;
      if (distance > op)
      {
        error = "a back-reference reaches " + std::to_string(distance) +
          " bytes back, before the start of the output" + where(at);
        return false;
      }
      if (len > outSize - op)
      {
        error = "a back-reference of " + std::to_string(len) + " bytes goes past the " +
          std::to_string(outSize) + " bytes the block should inflate to" + where(at);
        return false;
      }
      if (distance >= 32 && len <= 32 && outSize - op >= 32)
      {
        // Source and destination 32 bytes apart or more: one fixed move.
        std::memcpy(out + op, out + op - distance, 32);
        op += len;
      }
      // In pieces of at most `distance` bytes: each piece reads bytes that
      // are already written (a copy longer than its distance repeats them).
      else for (size_t left = len; left > 0;)
      {
        const size_t piece = std::min(left, distance);
        std::memcpy(out + op, out + op - distance, piece);
        op += piece;
        left -= piece;
      }
    }
    if (op >= nextReport)
    {
      nextReport = op + (size_t(1) << 20);
      if (!progress(op))
      {
        error.clear();
        return false;
      }
    }
  }
  if (op != outSize)
  {
    error = "the compressed data ends after " + std::to_string(op) + " of the " +
      std::to_string(outSize) + " bytes it should inflate to";
    return false;
  }
  return true;
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

// ---- The ascii body.

inline bool AllDigits(const char* b, const char* e)
{
  if (b == e)
  {
    return false;
  }
  for (const char* c = b; c < e; ++c)
  {
    if (static_cast<unsigned>(*c - '0') >= 10)
    {
      return false;
    }
  }
  return true;
}

// The value of a decimal number too large or too small for its type:
// +-infinity when its exponent is positive, +-0 when it is negative.
inline double OutOfRange(const char* s, const char* e)
{
  const bool negative = s < e && *s == '-';
  const char* x = s;
  while (x < e && *x != 'e' && *x != 'E')
  {
    ++x;
  }
  const bool tiny = x + 1 < e && x[1] == '-';
  const double v = tiny ? 0.0 : std::numeric_limits<double>::infinity();
  return negative ? -v : v;
}

// Stores one ascii token as the field's declared type at dst. False (with
// `why`) when it is no number of that type.
inline bool StoreToken(const Field& f, const char* b, const char* e, unsigned char* dst,
  std::string& why)
{
  if (f.Type == 'F')
  {
    // PCL writes a packed colour declared F as the uint32 it holds (its
    // float would often be NaN): a token of digits only in an rgb/rgba field
    // is those bits; anything else is the float.
    if (f.Size == 4 && (f.Name == "rgb" || f.Name == "rgba") && AllDigits(b, e))
    {
      uint32_t bits = 0;
      auto r = std::from_chars(b, e, bits);
      if (r.ec != std::errc() || r.ptr != e)
      {
        why = "a packed colour (0 to 4294967295)";
        return false;
      }
      std::memcpy(dst, &bits, 4);
      return true;
    }
    const char* s = b;
    if (s < e && *s == '+')
    {
      ++s;
    }
    if (f.Size == 4)
    {
      float v;
      auto r = std::from_chars(s, e, v);
      if (s == e || r.ptr != e ||
        (r.ec != std::errc() && r.ec != std::errc::result_out_of_range))
      {
        why = "a number";
        return false;
      }
      if (r.ec == std::errc::result_out_of_range)
      {
        v = static_cast<float>(OutOfRange(s, e)); // from_chars leaves v unset
      }
      std::memcpy(dst, &v, 4);
    }
    else
    {
      double v;
      auto r = std::from_chars(s, e, v);
      if (s == e || r.ptr != e ||
        (r.ec != std::errc() && r.ec != std::errc::result_out_of_range))
      {
        why = "a number";
        return false;
      }
      if (r.ec == std::errc::result_out_of_range)
      {
        v = OutOfRange(s, e);
      }
      std::memcpy(dst, &v, 8);
    }
    return true;
  }
  // Integers: an integer token, or a number with an integral value, in the
  // range of the declared type.
  const bool isSigned = f.Type == 'I';
  const int bits = 8 * f.Size;
  const long double lo = isSigned ? -std::ldexp(1.0L, bits - 1) : 0.0L;
  const long double hi = isSigned ? std::ldexp(1.0L, bits - 1) - 1 : std::ldexp(1.0L, bits) - 1;
  auto range = [&]() { return std::string(isSigned ? "I" : "U") + " " + std::to_string(f.Size); };
  const char* s = b;
  if (s < e && *s == '+')
  {
    ++s;
  }
  int64_t sv = 0;
  uint64_t uv = 0;
  bool integral = false;
  if (isSigned)
  {
    auto r = std::from_chars(s, e, sv);
    integral = s < e && r.ec == std::errc() && r.ptr == e;
  }
  else if (s < e && *s != '-')
  {
    auto r = std::from_chars(s, e, uv);
    integral = r.ec == std::errc() && r.ptr == e;
  }
  if (!integral)
  {
    double d;
    auto r = std::from_chars(s, e, d);
    if (s == e || r.ec != std::errc() || r.ptr != e || !std::isfinite(d) || d != std::floor(d) ||
      static_cast<long double>(d) < lo || static_cast<long double>(d) > hi)
    {
      why = "an integer of type " + range();
      return false;
    }
    if (isSigned)
      sv = static_cast<int64_t>(d);
    else
      uv = static_cast<uint64_t>(d);
  }
  if (isSigned ? (static_cast<long double>(sv) < lo || static_cast<long double>(sv) > hi)
               : static_cast<long double>(uv) > hi)
  {
    why = "an integer of type " + range();
    return false;
  }
  switch (f.Size)
  {
    case 1:
    {
      const uint8_t v = isSigned ? static_cast<uint8_t>(static_cast<int8_t>(sv)) : static_cast<uint8_t>(uv);
      std::memcpy(dst, &v, 1);
      break;
    }
    case 2:
    {
      const uint16_t v = isSigned ? static_cast<uint16_t>(static_cast<int16_t>(sv)) : static_cast<uint16_t>(uv);
      std::memcpy(dst, &v, 2);
      break;
    }
    case 4:
    {
      const uint32_t v = isSigned ? static_cast<uint32_t>(static_cast<int32_t>(sv)) : static_cast<uint32_t>(uv);
      std::memcpy(dst, &v, 4);
      break;
    }
    default:
    {
      const uint64_t v = isSigned ? static_cast<uint64_t>(sv) : uv;
      std::memcpy(dst, &v, 8);
      break;
    }
  }
  return true;
}

// Parses the ascii body [b, e) (its first line is line `firstLine` of the
// file) into h.Points interleaved points of h.PointStep bytes at out, the
// values in their declared types: the layout of a binary body. Blank lines
// are skipped. progress(points so far) is called every 65536 points; false
// stops (aborted, error left empty). Errors name file, line and column.
template <typename Progress>
inline bool ParseAscii(const char* b, const char* e, size_t firstLine, const Header& h,
  const std::string& file, unsigned char* out, std::string& error,
  std::vector<std::string>& warnings, Progress&& progress)
{
  const uint64_t n = h.Points;
  std::string names;
  for (const Field& f : h.Fields)
  {
    names += (names.empty() ? "" : " ") + f.Name + (f.Count > 1 ? "[" + std::to_string(f.Count) + "]" : "");
  }
  uint64_t pt = 0;
  size_t line = firstLine - 1;
  const char* p = b;
  std::string why;
  while (p < e && pt < n)
  {
    ++line;
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(e - p)));
    const char* le = nl ? nl : e;
    const char* ls = p;
    p = nl ? nl + 1 : e;
    const char* q = ls;
    while (q < le && IsBlank(*q))
    {
      ++q;
    }
    if (q == le)
    {
      continue;
    }
    unsigned char* dst = out + pt * h.PointStep;
    size_t value = 0;
    for (const Field& f : h.Fields)
    {
      for (uint64_t c = 0; c < f.Count; ++c, ++value)
      {
        while (q < le && IsBlank(*q))
        {
          ++q;
        }
        if (q == le)
        {
          error = file + ":" + std::to_string(line) + ":" + std::to_string(q - ls + 1) +
            ": expected " + std::to_string(h.ValuesPerPoint) + " values (" + Show(names) +
            "), found " + std::to_string(value);
          return false;
        }
        const char* t = q;
        while (q < le && !IsBlank(*q))
        {
          ++q;
        }
        if (f.Padding())
        {
          continue;
        }
        if (!StoreToken(f, t, q, dst + f.Offset + c * static_cast<uint64_t>(f.Size), why))
        {
          error = file + ":" + std::to_string(line) + ":" + std::to_string(t - ls + 1) +
            ": expected " + why + " for value " + std::to_string(value + 1) + " (" +
            Show(f.Name) + (f.Count > 1 ? "[" + std::to_string(c) + "]" : "") + "), found '" +
            Show(t, q) + "'";
          return false;
        }
      }
    }
    while (q < le && IsBlank(*q))
    {
      ++q;
    }
    if (q < le)
    {
      size_t extra = 0;
      for (const char* r = q; r < le;)
      {
        while (r < le && IsBlank(*r))
          ++r;
        if (r == le)
          break;
        ++extra;
        while (r < le && !IsBlank(*r))
          ++r;
      }
      error = file + ":" + std::to_string(line) + ":" + std::to_string(q - ls + 1) +
        ": expected " + std::to_string(h.ValuesPerPoint) + " values (" + Show(names) +
        "), found " + std::to_string(h.ValuesPerPoint + extra);
      return false;
    }
    ++pt;
    if ((pt & 0xffff) == 0 && !progress(pt))
    {
      error.clear();
      return false;
    }
  }
  if (pt < n)
  {
    error = file + ": the ascii data ends at line " + std::to_string(line) + " after " +
      std::to_string(pt) + " point(s); the header promises POINTS " + std::to_string(n);
    return false;
  }
  // Lines after the last point: PCL ignores them; say so.
  size_t extraLines = 0, firstExtra = 0;
  while (p < e)
  {
    ++line;
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(e - p)));
    const char* le = nl ? nl : e;
    const char* q = p;
    while (q < le && IsBlank(*q))
      ++q;
    if (q < le)
    {
      if (!extraLines)
        firstExtra = line;
      ++extraLines;
    }
    p = nl ? nl + 1 : e;
  }
  if (extraLines)
  {
    warnings.push_back(file + ":" + std::to_string(firstExtra) + ": " +
      std::to_string(extraLines) + " line(s) after the " + std::to_string(n) +
      " point(s) of POINTS were ignored");
  }
  return true;
}

} // namespace pcd
} // namespace octoray

#endif
