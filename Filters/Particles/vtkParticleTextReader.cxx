#include "vtkParticleTextReader.h"

#include "octorayTextSource.h"

#include "vtkCellArray.h"
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
#include <atomic>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

vtkStandardNewMacro(vtkParticleTextReader);

namespace
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

inline bool IsBlank(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}
inline bool EndsToken(char c)
{
  return IsBlank(c) || c == ',' || c == '#';
}

// Powers of ten that are exact in float (up to 1e10) and double (up to 1e22).
template <typename Real>
constexpr Real Pow10[] = { 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12,
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

std::string TokenAt(const char* p, const char* e)
{
  const char* q = p;
  while (q < e && !EndsToken(*q))
  {
    ++q;
  }
  std::string t(p, q);
  if (t.size() > 40)
  {
    t = t.substr(0, 37) + "...";
  }
  return t;
}

// Splits a line into tokens (no number parsing); used for the header and
// the first data line only.
std::vector<std::pair<std::string, int>> SplitTokens(const char* b, const char* e)
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

std::string Lower(std::string s)
{
  for (char& c : s)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return s;
}

bool IsNumber(const std::string& s)
{
  double v;
  return ParseNumber(s.data(), s.data() + s.size(), v) != nullptr;
}

// Maps header names to sinks; false when x, y or z is missing or a name repeats.
bool LayoutFromNames(const std::vector<std::string>& names, std::vector<Column>& columns,
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

bool LayoutFromCount(size_t n, std::vector<Column>& columns)
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

template <typename Real>
struct Sinks
{
  Real* Points = nullptr;
  unsigned char* Colors = nullptr;
  Real* Reflectivity = nullptr;
  Real* Refraction = nullptr;
  Real* Scalars = nullptr;
  std::vector<Real*> Extras;
};

struct ChunkResult
{
  vtkIdType Lines = 0;     // newline-terminated lines (and a last unterminated one)
  vtkIdType DataLines = 0; // lines that are neither blank nor comments
  vtkIdType Bad = 0;
  vtkIdType FirstLine = 0; // 1-based number of the chunk's first line
  vtkIdType FirstPoint = 0;
  std::vector<vtkIdType> BadLines; // the first few, in order
  std::string FirstMessage;
};

// Runs work(i) for i in [0, n) on `threads` threads; the calling thread waits
// and reports progress, because VTK's progress events must come from it.
template <typename Work, typename Progress>
void ParallelChunks(int n, int threads, Work&& work, Progress&& progress)
{
  std::atomic<int> next{ 0 };
  std::atomic<int> done{ 0 };
  std::mutex m;
  std::condition_variable cv;
  auto worker = [&]() {
    for (int i = next++; i < n; i = next++)
    {
      work(i);
      {
        std::lock_guard<std::mutex> lock(m);
        ++done;
      }
      cv.notify_one();
    }
  };
  // The calling thread only waits and reports, so `threads` workers parse;
  // with one thread (or one chunk) it parses itself.
  std::vector<std::thread> pool;
  const int workers = std::min(threads, n);
  for (int t = 0; workers > 1 && t < workers; ++t)
  {
    pool.emplace_back(worker);
  }
  if (pool.empty())
  {
    // One thread: work here, reporting between chunks.
    for (int i = next++; i < n; i = next++)
    {
      work(i);
      ++done;
      progress(done.load());
    }
  }
  else
  {
    std::unique_lock<std::mutex> lock(m);
    while (done.load() < n)
    {
      cv.wait_for(lock, std::chrono::milliseconds(50));
      lock.unlock();
      progress(done.load());
      lock.lock();
    }
  }
  for (auto& t : pool)
  {
    t.join();
  }
}
} // namespace

//------------------------------------------------------------------------------
vtkParticleTextReader::vtkParticleTextReader()
{
  this->SetNumberOfInputPorts(0);
}

//------------------------------------------------------------------------------
vtkParticleTextReader::~vtkParticleTextReader()
{
  this->SetFileName(nullptr);
}

//------------------------------------------------------------------------------
void vtkParticleTextReader::Fail(const std::string& message)
{
  this->ErrorMessage = message;
  vtkErrorMacro(<< message);
}

//------------------------------------------------------------------------------
int vtkParticleTextReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  this->ErrorMessage.clear();
  this->ColumnNames.clear();
  this->NumberOfSkippedLines = 0;

  if (!this->FileName || !*this->FileName)
  {
    this->Fail("no file name was set");
    return 0;
  }
  octoray::TextSource source;
  std::string error;
  if (!source.Open(this->FileName, error))
  {
    this->Fail(error);
    return 0;
  }
  this->UpdateProgress(0.0);
  const bool ok = this->OutputPointsPrecision == DOUBLE_PRECISION
    ? this->Parse<double>(source.Data(), source.Size(), output)
    : this->Parse<float>(source.Data(), source.Size(), output);
  if (!ok)
  {
    output->Initialize();
    return 0;
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
template <typename Real>
bool vtkParticleTextReader::Parse(const char* data, size_t size, vtkPolyData* output)
{
  const std::string file = this->FileName;
  const char* const end = data + size;
  if (size == 0)
  {
    this->Fail(file + ": the file is empty (0 bytes); expected one particle a line: x y z [r g b "
                      "[reflectivity refraction]]");
    return false;
  }

  // Serial prologue: comments, the optional header, and the first data line,
  // whose column count gives the layout when there is no header.
  std::vector<Column> columns;
  std::vector<std::string> extras;
  bool haveHeader = false;
  vtkIdType lineNo = 0;
  const char* p = data;
  const char* firstData = nullptr;
  vtkIdType firstDataLine = 0;
  while (p < end)
  {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', end - p));
    const char* e = nl ? nl : end;
    ++lineNo;
    const char* q = p;
    while (q < e && IsBlank(*q))
    {
      ++q;
    }
    if (q < e)
    {
      const bool comment = *q == '#';
      auto tokens = comment ? SplitTokens(q + 1, e) : SplitTokens(q, e);
      bool allNames = !tokens.empty() &&
        std::none_of(tokens.begin(), tokens.end(), [](auto& t) { return IsNumber(t.first); });
      std::vector<std::string> names;
      for (auto& t : tokens)
      {
        names.push_back(t.first);
      }
      auto named = [&](const char* want) {
        return std::any_of(
          names.begin(), names.end(), [&](const std::string& n) { return Lower(n) == want; });
      };
      const bool namesXYZ = allNames && named("x") && named("y") && named("z");
      if (!haveHeader && namesXYZ)
      {
        std::string why;
        if (!LayoutFromNames(names, columns, extras, why))
        {
          this->Fail(file + ":" + std::to_string(lineNo) + ":1: bad header line: " + why);
          return false;
        }
        haveHeader = true;
      }
      else if (!comment)
      {
        firstData = p;
        firstDataLine = lineNo;
        if (!haveHeader)
        {
          if (!LayoutFromCount(tokens.size(), columns))
          {
            this->Fail(file + ":" + std::to_string(lineNo) + ":1: expected 3 (x y z), 4 (x y z "
                "scalar), 6 (x y z r g b) or 8 (x y z r g b reflectivity refraction) columns, "
                "found " + std::to_string(tokens.size()) +
              "; a header line such as '# x y z intensity' names other layouts");
            return false;
          }
        }
        break;
      }
    }
    p = nl ? nl + 1 : end;
  }
  const int ncols = static_cast<int>(columns.size());
  std::string layout;
  for (const auto& c : columns)
  {
    layout += (layout.empty() ? "" : " ") + c.Name;
  }
  this->ColumnNames = layout;
  if (!firstData)
  {
    this->Fail(file + ":" + std::to_string(lineNo) + ":1: no particle lines in the file (only " +
      (haveHeader ? "a header, " : "") + "comments or blank lines); expected lines of " +
      (haveHeader ? layout : std::string("x y z ...")));
    return false;
  }

  // Chunks start at line starts; each is about 1 MB, at least 8 per thread
  // so that threads that finish early pick up more.
  int threads = this->NumberOfThreads > 0 ? this->NumberOfThreads
                                          : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::max(1, threads);
  const size_t dataBytes = static_cast<size_t>(end - firstData);
  size_t chunkBytes = std::max<size_t>(1 << 20, dataBytes / (static_cast<size_t>(threads) * 8) + 1);
  std::vector<const char*> starts{ firstData };
  while (true)
  {
    const char* s = starts.back() + chunkBytes;
    if (s >= end)
    {
      break;
    }
    const char* nl = static_cast<const char*>(std::memchr(s, '\n', end - s));
    if (!nl || nl + 1 >= end)
    {
      break;
    }
    starts.push_back(nl + 1);
  }
  const int nchunks = static_cast<int>(starts.size());
  starts.push_back(end);
  std::vector<ChunkResult> results(nchunks);

  // Pass 1: lines and data lines per chunk, for line numbers and the place of
  // each chunk's points in the output arrays.
  ParallelChunks(
    nchunks, threads,
    [&](int c) {
      ChunkResult& r = results[c];
      const char* s = starts[c];
      const char* ce = starts[c + 1];
      while (s < ce)
      {
        const char* nl = static_cast<const char*>(std::memchr(s, '\n', ce - s));
        const char* e = nl ? nl : ce;
        ++r.Lines;
        while (s < e && IsBlank(*s))
        {
          ++s;
        }
        if (s < e && *s != '#')
        {
          ++r.DataLines;
        }
        s = nl ? nl + 1 : ce;
      }
    },
    [&](int done) { this->UpdateProgress(0.1 * done / nchunks); });
  vtkIdType total = 0;
  vtkIdType line = firstDataLine;
  for (auto& r : results)
  {
    r.FirstPoint = total;
    r.FirstLine = line;
    total += r.DataLines;
    line += r.Lines;
  }

  // Output arrays, filled in place by pass 2.
  using RealArray = typename std::conditional<std::is_same<Real, double>::value, vtkDoubleArray,
    vtkFloatArray>::type;
  bool has[static_cast<int>(Sink::Extra)] = {};
  for (const auto& c : columns)
  {
    if (c.Target != Sink::Extra)
    {
      has[static_cast<int>(c.Target)] = true;
    }
  }
  auto makeArray = [&](const char* name, int comps) {
    auto a = vtkSmartPointer<RealArray>::New();
    a->SetName(name);
    a->SetNumberOfComponents(comps);
    a->SetNumberOfTuples(total);
    return a;
  };
  auto pointsArray = makeArray("Points", 3);
  vtkSmartPointer<vtkUnsignedCharArray> colors;
  vtkSmartPointer<RealArray> refl, refr, scalars;
  std::vector<vtkSmartPointer<RealArray>> extraArrays;
  Sinks<Real> sinks;
  sinks.Points = pointsArray->GetPointer(0);
  if (has[static_cast<int>(Sink::R)])
  {
    colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
    colors->SetName("Colors");
    colors->SetNumberOfComponents(3);
    colors->SetNumberOfTuples(total);
    sinks.Colors = colors->GetPointer(0);
  }
  if (has[static_cast<int>(Sink::Reflectivity)])
  {
    refl = makeArray("Reflectivity", 1);
    sinks.Reflectivity = refl->GetPointer(0);
  }
  if (has[static_cast<int>(Sink::Refraction)])
  {
    refr = makeArray("Refraction", 1);
    sinks.Refraction = refr->GetPointer(0);
  }
  if (has[static_cast<int>(Sink::Scalar)])
  {
    scalars = makeArray("Scalars", 1);
    sinks.Scalars = scalars->GetPointer(0);
  }
  for (const auto& name : extras)
  {
    extraArrays.push_back(makeArray(name.c_str(), 1));
    sinks.Extras.push_back(extraArrays.back()->GetPointer(0));
  }
  std::vector<unsigned char> valid;
  if (this->Lenient)
  {
    valid.assign(static_cast<size_t>(total), 1);
  }

  // Pass 2: parse. In strict mode a chunk stops at its first bad line, and
  // chunks after a chunk that already failed stop early, so the error that is
  // reported is the one with the lowest line number.
  const bool lenient = this->Lenient;
  const size_t keep = static_cast<size_t>(this->MaximumReportedLines);
  std::atomic<int> firstFailedChunk{ std::numeric_limits<int>::max() };
  std::atomic<bool> aborted{ false };
  ParallelChunks(
    nchunks, threads,
    [&](int c) {
      ChunkResult& r = results[c];
      const char* s = starts[c];
      const char* ce = starts[c + 1];
      vtkIdType ln = r.FirstLine - 1;
      vtkIdType pt = r.FirstPoint;
      std::vector<Real> values(ncols);
      auto bad = [&](const char* lineStart, const char* at, const std::string& what) {
        ++r.Bad;
        if (r.BadLines.size() < std::max<size_t>(keep, 1))
        {
          r.BadLines.push_back(ln);
        }
        if (r.FirstMessage.empty())
        {
          r.FirstMessage = file + ":" + std::to_string(ln) + ":" +
            std::to_string(at - lineStart + 1) + ": " + what;
        }
        if (lenient)
        {
          valid[pt] = 0;
        }
      };
      while (s < ce)
      {
        if (!lenient && (firstFailedChunk.load(std::memory_order_relaxed) < c || aborted))
        {
          return;
        }
        const char* nl = static_cast<const char*>(std::memchr(s, '\n', ce - s));
        const char* e = nl ? nl : ce;
        const char* lineStart = s;
        ++ln;
        const char* q = s;
        s = nl ? nl + 1 : ce;
        while (q < e && IsBlank(*q))
        {
          ++q;
        }
        if (q == e || *q == '#')
        {
          continue;
        }
        // Tokens: numbers separated by blanks or one comma.
        int field = 0;
        bool failed = false;
        while (true)
        {
          const char* tok = q;
          if (field < ncols)
          {
            Real v;
            const char* after = ParseNumber(q, e, v);
            const Column& col = columns[field];
            if (!after)
            {
              bad(lineStart, tok, "expected a number for column " + std::to_string(field + 1) +
                  " (" + col.Name + "), found '" + TokenAt(tok, e) + "'");
              failed = true;
              break;
            }
            if (!std::isfinite(v))
            {
              bad(lineStart, tok, "expected a finite number for column " +
                  std::to_string(field + 1) + " (" + col.Name + "), found '" + TokenAt(tok, e) +
                  "'");
              failed = true;
              break;
            }
            if ((col.Target == Sink::R || col.Target == Sink::G || col.Target == Sink::B) &&
              (v < 0 || v > 255))
            {
              bad(lineStart, tok, "expected a colour value 0-255 for column " +
                  std::to_string(field + 1) + " (" + col.Name + "), found '" + TokenAt(tok, e) +
                  "'");
              failed = true;
              break;
            }
            if (col.Target == Sink::Reflectivity && (v < 0 || v > 1))
            {
              bad(lineStart, tok, "expected a reflectivity 0-1 for column " +
                  std::to_string(field + 1) + " (" + col.Name + "), found '" + TokenAt(tok, e) +
                  "'");
              failed = true;
              break;
            }
            if (col.Target == Sink::Refraction && v < 0)
            {
              bad(lineStart, tok, "expected a refraction index >= 0 (0 = none) for column " +
                  std::to_string(field + 1) + " (" + col.Name + "), found '" + TokenAt(tok, e) +
                  "'");
              failed = true;
              break;
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
          while (q < e && IsBlank(*q))
          {
            ++q;
          }
          if (q < e && *q == ',')
          {
            ++q;
            while (q < e && IsBlank(*q))
            {
              ++q;
            }
            if (q == e || *q == ',' || *q == '#')
            {
              bad(lineStart, q, "expected a number for column " + std::to_string(field + 1) +
                  " after the comma, found an empty field");
              failed = true;
              break;
            }
          }
          else if (q == e || *q == '#')
          {
            break;
          }
        }
        if (!failed && field != ncols)
        {
          bad(lineStart, field < ncols ? q : lineStart,
            "expected " + std::to_string(ncols) + " columns (" + layout + "), found " +
              std::to_string(field));
          failed = true;
        }
        if (failed)
        {
          if (!lenient)
          {
            int expected = firstFailedChunk.load();
            while (c < expected && !firstFailedChunk.compare_exchange_weak(expected, c))
            {
            }
            return;
          }
          ++pt;
          continue;
        }
        Real rgb[3] = { 0, 0, 0 };
        for (int f = 0; f < ncols; ++f)
        {
          const Real v = values[f];
          switch (columns[f].Target)
          {
            case Sink::X:
              sinks.Points[3 * pt] = v;
              break;
            case Sink::Y:
              sinks.Points[3 * pt + 1] = v;
              break;
            case Sink::Z:
              sinks.Points[3 * pt + 2] = v;
              break;
            case Sink::R:
              rgb[0] = v;
              break;
            case Sink::G:
              rgb[1] = v;
              break;
            case Sink::B:
              rgb[2] = v;
              break;
            case Sink::Reflectivity:
              sinks.Reflectivity[pt] = v;
              break;
            case Sink::Refraction:
              sinks.Refraction[pt] = v;
              break;
            case Sink::Scalar:
              sinks.Scalars[pt] = v;
              break;
            case Sink::Extra:
              sinks.Extras[columns[f].Extra][pt] = v;
              break;
          }
        }
        if (sinks.Colors)
        {
          for (int k = 0; k < 3; ++k)
          {
            // rgb is in [0, 255] (checked above): adding 0.5 rounds half up.
            sinks.Colors[3 * pt + k] = static_cast<unsigned char>(rgb[k] + Real(0.5));
          }
        }
        ++pt;
      }
    },
    [&](int done) {
      this->UpdateProgress(0.1 + 0.85 * done / nchunks);
      if (this->GetAbortExecute())
      {
        aborted = true;
      }
    });

  if (aborted)
  {
    this->Fail(file + ": reading was aborted");
    return false;
  }

  vtkIdType badCount = 0;
  std::vector<vtkIdType> badLines;
  std::string firstMessage;
  for (const auto& r : results)
  {
    badCount += r.Bad;
    if (firstMessage.empty() && !r.FirstMessage.empty())
    {
      firstMessage = r.FirstMessage;
    }
    for (vtkIdType l : r.BadLines)
    {
      if (badLines.size() < keep)
      {
        badLines.push_back(l);
      }
    }
  }
  if (badCount && !lenient)
  {
    this->Fail(firstMessage);
    return false;
  }

  vtkIdType kept = total;
  if (badCount)
  {
    // Compact the arrays over the skipped lines, keeping the file's order.
    vtkIdType w = 0;
    for (vtkIdType i = 0; i < total; ++i)
    {
      if (!valid[i])
      {
        continue;
      }
      if (w != i)
      {
        std::copy_n(sinks.Points + 3 * i, 3, sinks.Points + 3 * w);
        if (sinks.Colors)
          std::copy_n(sinks.Colors + 3 * i, 3, sinks.Colors + 3 * w);
        if (sinks.Reflectivity)
          sinks.Reflectivity[w] = sinks.Reflectivity[i];
        if (sinks.Refraction)
          sinks.Refraction[w] = sinks.Refraction[i];
        if (sinks.Scalars)
          sinks.Scalars[w] = sinks.Scalars[i];
        for (Real* x : sinks.Extras)
          x[w] = x[i];
      }
      ++w;
    }
    kept = w;
    pointsArray->Resize(kept);
    pointsArray->SetNumberOfTuples(kept);
    if (colors)
    {
      colors->Resize(kept);
      colors->SetNumberOfTuples(kept);
    }
    for (RealArray* a : { refl.Get(), refr.Get(), scalars.Get() })
    {
      if (a)
      {
        a->Resize(kept);
        a->SetNumberOfTuples(kept);
      }
    }
    for (auto& a : extraArrays)
    {
      a->Resize(kept);
      a->SetNumberOfTuples(kept);
    }
    this->NumberOfSkippedLines = badCount;
    this->ErrorMessage = firstMessage;
    std::ostringstream lines;
    for (size_t i = 0; i < badLines.size(); ++i)
    {
      lines << (i ? ", " : "") << badLines[i];
    }
    vtkWarningMacro(<< file << ": skipped " << badCount << " bad line(s) of " << total
                    << " (lenient mode); first at line(s) " << lines.str()
                    << (static_cast<vtkIdType>(badLines.size()) < badCount ? ", ..." : "")
                    << "; first problem: " << firstMessage);
  }
  if (kept == 0)
  {
    this->Fail(file + ": every particle line was bad; nothing was read. First problem: " +
      firstMessage);
    return false;
  }

  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetData(pointsArray);
  output->SetPoints(points);
  vtkPointData* pd = output->GetPointData();
  if (colors)
  {
    pd->AddArray(colors);
    // Colors drive direct-RGB rendering; VTK treats them as scalars too.
    pd->SetScalars(colors);
  }
  if (scalars)
  {
    pd->AddArray(scalars);
    pd->SetActiveScalars(colors ? colors->GetName() : scalars->GetName());
  }
  if (refl)
  {
    pd->AddArray(refl);
  }
  if (refr)
  {
    pd->AddArray(refr);
  }
  for (auto& a : extraArrays)
  {
    pd->AddArray(a);
  }
  if (this->GenerateVertices)
  {
    auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
    offsets->SetNumberOfTuples(kept + 1);
    auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
    conn->SetNumberOfTuples(kept);
    vtkIdType* o = offsets->GetPointer(0);
    vtkIdType* cn = conn->GetPointer(0);
    for (vtkIdType i = 0; i < kept; ++i)
    {
      o[i] = i;
      cn[i] = i;
    }
    o[kept] = kept;
    auto verts = vtkSmartPointer<vtkCellArray>::New();
    verts->SetData(offsets, conn);
    output->SetVerts(verts);
  }
  // Lenient mode leaves its record in the data too, so a pipeline downstream
  // (or a saved file) still says what was skipped.
  if (lenient)
  {
    auto count = vtkSmartPointer<vtkIdTypeArray>::New();
    count->SetName("SkippedLineCount");
    count->InsertNextValue(badCount);
    auto numbers = vtkSmartPointer<vtkIdTypeArray>::New();
    numbers->SetName("SkippedLineNumbers");
    for (vtkIdType l : badLines)
    {
      numbers->InsertNextValue(l);
    }
    output->GetFieldData()->AddArray(count);
    output->GetFieldData()->AddArray(numbers);
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkParticleTextReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "OutputPointsPrecision: " << this->OutputPointsPrecision << "\n";
  os << indent << "GenerateVertices: " << this->GenerateVertices << "\n";
  os << indent << "Lenient: " << this->Lenient << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "MaximumReportedLines: " << this->MaximumReportedLines << "\n";
  os << indent << "NumberOfSkippedLines: " << this->NumberOfSkippedLines << "\n";
  os << indent << "ColumnNames: " << this->ColumnNames << "\n";
}
