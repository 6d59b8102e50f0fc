// The parse of a particle text file into vtkPolyData, for
// vtkParticleTextReader: the serial prologue (header, layout), chunk
// boundaries, pass 1 (lines and data lines per chunk), the output arrays,
// pass 2 (each line parsed, checked and stored, in parallel), the strict or
// lenient outcome, and the polydata filled. The format itself (tokens,
// numbers, layouts) is octorayParticleTextFormat.h. Private to the module;
// not wrapped.
//
// Two passes, so that the arrays are allocated once at their final size and
// each chunk writes its own part of them: pass 1 counts the lines of every
// chunk (for line numbers and where each chunk's points go), pass 2 parses.
#ifndef octorayParticleTextParser_h
#define octorayParticleTextParser_h

#include "octorayParallelChunks.h"
#include "octorayParticleArrays.h"
#include "octorayParticleTextFormat.h"

#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace octoray
{
namespace ptext
{
// What the reader asks of a parse.
struct ParseSettings
{
  std::string File;
  int Threads = 1; // parsing threads, at least 1
  bool Lenient = false;
  size_t ReportedLines = 10; // line numbers of skipped lines kept
  // Reports progress in [0, 1]; false when the read is to stop. Called from
  // the calling thread only.
  std::function<bool(double)> Progress;
};

enum class Outcome
{
  Read,
  Failed,  // Report().Error says why
  Aborted, // stopped through Progress
  Changed  // the file changed between the two passes
};

// What a parse found besides the polydata.
struct ParseReport
{
  std::string Layout; // the column names, space separated
  std::string Error;  // why the parse failed (Outcome::Failed)
  // Lenient mode: lines skipped, the first one's message, and the warning
  // that says how many and where.
  vtkIdType Skipped = 0;
  std::string FirstProblem;
  std::string Warning;
};

template <typename Real>
class ParticleTextParser
{
public:
  explicit ParticleTextParser(const ParseSettings& settings)
    : Settings(settings)
  {
  }

  Outcome Parse(const char* data, size_t size, vtkPolyData* output)
  {
    this->Data = data;
    this->End = data + size;
    if (!this->ReadPrologue())
    {
      return Outcome::Failed;
    }
    this->FindChunks();
    this->CountLines();
    if (this->Aborted)
    {
      return Outcome::Aborted;
    }
    if (!this->MakeArrays())
    {
      return Outcome::Failed;
    }
    this->ParseLines();
    if (this->Aborted)
    {
      return Outcome::Aborted;
    }
    if (this->ChangedBetweenPasses)
    {
      return Outcome::Changed;
    }
    if (!this->Conclude())
    {
      return Outcome::Failed;
    }
    this->Fill(output);
    return Outcome::Read;
  }

  const ParseReport& Report() const { return this->Result; }

private:
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

  // A bad line: where in it (for the column number) and what is wrong.
  // ---- Serial prologue: comments, the optional header, and the first data
  // line, whose column count gives the layout when there is no header.
  bool ReadPrologue()
  {
    this->Pro = ParsePrologue(this->Data, static_cast<size_t>(this->End - this->Data),
      this->Settings.File);
    this->Result.Layout = this->Pro.Layout;
    if (!this->Pro.Ok)
    {
      this->Result.Error = this->Pro.Error;
      return false;
    }
    this->NumberOfColumns = static_cast<int>(this->Pro.Columns.size());
    return true;
  }

  // ---- Chunks start at line starts; each is about 1 MB, at least 8 per
  // thread so that threads that finish early pick up more. A boundary is the
  // first newline at or after a chunk's nominal end, looked for one chunk
  // length at a time so that a file with few or no newlines (binary data, a
  // huge sparse file) is still walked with progress and can be aborted.
  void FindChunks()
  {
    const char* const firstData = this->Data + this->Pro.FirstData;
    const size_t size = static_cast<size_t>(this->End - this->Data);
    const size_t dataBytes = static_cast<size_t>(this->End - firstData);
    const size_t chunkBytes = std::max<size_t>(
      1 << 20, dataBytes / (static_cast<size_t>(this->Settings.Threads) * 8) + 1);
    this->Starts.assign(1, firstData);
    for (const char* s = firstData + chunkBytes; s < this->End;)
    {
      const char* lim = s + std::min<size_t>(chunkBytes, static_cast<size_t>(this->End - s));
      const char* nl = static_cast<const char*>(std::memchr(s, '\n', lim - s));
      if (nl)
      {
        if (nl + 1 >= this->End)
        {
          break;
        }
        this->Starts.push_back(nl + 1);
        s = nl + 1 + chunkBytes;
      }
      else
      {
        s = lim;
      }
      if (!this->Settings.Progress(
            0.05 * static_cast<double>(s - this->Data) / static_cast<double>(size)))
      {
        this->Aborted = true;
        break;
      }
    }
    this->NumberOfChunks = static_cast<int>(this->Starts.size());
    this->Starts.push_back(this->End);
    this->Results.assign(this->NumberOfChunks, ChunkResult());
  }

  // Progress of a pass over the chunks, mapped onto [from, to]; a stop asked
  // for through it stops the chunks still to come.
  std::function<void(int)> PassProgress(double from, double to)
  {
    return [this, from, to](int done) {
      if (!this->Settings.Progress(from + (to - from) * done / this->NumberOfChunks))
      {
        this->Aborted = true;
      }
    };
  }

  // ---- Pass 1: lines and data lines per chunk, for line numbers and the
  // place of each chunk's points in the output arrays.
  void CountLines()
  {
    ParallelChunks(this->NumberOfChunks, this->Settings.Threads,
      [this](int c) { this->CountChunk(c); }, this->PassProgress(0.05, 0.1));
    if (this->Aborted)
    {
      return;
    }
    vtkIdType line = static_cast<vtkIdType>(this->Pro.FirstDataLine);
    for (auto& r : this->Results)
    {
      r.FirstPoint = this->Total;
      r.FirstLine = line;
      this->Total += r.DataLines;
      line += r.Lines;
    }
  }

  void CountChunk(int c)
  {
    ChunkResult& r = this->Results[c];
    const char* s = this->Starts[c];
    const char* const ce = this->Starts[c + 1];
    while (s < ce)
    {
      if (this->Aborted)
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
      while (q < ce && !this->Aborted)
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
  }

  // ---- The output arrays, filled in place by pass 2.
  bool MakeArrays()
  {
    if (!this->Arrays.Allocate(this->Pro.Columns, this->Pro.Extras, this->Total))
    {
      const int ncols = this->NumberOfColumns;
      this->Result.Error = this->Settings.File + ": cannot allocate memory for " +
        std::to_string(this->Total) + " particles of " + std::to_string(ncols) + " columns (" +
        std::to_string(static_cast<double>(this->Total) * ncols * sizeof(Real) / (1 << 20)) +
        " MiB)";
      return false;
    }
    if (this->Settings.Lenient)
    {
      this->Valid.assign(static_cast<size_t>(this->Total), 1);
    }
    return true;
  }

  // ---- Pass 2: parse. In strict mode a chunk stops at its first bad line,
  // and chunks after a chunk that already failed stop early, so the error
  // that is reported is the one with the lowest line number.
  void ParseLines()
  {
    ParallelChunks(this->NumberOfChunks, this->Settings.Threads,
      [this](int c) { this->ParseChunk(c); }, this->PassProgress(0.1, 0.95));
  }

  void ParseChunk(int c)
  {
    ChunkResult& r = this->Results[c];
    const char* s = this->Starts[c];
    const char* const ce = this->Starts[c + 1];
    const bool lenient = this->Settings.Lenient;
    vtkIdType ln = r.FirstLine; // the number of the line at s
    vtkIdType pt = r.FirstPoint;
    // Pass 1 counted this chunk's data lines; a file written to between
    // the passes can hold more or fewer now, and the chunk must not write
    // into its neighbour's points (or past the arrays).
    const vtkIdType ptEnd = r.FirstPoint + r.DataLines;
    std::vector<Real> values(this->NumberOfColumns);
    Problem problem;
    bool walked = true; // every line of the chunk, not stopped
    ForEachDataLine(s, ce, ln, [&](const char* lineStart, const char* q, const char* e) {
      if (!lenient &&
        (this->FirstFailedChunk.load(std::memory_order_relaxed) < c || this->Aborted))
      {
        return walked = false;
      }
      if (pt >= ptEnd)
      {
        this->ChangedBetweenPasses = true;
        return walked = false;
      }
      if (ParseFields(this->Pro, lineStart, q, e, values.data(), problem))
      {
        this->Arrays.Store(values.data(), pt);
      }
      else
      {
        this->RecordBad(r, ln, pt, lineStart, problem);
        if (!lenient)
        {
          int expected = this->FirstFailedChunk.load();
          while (c < expected && !this->FirstFailedChunk.compare_exchange_weak(expected, c))
          {
          }
          return walked = false;
        }
      }
      ++pt;
      return true;
    });
    if (walked && pt != ptEnd)
    {
      this->ChangedBetweenPasses = true;
    }
  }

  void RecordBad(ChunkResult& r, vtkIdType ln, vtkIdType pt, const char* lineStart,
    const Problem& problem)
  {
    ++r.Bad;
    if (r.BadLines.size() < std::max<size_t>(this->Settings.ReportedLines, 1))
    {
      r.BadLines.push_back(ln);
    }
    if (r.FirstMessage.empty())
    {
      r.FirstMessage = LineMessage(this->Settings.File, ln, lineStart, problem);
    }
    if (this->Settings.Lenient)
    {
      this->Valid[pt] = 0;
    }
  }

  // ---- The outcome: strict, the first bad line is the error; lenient, the
  // bad lines are left out and reported.
  bool Conclude()
  {
    for (const auto& r : this->Results)
    {
      this->Bad += r.Bad;
      if (this->FirstMessage.empty() && !r.FirstMessage.empty())
      {
        this->FirstMessage = r.FirstMessage;
      }
      for (vtkIdType l : r.BadLines)
      {
        if (this->BadLines.size() < this->Settings.ReportedLines)
        {
          this->BadLines.push_back(l);
        }
      }
    }
    if (this->Bad && !this->Settings.Lenient)
    {
      this->Result.Error = this->FirstMessage;
      return false;
    }
    this->Kept = this->Total;
    if (this->Bad)
    {
      this->Kept = this->Arrays.Compact(this->Valid);
      this->Result.Skipped = this->Bad;
      this->Result.FirstProblem = this->FirstMessage;
      std::ostringstream warning;
      warning << this->Settings.File << ": skipped " << this->Bad << " bad line(s) of "
              << this->Total << " (lenient mode); first at line(s) ";
      for (size_t i = 0; i < this->BadLines.size(); ++i)
      {
        warning << (i ? ", " : "") << this->BadLines[i];
      }
      warning << (static_cast<vtkIdType>(this->BadLines.size()) < this->Bad ? ", ..." : "")
              << "; first problem: " << this->FirstMessage;
      this->Result.Warning = warning.str();
    }
    if (this->Kept == 0)
    {
      this->Result.Error = this->Settings.File +
        ": every particle line was bad; nothing was read. First problem: " + this->FirstMessage;
      return false;
    }
    return true;
  }

  // ---- The polydata: points and point data; in lenient mode the record of
  // what was skipped too, so a pipeline downstream (or a saved file) still
  // says so.
  void Fill(vtkPolyData* output) const
  {
    this->Arrays.Fill(output);
    if (this->Settings.Lenient)
    {
      auto count = vtkSmartPointer<vtkIdTypeArray>::New();
      count->SetName("SkippedLineCount");
      count->InsertNextValue(this->Bad);
      auto numbers = vtkSmartPointer<vtkIdTypeArray>::New();
      numbers->SetName("SkippedLineNumbers");
      for (vtkIdType l : this->BadLines)
      {
        numbers->InsertNextValue(l);
      }
      output->GetFieldData()->AddArray(count);
      output->GetFieldData()->AddArray(numbers);
    }
  }

  const ParseSettings& Settings;
  ParseReport Result;
  const char* Data = nullptr;
  const char* End = nullptr;
  Prologue Pro;
  int NumberOfColumns = 0;

  // Chunks: their starts (and the end), what each pass found in each.
  std::vector<const char*> Starts;
  int NumberOfChunks = 0;
  std::vector<ChunkResult> Results;
  vtkIdType Total = 0; // data lines of every chunk: the points, bad lines included
  std::atomic<bool> Aborted{ false };
  std::atomic<int> FirstFailedChunk{ std::numeric_limits<int>::max() };
  std::atomic<bool> ChangedBetweenPasses{ false };

  ParticleArrays<Real> Arrays;
  std::vector<unsigned char> Valid; // lenient: 0 for the points of bad lines

  // The outcome.
  vtkIdType Bad = 0;
  std::vector<vtkIdType> BadLines; // the first ReportedLines
  std::string FirstMessage;
  vtkIdType Kept = 0;
};

} // namespace ptext
} // namespace octoray

#endif
