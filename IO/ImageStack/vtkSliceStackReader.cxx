// The reader's own job: its properties, the pipeline passes, and what an
// update leaves behind (progress, the outputs of the last successful update
// after a failed one, a new read when a slice changes on disk). The parts
// of a read are the module's private files, one job each:
//   octoraySliceFiles      which files, in which order they are listed
//   octoraySlicePictures   picture slices through OpenImageIO
//   octoraySliceDicom      DICOM slices through GDCM, with geometry and rescale
//   octoraySliceChecks     what the slices must share; DICOM order and spacing
//   octoraySliceParticles  the particles (output 0) from the image (output 1)
#include "vtkSliceStackReader.h"

#include "octoraySliceDicom.h"
#include "octoraySliceFiles.h"
#include "octoraySliceParticles.h"
#include "octoraySlicePictures.h"

#include "vtkDemandDrivenPipeline.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include <algorithm>
#include <cstdio>

vtkStandardNewMacro(vtkSliceStackReader);

//------------------------------------------------------------------------------
vtkSliceStackReader::vtkSliceStackReader()
{
  this->SetNumberOfInputPorts(0);
  this->SetNumberOfOutputPorts(2);
}

//------------------------------------------------------------------------------
vtkSliceStackReader::~vtkSliceStackReader()
{
  this->SetDirectoryName(nullptr);
  this->SetFilePattern(nullptr);
}

