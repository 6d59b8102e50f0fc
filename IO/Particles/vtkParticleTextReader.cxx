#include "vtkParticleTextReader.h"

#include "octorayParticleTextParser.h"

#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"
#include "vtk_zlib.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <string>
#include <thread>

#include <sys/stat.h>
#include <unistd.h>

vtkStandardNewMacro(vtkParticleTextReader);

//------------------------------------------------------------------------------
vtkParticleTextReader::vtkParticleTextReader() = default;

//------------------------------------------------------------------------------
vtkParticleTextReader::~vtkParticleTextReader() = default;

//------------------------------------------------------------------------------
int vtkParticleTextReader::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  this->ColumnNames.clear();
  this->NumberOfSkippedLines = 0;
  return this->Superclass::RequestData(request, inputVector, outputVector);
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
bool vtkParticleTextReader::ReadPoints(const char* data, size_t size, vtkPolyData* output)
{
  return this->OutputPointsPrecision == DOUBLE_PRECISION
    ? this->Parse<double>(data, size, output)
    : this->Parse<float>(data, size, output);
}

//------------------------------------------------------------------------------
template <typename Real>
bool vtkParticleTextReader::Parse(const char* data, size_t size, vtkPolyData* output)
{
  using namespace octoray::ptext;
  ParseSettings settings;
  settings.File = this->FileName;
  const int threads = this->NumberOfThreads > 0
    ? this->NumberOfThreads
    : static_cast<int>(std::thread::hardware_concurrency());
  settings.Threads = std::max(1, threads);
  settings.Lenient = this->Lenient;
  settings.ReportedLines = static_cast<size_t>(this->MaximumReportedLines);
  settings.Progress = [this](double progress) { return this->ContinueReading(progress); };

  ParticleTextParser<Real> parser(settings);
  const Outcome outcome = parser.Parse(data, size, output);
  const ParseReport& report = parser.Report();
  this->ColumnNames = report.Layout;
  if (report.Skipped)
  {
    this->NumberOfSkippedLines = report.Skipped;
    this->ErrorMessage = report.FirstProblem;
    vtkWarningMacro(<< report.Warning);
  }
  switch (outcome)
  {
    case Outcome::Read:
      return true;
    case Outcome::Aborted:
      this->FailAborted();
      return false;
    case Outcome::Changed:
      this->FailChanged();
      return false;
    default:
      this->Fail(report.Error);
      return false;
  }
}

//------------------------------------------------------------------------------
void vtkParticleTextReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Lenient: " << this->Lenient << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "MaximumReportedLines: " << this->MaximumReportedLines << "\n";
  os << indent << "NumberOfSkippedLines: " << this->NumberOfSkippedLines << "\n";
  os << indent << "ColumnNames: " << this->ColumnNames << "\n";
}
