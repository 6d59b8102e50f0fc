#include "vtkParticleTextReader.h"

#include "octorayParticleTextParser.h"

#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <thread>

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
