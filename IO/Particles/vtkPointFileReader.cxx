#include "vtkPointFileReader.h"

#include "octorayTextSource.h"

#include "vtkCellArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <new>

//------------------------------------------------------------------------------
vtkPointFileReader::vtkPointFileReader() = default;

//------------------------------------------------------------------------------
vtkPointFileReader::~vtkPointFileReader() = default;

//------------------------------------------------------------------------------
void vtkPointFileReader::Fail(const std::string& message)
{
  this->ErrorMessage = message;
  vtkErrorMacro(<< message);
}

//------------------------------------------------------------------------------
void vtkPointFileReader::FailAborted()
{
  this->Fail(std::string(this->FileName) + ": reading was aborted");
}

//------------------------------------------------------------------------------
void vtkPointFileReader::FailChanged()
{
  this->Fail(std::string(this->FileName) +
    ": the file changed while it was being read; nothing was read (read it again)");
}

//------------------------------------------------------------------------------
bool vtkPointFileReader::ContinueReading(double progress)
{
  this->UpdateProgress(progress);
  return !this->GetAbortExecute();
}

//------------------------------------------------------------------------------
int vtkPointFileReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  this->ErrorMessage.clear();
  vtkSmartPointer<vtkPolyData> fresh = this->ReadFile();
  if (!fresh)
  {
    // A failed update leaves the output of the last successful one (or an
    // empty one) in place, never a half-read file: the pipeline has already
    // emptied the output, so the kept copy is put back.
    if (this->LastOutput)
    {
      output->ShallowCopy(this->LastOutput);
    }
    else
    {
      output->Initialize();
    }
    return 0;
  }
  output->ShallowCopy(fresh);
  this->LastOutput = fresh;
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
// The file read into a new polydata, or null after Fail().
vtkSmartPointer<vtkPolyData> vtkPointFileReader::ReadFile()
{
  if (!this->FileName || !*this->FileName)
  {
    this->Fail("no file name was set");
    return nullptr;
  }
  octoray::TextSource source;
  std::string error;
  if (!source.Open(this->FileName, error))
  {
    this->Fail(error);
    return nullptr;
  }
  this->UpdateProgress(0.0);
  auto fresh = vtkSmartPointer<vtkPolyData>::New();
  bool ok = false;
  try
  {
    ok = this->ReadPoints(source.Data(), source.Size(), fresh);
    if (ok && this->GenerateVertices)
    {
      fresh->SetVerts(MakeVertices(fresh->GetNumberOfPoints()));
    }
  }
  catch (const std::bad_alloc&)
  {
    this->Fail(std::string(this->FileName) + ": out of memory while reading " +
      std::to_string(source.Size()) + " bytes");
    ok = false;
  }
  // Truncated while mapped: the read went on over zeros (and may have failed
  // on them, reported just before); what it found is not the file.
  if (source.Truncated())
  {
    this->Fail(source.TruncationMessage(this->FileName));
    ok = false;
  }
  else if (ok && source.ChangedSinceOpen())
  {
    this->FailChanged();
    ok = false;
  }
  return ok ? fresh : nullptr;
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkCellArray> vtkPointFileReader::MakeVertices(vtkIdType n)
{
  auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
  offsets->SetNumberOfTuples(n + 1);
  auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
  conn->SetNumberOfTuples(n);
  vtkIdType* o = offsets->GetPointer(0);
  vtkIdType* c = conn->GetPointer(0);
  for (vtkIdType i = 0; i < n; ++i)
  {
    o[i] = i;
    c[i] = i;
  }
  o[n] = n;
  auto verts = vtkSmartPointer<vtkCellArray>::New();
  verts->SetData(offsets, conn);
  return verts;
}

//------------------------------------------------------------------------------
vtkMTimeType vtkPointFileReader::GetMTime()
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
void vtkPointFileReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "OutputPointsPrecision: " << this->OutputPointsPrecision << "\n";
  os << indent << "GenerateVertices: " << this->GenerateVertices << "\n";
}
