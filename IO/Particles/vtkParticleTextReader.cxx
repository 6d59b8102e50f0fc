#include "vtkParticleTextReader.h"

#include "octorayParticleTextFormat.h"
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
#include "vtk_zlib.h"

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
#include <new>
#include <sstream>
#include <thread>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

vtkStandardNewMacro(vtkParticleTextReader);

namespace
{
using namespace octoray::ptext;

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
  // A failed update leaves the output of the last successful one (or an
  // empty one) in place, never a half-read file: the pipeline has already
  // emptied the output, so the kept copy is put back.
  auto restore = [&]() {
    if (this->LastOutput)
    {
      output->ShallowCopy(this->LastOutput);
    }
    else
    {
      output->Initialize();
    }
  };
  octoray::TextSource source;
  std::string error;
  if (!source.Open(this->FileName, error))
  {
    this->Fail(error);
    restore();
    return 0;
  }
  this->UpdateProgress(0.0);
  auto fresh = vtkSmartPointer<vtkPolyData>::New();
  bool ok = false;
  try
  {
    ok = this->OutputPointsPrecision == DOUBLE_PRECISION
      ? this->Parse<double>(source.Data(), source.Size(), fresh)
      : this->Parse<float>(source.Data(), source.Size(), fresh);
  }
  catch (const std::bad_alloc&)
  {
    this->Fail(std::string(this->FileName) + ": out of memory while reading " +
      std::to_string(source.Size()) + " bytes");
    ok = false;
  }
  // Truncated while mapped: the parse went on over zeros (and may have
  // failed on them, reported just before); what it found is not the file.
  if (source.Truncated())
  {
    this->Fail(source.TruncationMessage(this->FileName));
    ok = false;
  }
  else if (ok && source.ChangedSinceOpen())
  {
    this->Fail(std::string(this->FileName) +
      ": the file changed while it was being read; nothing was read (read it again)");
    ok = false;
  }
  if (!ok)
  {
    restore();
    return 0;
  }
  output->ShallowCopy(fresh);
  this->LastOutput = fresh;
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
int vtkParticleTextReader::CanReadFile(const char* filename)
{
  if (!filename || !*filename)
  {
    return 0;
  }
  struct stat st;
  if (::stat(filename, &st) != 0 || !S_ISREG(st.st_mode))
  {
    return 0;
  }
  const std::string name = filename;
  auto endsWith = [&name](const char* tail) {
    const size_t n = std::strlen(tail);
    if (name.size() < n)
    {
      return false;
    }
    for (size_t i = 0; i < n; ++i)
    {
      if (std::tolower(static_cast<unsigned char>(name[name.size() - n + i])) != tail[i])
      {
        return false;
      }
    }
    return true;
  };
  if (endsWith(".particles") || endsWith(".particles.gz"))
  {
    return ::access(filename, R_OK) == 0 ? 1 : 0;
  }
  // The first bytes of the text (inflated when the file is gzip data; gzread
  // passes plain files through).
  constexpr int sniffBytes = 1 << 16;
  gzFile in = gzopen(filename, "rb");
  if (!in)
  {
    return 0;
  }
  std::string head(sniffBytes + 1, '\0');
  const int got = gzread(in, &head[0], sniffBytes + 1);
  gzclose(in);
  if (got <= 0)
  {
    return 0;
  }
  const bool complete = got <= sniffBytes;
  head.resize(complete ? static_cast<size_t>(got) : static_cast<size_t>(sniffBytes));
  return octoray::ptext::LooksLikeParticleText(head.data(), head.size(), complete) ? 1 : 0;
}

//------------------------------------------------------------------------------
vtkMTimeType vtkParticleTextReader::GetMTime()
{
  const vtkMTimeType own = this->Superclass::GetMTime();
  const std::string signature = octoray::FileSignature(this->FileName);
  if (signature != this->FileSignature)
  {
    this->FileSignature = signature;
    this->FileChangeTime.Modified();
  }
  return std::max(own, this->FileChangeTime.GetMTime());
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
  Prologue pro = ParsePrologue(data, size, file);
  this->ColumnNames = pro.Layout;
  if (!pro.Ok)
  {
    this->Fail(pro.Error);
    return false;
  }
  const std::vector<Column>& columns = pro.Columns;
  const std::vector<std::string>& extras = pro.Extras;
  const std::string& layout = pro.Layout;
  const int ncols = static_cast<int>(columns.size());
  const char* const firstData = data + pro.FirstData;
  const vtkIdType firstDataLine = static_cast<vtkIdType>(pro.FirstDataLine);

  // Chunks start at line starts; each is about 1 MB, at least 8 per thread
  // so that threads that finish early pick up more.
  int threads = this->NumberOfThreads > 0 ? this->NumberOfThreads
                                          : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::max(1, threads);
  const size_t dataBytes = static_cast<size_t>(end - firstData);
  size_t chunkBytes = std::max<size_t>(1 << 20, dataBytes / (static_cast<size_t>(threads) * 8) + 1);
  // Chunk boundaries: the first newline at or after each chunk's nominal
  // end, looked for one chunk length at a time so that a file with few or no
  // newlines (binary data, a huge sparse file) is still walked with progress
  // and can be aborted.
  std::vector<const char*> starts{ firstData };
  std::atomic<bool> aborted{ false };
  for (const char* s = firstData + chunkBytes; s < end;)
  {
    const char* lim = s + std::min<size_t>(chunkBytes, static_cast<size_t>(end - s));
    const char* nl = static_cast<const char*>(std::memchr(s, '\n', lim - s));
    if (nl)
    {
      if (nl + 1 >= end)
      {
        break;
      }
      starts.push_back(nl + 1);
      s = nl + 1 + chunkBytes;
    }
    else
    {
      s = lim;
    }
    this->UpdateProgress(0.05 * static_cast<double>(s - data) / static_cast<double>(size));
    if (this->GetAbortExecute())
    {
      aborted = true;
      break;
    }
  }
  const int nchunks = static_cast<int>(starts.size());
  starts.push_back(end);
  std::vector<ChunkResult> results(nchunks);
  // Progress of a pass over the chunks, mapped onto [from, to]; an abort
  // asked for through VTK stops the chunks still to come.
  auto passProgress = [&](double from, double to) {
    return [this, &aborted, from, to, nchunks](int done) {
      this->UpdateProgress(from + (to - from) * done / nchunks);
      if (this->GetAbortExecute())
      {
        aborted = true;
      }
    };
  };
  // After a pass: false, with the reader's error, when it was aborted.
  auto notAborted = [&]() {
    if (aborted)
    {
      this->Fail(file + ": reading was aborted");
      return false;
    }
    return true;
  };

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
        if (aborted)
        {
          return;
        }
        // Whether the line holds data is decided by its first non-blank
        // byte; its end is then looked for at most 16 MB at a time, so that
        // an abort is seen soon even in a line of gigabytes.
        ++r.Lines;
        const char* q = s;
        while (q < ce && *q != '\n' && IsBlank(*q))
        {
          ++q;
        }
        if (q < ce && *q != '\n' && *q != '#')
        {
          ++r.DataLines;
        }
        const char* nl = nullptr;
        while (q < ce && !aborted)
        {
          const size_t look = std::min<size_t>(static_cast<size_t>(ce - q), size_t(1) << 24);
          nl = static_cast<const char*>(std::memchr(q, '\n', look));
          if (nl)
          {
            break;
          }
          q += look;
        }
        s = nl ? nl + 1 : ce;
      }
    },
    passProgress(0.05, 0.1));
  if (!notAborted())
  {
    return false;
  }
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
  // A file of billions of short lines can ask for more memory than there
  // is: say so instead of writing through a null pointer.
  bool allocated = pointsArray->GetNumberOfTuples() == total &&
    (!colors || colors->GetNumberOfTuples() == total);
  for (RealArray* a : { refl.Get(), refr.Get(), scalars.Get() })
  {
    allocated = allocated && (!a || a->GetNumberOfTuples() == total);
  }
  for (auto& a : extraArrays)
  {
    allocated = allocated && a->GetNumberOfTuples() == total;
  }
  if (!allocated)
  {
    this->Fail(file + ": cannot allocate memory for " + std::to_string(total) + " particles of " +
      std::to_string(ncols) + " columns (" +
      std::to_string(static_cast<double>(total) * ncols * sizeof(Real) / (1 << 20)) + " MiB)");
    return false;
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
  std::atomic<bool> changedBetweenPasses{ false };
  ParallelChunks(
    nchunks, threads,
    [&](int c) {
      ChunkResult& r = results[c];
      const char* s = starts[c];
      const char* ce = starts[c + 1];
      vtkIdType ln = r.FirstLine - 1;
      vtkIdType pt = r.FirstPoint;
      // Pass 1 counted this chunk's data lines; a file written to between
      // the passes can hold more or fewer now, and the chunk must not write
      // into its neighbour's points (or past the arrays).
      const vtkIdType ptEnd = r.FirstPoint + r.DataLines;
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
        if (pt >= ptEnd)
        {
          changedBetweenPasses = true;
          return;
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
      if (pt != ptEnd)
      {
        changedBetweenPasses = true;
      }
    },
    passProgress(0.1, 0.95));
  if (!notAborted())
  {
    return false;
  }
  if (changedBetweenPasses)
  {
    this->Fail(file +
      ": the file changed while it was being read; nothing was read (read it again)");
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
