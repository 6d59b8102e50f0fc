// The particle text format without VTK: tokens, numbers, the column layout
// from a header line or a column count, the prologue (comments, header,
// first data line) of a file, and the fields of a data line with the
// message for a bad one. vtkParticleTextReader parses with these; the fuzz
// targets in Testing/Fuzz and the engine's command-line tool
// (Rendering/Engine/Tools/PointFile.h, which builds without VTK) call them
// directly. Not wrapped.
#ifndef octorayParticleTextFormat_h
#define octorayParticleTextFormat_h

#include "octorayTextScan.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace octoray
{
namespace ptext
{
// Where a column's value goes.
enum class Sink
{
  X,
  Y,
  Z,
  R,
  G,
  B,
  Reflectivity,
  Refraction,
  Scalar,
  Extra
};

struct Column
{
  std::string Name;
  Sink Target;
  int Extra; // index into the extra arrays for Sink::Extra
};

inline bool EndsToken(char c)
{
  return IsBlank(c) || c == ',' || c == '#';
}

// Powers of ten that are exact in float (up to 1e10) and double (up to 1e22).
template <typename Real>
inline constexpr Real Pow10[] = { 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12,
  1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22 };

// Numbers as exporters write them (plain decimals such as -123.4567 or 255):
// when the digits form an integer m that the type holds exactly and 10^k is
// exact too, m / 10^k is one correctly rounded division (Clinger's fast
// path), so the result equals from_chars' at a fraction of the cost. Anything
// else (exponents, long mantissas, inf, nan) goes to std::from_chars, which
// rejects a leading '+' that printf("%+f") writes.
template <typename Real>
inline const char* ParseNumber(const char* p, const char* e, Real& v)
{
  {
    constexpr bool isFloat = std::is_same<Real, float>::value;
    constexpr uint64_t maxMantissa = isFloat ? (uint64_t(1) << 24) : (uint64_t(1) << 53);
    constexpr int maxFraction = isFloat ? 10 : 22;
    const char* q = p;
    bool negative = false;
    if (q < e && (*q == '-' || *q == '+'))
    {
      negative = *q == '-';
      ++q;
    }
    uint64_t m = 0;
    int digits = 0, fraction = 0;
    while (q < e && static_cast<unsigned>(*q - '0') < 10 && digits < 19)
    {
      m = m * 10 + static_cast<unsigned>(*q - '0');
      ++q;
      ++digits;
    }
    if (q < e && *q == '.')
    {
      ++q;
      while (q < e && static_cast<unsigned>(*q - '0') < 10 && digits < 19)
      {
        m = m * 10 + static_cast<unsigned>(*q - '0');
        ++q;
        ++digits;
        ++fraction;
      }
    }
    if (digits > 0 && (q == e || EndsToken(*q)) && m <= maxMantissa && fraction <= maxFraction)
    {
      const Real r = static_cast<Real>(m) / Pow10<Real>[fraction];
      v = negative ? -r : r;
      return q;
    }
  }
  if (p < e && *p == '+')
  {
    ++p;
    if (p < e && (*p == '-' || *p == '+'))
    {
      return nullptr;
    }
  }
  auto r = std::from_chars(p, e, v, std::chars_format::general);
  if (r.ec != std::errc() || (r.ptr < e && !EndsToken(*r.ptr)))
  {
    return nullptr;
  }
  return r.ptr;
}

// What a token that ParseNumber refused should have been: a number, or,
// where it is one beyond Real's range ("1e39" in single precision, "1e-400"
// in double), a number within that range.
template <typename Real>
inline const char* NumberExpected(const char* p, const char* e)
{
  double d = 0.0;
  const char* b = p < e && *p == '+' ? p + 1 : p;
  const auto r = std::from_chars(b, e, d, std::chars_format::general);
  const bool number = r.ptr != b && (r.ptr == e || EndsToken(*r.ptr)) &&
    (r.ec == std::errc::result_out_of_range || (r.ec == std::errc() && std::is_same<Real, float>::value));
  if (!number)
  {
    return "a number";
  }
  return std::is_same<Real, float>::value
    ? "a number within single precision's range (OutputPointsPrecision double reads more)"
    : "a number within double precision's range";
}

// The token at p for an error message (Printable: at most 40 characters,
// bytes that are not printable ASCII as \xNN). Looks at no more than 41
// bytes, whatever the token's length (a 10 GB line of NUL bytes).
inline std::string TokenAt(const char* p, const char* e)
{
  const char* q = p;
  while (q < e && q - p <= 40 && !EndsToken(*q))
  {
    ++q;
  }
  return Printable(p, q);
}

// Splits a line into tokens (no number parsing); used for the header and
// the first data line only.
inline std::vector<std::pair<std::string, int>> SplitTokens(const char* b, const char* e)
{
  std::vector<std::pair<std::string, int>> tokens;
  const char* p = b;
  while (p < e)
  {
    while (p < e && (IsBlank(*p) || *p == ','))
    {
      ++p;
    }
    if (p >= e || *p == '#')
    {
      break;
    }
    const char* q = p;
    while (q < e && !EndsToken(*q))
    {
      ++q;
    }
    tokens.emplace_back(std::string(p, q), static_cast<int>(p - b) + 1);
    p = q;
  }
  return tokens;
}

// A line of decimal commas ("1,5 2,5 3,5", read as the six fields 1 5 2 5
// 3 5, as a comma parts fields): two or more fields parted by blanks, each
// of digits with one comma between two of them and no point; the first such
// comma, or null. Fields parted by blanks and commas alike ("1.5\t2.5,3.5")
// are not.
inline const char* DecimalComma(const char* b, const char* e)
{
  const char* first = nullptr;
  int fields = 0;
  for (const char* p = SkipBlanks(b, e); p < e && *p != '#'; p = SkipBlanks(p, e), ++fields)
  {
    const char* comma = nullptr;
    for (; p < e && !IsBlank(*p); ++p)
    {
      const bool between = *p == ',' && comma == nullptr && p > b && p + 1 < e &&
        std::isdigit(static_cast<unsigned char>(p[-1])) && std::isdigit(static_cast<unsigned char>(p[1]));
      if (!(between || std::isdigit(static_cast<unsigned char>(*p)) || *p == '-' || *p == '+'))
      {
        return nullptr;
      }
      comma = between ? p : comma;
    }
    if (!comma)
    {
      return nullptr;
    }
    first = first ? first : comma;
  }
  return fields >= 2 ? first : nullptr;
}

inline std::string Lower(std::string s)
{
  for (char& c : s)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return s;
}

inline bool IsNumber(const std::string& s)
{
  double v;
  return ParseNumber(s.data(), s.data() + s.size(), v) != nullptr;
}

// Maps header names to sinks; false when x, y or z is missing or a name repeats.
inline bool LayoutFromNames(const std::vector<std::string>& names, std::vector<Column>& columns,
  std::vector<std::string>& extras, std::string& why)
{
  columns.clear();
  extras.clear();
  bool seen[static_cast<int>(Sink::Extra)] = {};
  for (const auto& original : names)
  {
    std::string n = Lower(original);
    Sink s = Sink::Extra;
    if (n == "x")
      s = Sink::X;
    else if (n == "y")
      s = Sink::Y;
    else if (n == "z")
      s = Sink::Z;
    else if (n == "r" || n == "red")
      s = Sink::R;
    else if (n == "g" || n == "green")
      s = Sink::G;
    else if (n == "b" || n == "blue")
      s = Sink::B;
    else if (n == "reflectivity")
      s = Sink::Reflectivity;
    else if (n == "refraction")
      s = Sink::Refraction;
    else if (n == "scalar" || n == "scalars")
      s = Sink::Scalar;
    if (s != Sink::Extra)
    {
      if (seen[static_cast<int>(s)])
      {
        why = "column '" + original + "' is named twice";
        return false;
      }
      seen[static_cast<int>(s)] = true;
      columns.push_back({ original, s, -1 });
    }
    else
    {
      if (std::find(extras.begin(), extras.end(), original) != extras.end())
      {
        why = "column '" + original + "' is named twice";
        return false;
      }
      columns.push_back({ original, s, static_cast<int>(extras.size()) });
      extras.push_back(original);
    }
  }
  if (!seen[0] || !seen[1] || !seen[2])
  {
    why = "the header must name the columns x, y and z";
    return false;
  }
  const int rgb = seen[3] + seen[4] + seen[5];
  if (rgb != 0 && rgb != 3)
  {
    why = "the header names some but not all of the colour columns r, g, b";
    return false;
  }
  return true;
}

inline bool LayoutFromCount(size_t n, std::vector<Column>& columns)
{
  static const char* names8[] = { "x", "y", "z", "r", "g", "b", "reflectivity", "refraction" };
  std::vector<std::string> names;
  if (n == 3 || n == 6 || n == 8)
  {
    names.assign(names8, names8 + n);
  }
  else if (n == 4)
  {
    names = { "x", "y", "z", "scalar" };
  }
  else
  {
    return false;
  }
  std::vector<std::string> extras;
  std::string why;
  return LayoutFromNames(names, columns, extras, why);
}

// The prologue of a particle text file: comment lines, the optional header
// line, and the first data line (whose column count gives the layout when
// there is no header). Errors name file, line and column like the reader's.
struct Prologue
{
  bool Ok = false;
  std::string Error;
  std::vector<Column> Columns;
  std::vector<std::string> Extras;
  std::string Layout; // the column names, space separated
  bool HaveHeader = false;
  size_t FirstData = 0;        // byte offset of the first data line
  long long FirstDataLine = 0; // its 1-based line number
};

// Longest header or first data line accepted: far more than any real layout
// needs, and it keeps the serial prologue from walking a huge binary file.
constexpr size_t MaxPrologueLine = size_t(1) << 20;

// The column names of a header line: a line's tokens (a comment's after
// its '#') where none is a number and they name x, y and z; else none.
inline std::vector<std::string> HeaderNames(const std::vector<std::pair<std::string, int>>& tokens)
{
  std::vector<std::string> names;
  for (const auto& t : tokens)
  {
    if (IsNumber(t.first))
    {
      return {};
    }
    names.push_back(t.first);
  }
  const auto named = [&names](const char* axis) {
    return std::any_of(names.begin(), names.end(), [axis](const std::string& n) { return Lower(n) == axis; });
  };
  return named("x") && named("y") && named("z") ? names : std::vector<std::string>();
}

// Why the prologue's line `lineNo`, [p, e) of the file at data, is not
// text: longer than MaxPrologueLine (`cut`: no newline within it) or
// holding a NUL byte, which no particle text file holds; "" where it is.
inline std::string NotText(
  const char* data, const char* p, const char* e, bool cut, const std::string& file, long long lineNo)
{
  if (cut)
  {
    return Where(file, lineNo, 1) + "line " + std::to_string(lineNo) + " is longer than " +
      std::to_string(MaxPrologueLine) + " bytes before any particle was read; not a particle text file";
  }
  if (const void* z = std::memchr(p, '\0', static_cast<size_t>(e - p)))
  {
    const char* at = static_cast<const char*>(z);
    return Where(file, lineNo, at - p + 1) + "a NUL byte (at byte offset " + std::to_string(at - data) +
      "): this is a binary file, not particle text";
  }
  // A CR is a blank where it ends a CRLF line; one inside a line ends the
  // lines of classic Mac OS files, which would otherwise run together into
  // one line of many columns.
  const char* last = e > p && e[-1] == '\r' ? e - 1 : e;
  if (const void* cr = std::memchr(p, '\r', static_cast<size_t>(last - p)))
  {
    return Where(file, lineNo, static_cast<const char*>(cr) - p + 1) +
      "a carriage return inside a line: lines that end in CR alone (classic Mac OS) are not read; convert the "
      "file to LF or CRLF line ends";
  }
  return "";
}

// Line `lineNo` of the prologue, [p, e) of the file at data, from its first
// non-blank byte q: the header line (the first that names x, y and z), a
// comment, or the first data line, which ends the prologue and, without a
// header, gives the layout by its column count. False, with r.Error, where
// the line is wrong.
inline bool ReadPrologueLine(Prologue& r, const char* data, const char* p, const char* q, const char* e,
  const std::string& file, long long lineNo)
{
  const std::string where = Where(file, lineNo, 1);
  const bool comment = *q == '#';
  const auto tokens = SplitTokens(comment ? q + 1 : q, e);
  const std::vector<std::string> names = r.HaveHeader ? std::vector<std::string>() : HeaderNames(tokens);
  if (!names.empty())
  {
    std::string why;
    r.HaveHeader = LayoutFromNames(names, r.Columns, r.Extras, why);
    r.Error = r.HaveHeader ? "" : where + "bad header line: " + why;
    return r.HaveHeader;
  }
  if (comment)
  {
    return true;
  }
  r.FirstData = static_cast<size_t>(p - data);
  r.FirstDataLine = lineNo;
  if (const char* comma = DecimalComma(q, e))
  {
    r.Error = Where(file, lineNo, comma - p + 1) +
      "a comma between digits in a line whose fields are parted by blanks: a decimal comma? Write decimals "
      "with a point (1.5); a comma parts fields";
    return false;
  }
  const char* binary = FirstBinaryByte(q, e);
  if (binary != e)
  {
    char byte[8];
    std::snprintf(byte, sizeof(byte), "0x%02x", static_cast<unsigned char>(*binary));
    r.Error = Where(file, lineNo, binary - p + 1) + "a byte " + byte +
      ", which no particle line holds: a binary file (an image, a LAS file?), not particle text";
    return false;
  }
  if (!r.HaveHeader && !LayoutFromCount(tokens.size(), r.Columns))
  {
    r.Error = where +
      "expected 3 (x y z), 4 (x y z scalar), 6 (x y z r g b) or 8 (x y z r g b reflectivity refraction) "
      "columns, found " +
      std::to_string(tokens.size()) + "; a header line such as '# x y z intensity' names other layouts";
    return false;
  }
  return true;
}

// Reads the prologue; its Error names the file, line and column of what is
// wrong, or says that the file is empty or that no data line follows.
inline Prologue ParsePrologue(const char* data, size_t size, const std::string& file)
{
  Prologue r;
  if (size == 0)
  {
    r.Error = file + ": the file is empty (0 bytes); expected one particle a line: x y z [r g b [reflectivity "
                     "refraction]]";
    return r;
  }
  const char* const end = data + size;
  long long lineNo = 0;
  // A UTF-8 byte order mark is not part of the first line.
  for (const char* p = data + (StartsUtf8Mark(data, size) ? 3 : 0); p < end && r.FirstDataLine == 0;)
  {
    ++lineNo;
    const size_t look = std::min<size_t>(static_cast<size_t>(end - p), MaxPrologueLine + 1);
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', look));
    const char* e = nl ? nl : end;
    r.Error = NotText(data, p, e, !nl && look > MaxPrologueLine, file, lineNo);
    if (!r.Error.empty())
    {
      return r;
    }
    const char* q = SkipBlanks(p, e);
    if (q < e && !ReadPrologueLine(r, data, p, q, e, file, lineNo))
    {
      return r;
    }
    p = nl ? nl + 1 : end;
  }
  for (const auto& c : r.Columns)
  {
    r.Layout += (r.Layout.empty() ? "" : " ") + c.Name;
  }
  if (r.FirstDataLine == 0)
  {
    r.Error = Where(file, std::max(lineNo, 1LL), 1) + "no particle lines in the file (only " +
      (r.HaveHeader ? "a header, " : "") + "comments or blank lines); expected lines of " +
      (r.HaveHeader ? r.Layout : std::string("x y z ..."));
    return r;
  }
  r.Ok = true;
  return r;
}

// What is wrong with a data line: where, and what.
struct Problem
{
  const char* At = nullptr;
  std::string What;
};

// What a value of a column of that sink must be, when v is not it: the
// "expected ..." of the message; null when v is fine.
template <typename Real>
inline const char* Expected(Sink target, Real v)
{
  if (!std::isfinite(v))
  {
    return "a finite number";
  }
  switch (target)
  {
    case Sink::R:
    case Sink::G:
    case Sink::B:
      // Whole numbers: 0-1 colours (Open3D's .xyzrgb) rounded to black.
      return v < 0 || v > 255 || v != std::floor(v) ? "a whole colour value 0-255 (scale 0-1 colours by 255)"
                                                     : nullptr;
    case Sink::Reflectivity:
      return v < 0 || v > 1 ? "a reflectivity 0-1" : nullptr;
    case Sink::Refraction:
      return v < 0 ? "a refraction index >= 0 (0 = none)" : nullptr;
    default:
      return nullptr;
  }
}

// The fields of the data line that starts at lineStart, from its first
// non-blank byte q to e: numbers separated by blanks or one comma, into
// values (one a column of the prologue's layout). False, with the problem,
// at the first that is wrong.
template <typename Real>
inline bool ParseFields(
  const Prologue& pro, const char* lineStart, const char* q, const char* e, Real* values, Problem& problem)
{
  const int ncols = static_cast<int>(pro.Columns.size());
  int field = 0;
  while (true)
  {
    const char* tok = q;
    if (field < ncols)
    {
      Real v;
      const char* after = ParseNumber(q, e, v);
      const Column& col = pro.Columns[field];
      if (const char* expected = after ? Expected(col.Target, v) : NumberExpected<Real>(q, e))
      {
        problem = { tok, "expected " + std::string(expected) + " for column " + std::to_string(field + 1) +
            " (" + col.Name + "), found '" + TokenAt(tok, e) + "'" };
        return false;
      }
      values[field] = v;
      q = after;
    }
    else
    {
      while (q < e && !EndsToken(*q))
      {
        ++q;
      }
    }
    ++field;
    q = SkipBlanks(q, e);
    if (q < e && *q == ',')
    {
      q = SkipBlanks(q + 1, e);
      if (q == e || *q == ',' || *q == '#')
      {
        problem = { q, "expected a number for column " + std::to_string(field + 1) +
            " after the comma, found an empty field" };
        return false;
      }
    }
    else if (q == e || *q == '#')
    {
      break;
    }
  }
  if (field != ncols)
  {
    problem = { field < ncols ? q : lineStart, "expected " + std::to_string(ncols) + " columns (" + pro.Layout +
        "), found " + std::to_string(field) };
    return false;
  }
  return true;
}

// Calls visit(lineStart, q, e) for each data line of [s, end): each line
// whose first non-blank byte q is neither its end e nor a comment's '#'.
// `line` holds the number of the line at s and counts on with every line,
// blank and comment lines too, so that visit reads its line's number there;
// the walk stops at end, or at a line for which visit returns false.
template <typename LineNumber, typename Visit>
inline void ForEachDataLine(const char* s, const char* const end, LineNumber& line, Visit&& visit)
{
  for (; s < end; ++line)
  {
    const char* const lineStart = s;
    const char* const nl = static_cast<const char*>(std::memchr(s, '\n', static_cast<size_t>(end - s)));
    const char* const e = nl ? nl : end;
    s = nl ? nl + 1 : end;
    const char* const q = SkipBlanks(lineStart, e);
    if (q != e && *q != '#' && !visit(lineStart, q, e))
    {
      return;
    }
  }
}

// A problem's message: file:line:column: what.
inline std::string LineMessage(const std::string& file, long long line, const char* lineStart, const Problem& problem)
{
  return Where(file, line, problem.At - lineStart + 1) + problem.What;
}

// Whether the start of a file is particle text, for CanReadFile (a reader
// factory choosing among the readers of an ambiguous extension such as .txt
// or .csv): the prologue parses as the reader parses it (comments, a header
// line naming x, y and z, or a first data line of 3, 4, 6 or 8 columns), and
// the first `lines` data lines each hold as many numbers as the layout has
// columns. `complete` says the bytes are the whole file; otherwise a last
// line without its newline is cut off there and not judged. `why` gets the
// reason for a no.
constexpr int SniffLines = 16;

inline bool LooksLikeParticleText(
  const char* data, size_t size, bool complete, std::string* why = nullptr, int lines = SniffLines)
{
  auto no = [why](std::string reason) {
    if (why)
    {
      *why = std::move(reason);
    }
    return false;
  };
  if (!complete)
  {
    size_t whole = size;
    while (whole > 0 && data[whole - 1] != '\n')
    {
      --whole;
    }
    if (whole == 0)
    {
      return no("no whole line in the first " + std::to_string(size) + " bytes");
    }
    size = whole;
  }
  const Prologue pro = ParsePrologue(data, size, "file");
  if (!pro.Ok)
  {
    return no(pro.Error);
  }
  const size_t columns = pro.Columns.size();
  const char* const end = data + size;
  const char* p = data + pro.FirstData;
  long long line = pro.FirstDataLine;
  for (int checked = 0; p < end && checked < lines; ++line)
  {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(end - p)));
    const char* e = nl ? nl : end;
    const auto tokens = SplitTokens(p, e); // stops at a comment
    if (!tokens.empty())
    {
      ++checked;
      if (tokens.size() != columns)
      {
        return no("line " + std::to_string(line) + ": " + std::to_string(tokens.size()) +
          " fields, expected " + std::to_string(columns) + " (" + pro.Layout + ")");
      }
      for (const auto& t : tokens)
      {
        if (!IsNumber(t.first))
        {
          return no("line " + std::to_string(line) + ": '" +
            TokenAt(t.first.data(), t.first.data() + t.first.size()) + "' is not a number");
        }
      }
    }
    p = nl ? nl + 1 : end;
  }
  return true;
}

} // namespace ptext
} // namespace octoray

#endif
