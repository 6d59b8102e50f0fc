// The ascii body of a PCD file, without VTK: each line's values parsed into
// the declared types of the header's fields, so that the result has the
// layout of a binary body and one conversion serves both. vtkPCDReader
// parses with these (through octorayPCDBody.h). Private to the module; not
// wrapped.
#ifndef octorayPCDAscii_h
#define octorayPCDAscii_h

#include "octorayPCDHeader.h"
#include "octorayTextScan.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

namespace octoray
{
namespace pcd
{
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

// A float token [s, e) (its '+' already skipped) as T at dst; false when it
// is no number.
template <typename T>
inline bool StoreFloat(const char* s, const char* e, unsigned char* dst)
{
  T v;
  auto r = std::from_chars(s, e, v);
  if (s == e || r.ptr != e || (r.ec != std::errc() && r.ec != std::errc::result_out_of_range))
  {
    return false;
  }
  if (r.ec == std::errc::result_out_of_range)
  {
    v = static_cast<T>(OutOfRange(s, e)); // from_chars leaves v unset
  }
  std::memcpy(dst, &v, sizeof(T));
  return true;
}

// The low `size` bytes' worth of an integer (already checked to fit) at dst.
template <typename T>
inline void StoreBits(uint64_t bits, unsigned char* dst)
{
  const T v = static_cast<T>(bits);
  std::memcpy(dst, &v, sizeof(T));
}

// An integer token [b, e) of field f at dst: an integer, or a number with an
// integral value, in the range of the declared type. False (with `why`)
// otherwise.
inline bool StoreInteger(
  const Field& f, const char* b, const char* e, unsigned char* dst, std::string& why)
{
  const bool isSigned = f.Type == 'I';
  const int bits = 8 * f.Size;
  const long double lo = isSigned ? -std::ldexp(1.0L, bits - 1) : 0.0L;
  const long double hi = isSigned ? std::ldexp(1.0L, bits - 1) - 1 : std::ldexp(1.0L, bits) - 1;
  auto outOfType = [&]() {
    why = "an integer of type " + std::string(isSigned ? "I" : "U") + " " +
      std::to_string(f.Size);
    return false;
  };
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
      return outOfType();
    }
    if (isSigned)
      sv = static_cast<int64_t>(d);
    else
      uv = static_cast<uint64_t>(d);
  }
  if (isSigned ? (static_cast<long double>(sv) < lo || static_cast<long double>(sv) > hi)
               : static_cast<long double>(uv) > hi)
  {
    return outOfType();
  }
  // Two's complement: the low bytes of a signed value that fits are its own.
  const uint64_t value = isSigned ? static_cast<uint64_t>(sv) : uv;
  switch (f.Size)
  {
    case 1:
      StoreBits<uint8_t>(value, dst);
      break;
    case 2:
      StoreBits<uint16_t>(value, dst);
      break;
    case 4:
      StoreBits<uint32_t>(value, dst);
      break;
    default:
      StoreBits<uint64_t>(value, dst);
      break;
  }
  return true;
}

// Stores one ascii token as the field's declared type at dst. False (with
// `why`) when it is no number of that type.
inline bool StoreToken(
  const Field& f, const char* b, const char* e, unsigned char* dst, std::string& why)
{
  if (f.Type != 'F')
  {
    return StoreInteger(f, b, e, dst, why);
  }
  // PCL writes a packed colour declared F as the uint32 it holds (its float
  // would often be NaN): a token of digits only in an rgb/rgba field is
  // those bits; anything else is the float.
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
  const char* s = b < e && *b == '+' ? b + 1 : b;
  if (!(f.Size == 4 ? StoreFloat<float>(s, e, dst) : StoreFloat<double>(s, e, dst)))
  {
    why = "a number";
    return false;
  }
  return true;
}

// The lines of [p, e) that hold more than blanks: how many, and the index
// (0 for the first line of [p, e)) of the first of them.
struct NonBlankLines
{
  size_t Count = 0;
  size_t First = 0;
};

inline NonBlankLines CountNonBlankLines(const char* p, const char* e)
{
  NonBlankLines r;
  for (size_t index = 0; p < e; ++index)
  {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(e - p)));
    const char* le = nl ? nl : e;
    if (SkipBlanks(p, le) < le)
    {
      r.First = r.Count ? r.First : index;
      ++r.Count;
    }
    p = nl ? nl + 1 : e;
  }
  return r;
}

// The header's values for a message: "x y z rgb fpfh[33]".
inline std::string AsciiValueNames(const Header& h)
{
  std::string names;
  for (const Field& f : h.Fields)
  {
    names += (names.empty() ? "" : " ") + f.Name +
      (f.Count > 1 ? "[" + std::to_string(f.Count) + "]" : "");
  }
  return names;
}

// Parses one ascii line [ls, le), line `line` of the file and not blank,
// into the point at dst. On failure, error names file, line and column.
inline bool ParseAsciiLine(const char* ls, const char* le, size_t line, const Header& h,
  const std::string& file, const std::string& names, unsigned char* dst, std::string& error)
{
  auto where = [&](const char* at) { return Where(file, static_cast<long long>(line), at - ls + 1); };
  auto wrongCount = [&](const char* at, size_t found) {
    error = where(at) + "expected " + std::to_string(h.ValuesPerPoint) + " values (" +
      Printable(names) + "), found " + std::to_string(found);
    return false;
  };
  const char* q = ls;
  size_t value = 0;
  std::string why;
  for (const Field& f : h.Fields)
  {
    for (uint64_t c = 0; c < f.Count; ++c, ++value)
    {
      q = SkipBlanks(q, le);
      if (q == le)
      {
        return wrongCount(q, value);
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
        error = where(t) + "expected " + why + " for value " + std::to_string(value + 1) + " (" +
          Printable(f.Name) + (f.Count > 1 ? "[" + std::to_string(c) + "]" : "") + "), found '" +
          Printable(t, q) + "'";
        return false;
      }
    }
  }
  q = SkipBlanks(q, le);
  if (q < le)
  {
    size_t extra = 0;
    for (const char* r = q; r < le;)
    {
      ++extra;
      while (r < le && !IsBlank(*r))
        ++r;
      r = SkipBlanks(r, le);
    }
    return wrongCount(q, h.ValuesPerPoint + extra);
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
  const std::string names = AsciiValueNames(h);
  uint64_t pt = 0;
  size_t line = firstLine - 1;
  const char* p = b;
  while (p < e && pt < n)
  {
    ++line;
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(e - p)));
    const char* le = nl ? nl : e;
    const char* ls = p;
    p = nl ? nl + 1 : e;
    if (SkipBlanks(ls, le) == le)
    {
      continue;
    }
    if (!ParseAsciiLine(ls, le, line, h, file, names, out + pt * h.PointStep, error))
    {
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
  const NonBlankLines rest = CountNonBlankLines(p, e);
  if (rest.Count)
  {
    warnings.push_back(file + ":" + std::to_string(line + 1 + rest.First) + ": " +
      std::to_string(rest.Count) + " line(s) after the " + std::to_string(n) +
      " point(s) of POINTS were ignored");
  }
  return true;
}

} // namespace pcd
} // namespace octoray

#endif