//------------------------------------------------------------------------------
void vtkSliceStackReader::AddFileName(const char* name)
{
  if (name)
  {
    this->FileNames.emplace_back(name);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkSliceStackReader::ClearFileNames()
{
  if (!this->FileNames.empty())
  {
    this->FileNames.clear();
    this->Modified();
  }
}

//------------------------------------------------------------------------------
const char* vtkSliceStackReader::GetFileName(int i) const
{
  return i >= 0 && i < static_cast<int>(this->FileNames.size()) ? this->FileNames[i].c_str()
                                                                : nullptr;
}

//------------------------------------------------------------------------------
void vtkSliceStackReader::SetFileNames(vtkStringArray* names)
{
  this->FileNames.clear();
  for (vtkIdType i = 0; names && i < names->GetNumberOfValues(); ++i)
  {
    this->FileNames.push_back(names->GetValue(i));
  }
  this->Modified();
}

//------------------------------------------------------------------------------
const char* vtkSliceStackReader::GetSliceFileName(int k) const
{
  return k >= 0 && k < static_cast<int>(this->SliceFiles.size()) ? this->SliceFiles[k].c_str()
                                                                 : nullptr;
}

//------------------------------------------------------------------------------
vtkImageData* vtkSliceStackReader::GetImageOutput()
{
  return vtkImageData::SafeDownCast(this->GetOutputDataObject(1));
}

//------------------------------------------------------------------------------
int vtkSliceStackReader::FillOutputPortInformation(int port, vtkInformation* info)
{
  if (port == 1)
  {
    info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkImageData");
    return 1;
  }
  return this->Superclass::FillOutputPortInformation(port, info);
}

//------------------------------------------------------------------------------
void vtkSliceStackReader::Fail(const std::string& message)
{
  this->ErrorMessage = message;
  if (message != this->SaidError || this->GetMTime() != this->SaidErrorMTime)
  {
    this->SaidError = message;
    this->SaidErrorMTime = this->GetMTime();
    vtkErrorMacro(<< message);
  }
}

//------------------------------------------------------------------------------
bool vtkSliceStackReader::ListSlices(std::vector<std::string>& files)
{
  octoray::slices::SliceSource source;
  source.Names = &this->FileNames;
  source.Pattern = this->FilePattern;
  source.Range[0] = this->FileNameRange[0];
  source.Range[1] = this->FileNameRange[1];
  source.Directory = this->DirectoryName;
  std::string error;
  if (!octoray::slices::ListSliceFiles(source, files, error))
  {
    this->Fail(error);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
int vtkSliceStackReader::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  // The volume's extent, from the headers (first DICOM file, or every
  // picture's page count), so that pipelines downstream (and ParaView) see a
  // whole extent before any pixel is read.
  this->ErrorMessage.clear();
  vtkInformation* info = outputVector->GetInformationObject(1);
  // Where the slices cannot be listed, an empty volume: the pipeline then
  // does not add that it has no extent to the error.
  const int none[6] = { 0, -1, 0, -1, 0, -1 };
  info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), none, 6);
  std::vector<std::string> files;
  if (!this->ListSlices(files))
  {
    return 0;
  }
  int dims[3] = { 0, 0, 0 };
  std::string error;
  const bool ok = octoray::slices::IsDICOMFile(files.front())
    ? octoray::slices::DicomStackDimensions(files, dims, error)
    : octoray::slices::PictureStackDimensions(files, dims, error);
  if (!ok)
  {
    this->Fail(error);
    return 0;
  }
  const int extent[6] = { 0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1 };
  info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  info->Set(vtkDataObject::SPACING(), this->Spacing, 3);
  info->Set(vtkDataObject::ORIGIN(), this->Origin, 3);
  return 1;
}

//------------------------------------------------------------------------------
// The slices into image; false after Fail().
bool vtkSliceStackReader::ReadStack(const std::vector<std::string>& files, vtkImageData* image)
{
  octoray::slices::SliceRead read;
  read.Progress = [this](double progress) { this->UpdateProgress(progress); };
  read.Warn = [this](const std::string& warning) { vtkWarningMacro(<< warning); };
  bool ok = false;
  try
  {
    ok = this->IsDICOM
      ? octoray::slices::ReadDicomStack(files, this->Spacing[2], this->UseMetadata, image, read)
      : octoray::slices::ReadPictureStack(files, image, read);
    if (!ok)
    {
      this->Fail(read.Error);
    }
    // The spacing and origin the user set, unless the DICOM series' own
    // are used.
    else if (!this->IsDICOM || !this->UseMetadata)
    {
      image->SetSpacing(this->Spacing);
      image->SetOrigin(this->Origin);
    }
  }
  catch (const std::exception& e)
  {
    this->Fail(std::string("reading the slices failed: ") + e.what() + " (first slice '" +
      files.front() + "')");
    ok = false;
  }
  this->SliceFiles = read.SliceFiles;
  return ok;
}

//------------------------------------------------------------------------------
// What the image read from `files` depends on: the files as they are on
// disk and the geometry properties. Particle options are not part of it.
std::string vtkSliceStackReader::ImageSignature(const std::vector<std::string>& files) const
{
  char geometry[256];
  std::snprintf(geometry, sizeof(geometry), "%a %a %a %a %a %a %d", this->Spacing[0],
    this->Spacing[1], this->Spacing[2], this->Origin[0], this->Origin[1], this->Origin[2],
    this->UseMetadata ? 1 : 0);
  return octoray::slices::FilesSignature(nullptr, files, {}) + geometry;
}

//------------------------------------------------------------------------------
// The stack's volume for this update: the last one read where nothing it
// depends on has changed (its ImageSignature: only a particle option did,
// or the particles are asked for after the volume alone), else read now;
// null after Fail().
vtkSmartPointer<vtkImageData> vtkSliceStackReader::CurrentImage(
  const std::vector<std::string>& files, const std::string& signature)
{
  if (this->LastImage && signature == this->LastImageSignature)
  {
    this->SliceFiles = this->LastSliceFiles;
    return this->LastImage;
  }
  auto image = vtkSmartPointer<vtkImageData>::New();
  return this->ReadStack(files, image) ? image : nullptr;
}

//------------------------------------------------------------------------------
// The particles of the image read, as the reader's options select them
// (none without GenerateParticles); false after Fail() for options that do
// not fit the stack.
bool vtkSliceStackReader::MakeParticles(vtkImageData* image, vtkPolyData* particles)
{
  if (!this->GenerateParticles)
  {
    particles->SetPoints(vtkSmartPointer<vtkPoints>::New());
    return true;
  }
  octoray::slices::ParticleOptions options;
  std::copy_n(this->RegionOfInterest, 6, options.RegionOfInterest);
  std::copy_n(this->Stride, 3, options.Stride);
  options.FillBetweenSlices = this->FillBetweenSlices;
  std::copy_n(this->BackgroundRange, 2, options.BackgroundRange);
  options.GenerateVertices = this->GenerateVertices;
  options.GradientNormals = this->GradientNormals;
  const std::string problem = octoray::slices::ParticleOptionsProblem(image->GetDimensions(), options);
  if (!problem.empty())
  {
    this->Fail(problem);
    return false;
  }
  octoray::slices::MakeParticles(image, options, particles);
  return true;
}

//------------------------------------------------------------------------------
// Spacing and Origin no image can have: what is wrong, naming the property;
// empty when nothing is.
static std::string GeometryProblem(const double spacing[3], const double origin[3])
{
  const auto triple = [](const double v[3]) {
    std::ostringstream text;
    text << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
    return text.str();
  };
  for (int a = 0; a < 3; ++a)
  {
    if (!(std::isfinite(spacing[a]) && spacing[a] > 0.0))
    {
      return "Spacing " + triple(spacing) + ": each must be finite and above zero";
    }
    if (!std::isfinite(origin[a]))
    {
      return "Origin " + triple(origin) + ": each must be finite";
    }
  }
  return std::string();
}

//------------------------------------------------------------------------------
// A failed update puts back the outputs of the last successful one (or
// leaves them empty): the pipeline has already emptied them, and a failure
// half-way must not leave a half-read stack. Particles not asked for
// (output == null) stay as they are.
int vtkSliceStackReader::KeepLastOutputs(vtkPolyData* output, vtkImageData* image)
{
  if (output && this->LastOutput)
  {
    output->ShallowCopy(this->LastOutput);
  }
  else if (output)
  {
    output->Initialize();
  }
  if (this->LastImage)
  {
    image->ShallowCopy(this->LastImage);
    this->SliceFiles = this->LastSliceFiles;
    this->IsDICOM = this->LastIsDICOM;
  }
  else
  {
    image->Initialize();
    this->SliceFiles.clear();
    this->IsDICOM = false;
  }
  return 0;
}

//------------------------------------------------------------------------------
vtkTypeBool vtkSliceStackReader::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The particles are made only where output 0 is asked for (or no port in
  // particular is): a pipeline that draws the volume alone does not pay for
  // them. The executive then keeps output 0 as it was and re-executes when
  // it is asked for, and the volume is not read again for it
  // (CurrentImage).
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_DATA_NOT_GENERATED()))
  {
    const bool volumeAlone = request->Has(vtkExecutive::FROM_OUTPUT_PORT()) &&
      request->Get(vtkExecutive::FROM_OUTPUT_PORT()) == 1;
    if (volumeAlone)
    {
      outputVector->GetInformationObject(0)->Set(vtkDemandDrivenPipeline::DATA_NOT_GENERATED(), 1);
    }
    return 1;
  }
  return this->Superclass::ProcessRequest(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
int vtkSliceStackReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* particlesInfo = outputVector->GetInformationObject(0);
  vtkPolyData* output = particlesInfo->Get(vtkDemandDrivenPipeline::DATA_NOT_GENERATED())
    ? nullptr
    : vtkPolyData::GetData(particlesInfo);
  vtkImageData* image = vtkImageData::GetData(outputVector, 1);
  this->ErrorMessage.clear();
  this->SliceFiles.clear();
  this->IsDICOM = false;
  if (output)
  {
    output->Initialize();
  }
  image->Initialize();

  const std::string geometry = GeometryProblem(this->Spacing, this->Origin);
  if (!geometry.empty())
  {
    this->Fail(geometry);
    return this->KeepLastOutputs(output, image);
  }
  std::vector<std::string> files;
  if (!this->ListSlices(files))
  {
    return this->KeepLastOutputs(output, image);
  }
  const size_t dicom = std::count_if(files.begin(), files.end(), octoray::slices::IsDICOMFile);
  if (dicom && dicom != files.size())
  {
    this->Fail("the slices mix DICOM and other image files (e.g. '" + files.front() + "')");
    return this->KeepLastOutputs(output, image);
  }
  this->IsDICOM = dicom > 0;
  this->UpdateProgress(0.0);
  const std::string signature = this->ImageSignature(files);
  vtkSmartPointer<vtkImageData> volume = this->CurrentImage(files, signature);
  auto particles = vtkSmartPointer<vtkPolyData>::New();
  if (!volume || (output && !this->MakeParticles(volume, particles)))
  {
    return this->KeepLastOutputs(output, image);
  }
  image->ShallowCopy(volume);
  this->LastImage = volume;
  this->LastImageSignature = signature;
  // Particles not asked for: output 0 keeps those of an earlier update,
  // which the executive re-executes for when it is asked for.
  if (output)
  {
    output->ShallowCopy(particles);
    this->LastOutput = particles;
  }
  this->LastSliceFiles = this->SliceFiles;
  this->LastIsDICOM = this->IsDICOM;
  // The slices just read are part of the signature from now on; that is not
  // a change on disk.
  this->FileSignature =
    octoray::slices::FilesSignature(this->DirectoryName, this->FileNames, this->SliceFiles);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
vtkMTimeType vtkSliceStackReader::GetMTime()
{
  const vtkMTimeType own = this->Superclass::GetMTime();
  const std::string signature =
    octoray::slices::FilesSignature(this->DirectoryName, this->FileNames, this->SliceFiles);
  if (signature != this->FileSignature)
  {
    this->FileSignature = signature;
    this->FileChangeTime.Modified();
  }
  return std::max(own, this->FileChangeTime.GetMTime());
}

//------------------------------------------------------------------------------
void vtkSliceStackReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileNames: " << this->FileNames.size() << "\n";
  os << indent << "DirectoryName: " << (this->DirectoryName ? this->DirectoryName : "(none)")
     << "\n";
  os << indent << "FilePattern: " << (this->FilePattern ? this->FilePattern : "(none)") << "\n";
  os << indent << "FileNameRange: " << this->FileNameRange[0] << " " << this->FileNameRange[1]
     << "\n";
  os << indent << "Spacing: " << this->Spacing[0] << " " << this->Spacing[1] << " "
     << this->Spacing[2] << "\n";
  os << indent << "Origin: " << this->Origin[0] << " " << this->Origin[1] << " "
     << this->Origin[2] << "\n";
  os << indent << "UseMetadata: " << this->UseMetadata << "\n";
  os << indent << "BackgroundRange: " << this->BackgroundRange[0] << " "
     << this->BackgroundRange[1] << "\n";
  os << indent << "RegionOfInterest:";
  for (int v : this->RegionOfInterest)
  {
    os << " " << v;
  }
  os << "\n" << indent << "Stride: " << this->Stride[0] << " " << this->Stride[1] << " "
     << this->Stride[2] << "\n";
  os << indent << "GenerateVertices: " << this->GenerateVertices << "\n";
  os << indent << "FillBetweenSlices: " << this->FillBetweenSlices << "\n";
  os << indent << "GradientNormals: " << this->GradientNormals << "\n";
  os << indent << "GenerateParticles: " << this->GenerateParticles << "\n";
  os << indent << "IsDICOM: " << this->IsDICOM << "\n";
}
