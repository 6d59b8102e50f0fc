#include "octoraySliceDicom.h"

#include "octorayDicomCheck.h"
#include "octoraySliceChecks.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkPointData.h"

#include <gdcmImage.h>
#include <gdcmImageHelper.h>
#include <gdcmImageReader.h>
#include <gdcmReader.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>

namespace fs = std::filesystem;

namespace octoray
{
namespace slices
{
namespace
{
// Before GDCM sees a file: is it there, and is its structure sound? GDCM
// aborts on some damaged files (an assert()) or allocates what a damaged
// length claims, so the structure is checked first, without reading values.
bool CheckFile(const std::string& f, std::string& error)
{
  std::error_code ec;
  if (!fs::exists(f, ec))
  {
    error = "DICOM slice '" + f + "' does not exist";
    return false;
  }
  const std::string damage = octoray::CheckDicomStructure(f);
  if (!damage.empty())
  {
    error = "cannot read DICOM slice '" + f + "': " + damage;
    return false;
  }
  return true;
}

std::string NotAnImage(const std::string& f)
{
  return "cannot read DICOM slice '" + f + "': not a DICOM image GDCM can decode";
}

std::string Describe(const DicomSlice& s)
{
  return std::to_string(s.Width) + "x" + std::to_string(s.Height) + " " +
    (s.Samples == 1 ? "grey" : "RGB");
}

// Modality LUT: stored value * slope + intercept (e.g. CT numbers in HU).
bool Rescale(const gdcm::Image& img, const std::vector<char>& buffer, size_t count, DicomSlice& s,
  std::string& error)
{
  const double slope = img.GetSlope();
  const double intercept = img.GetIntercept();
  s.Values.resize(count);
  auto convert = [&](auto* src) {
    for (size_t i = 0; i < count; ++i)
    {
      s.Values[i] = static_cast<float>(src[i] * slope + intercept);
    }
  };
  switch (img.GetPixelFormat().GetScalarType())
  {
    case gdcm::PixelFormat::UINT8:
      convert(reinterpret_cast<const uint8_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::INT8:
      convert(reinterpret_cast<const int8_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::UINT16:
      convert(reinterpret_cast<const uint16_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::INT16:
      convert(reinterpret_cast<const int16_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::UINT32:
      convert(reinterpret_cast<const uint32_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::INT32:
      convert(reinterpret_cast<const int32_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::FLOAT32:
      convert(reinterpret_cast<const float*>(buffer.data()));
      break;
    case gdcm::PixelFormat::FLOAT64:
      convert(reinterpret_cast<const double*>(buffer.data()));
      break;
    default:
      error = "DICOM slice '" + s.File + "' has a pixel type that is not supported";
      return false;
  }
  return true;
}

// The pixels GDCM decodes: grey rescaled, 8-bit RGB as it is.
bool DecodePixels(const gdcm::Image& img, DicomSlice& s, std::string& error)
{
  std::vector<char> buffer(img.GetBufferLength());
  if (!img.GetBuffer(buffer.data()))
  {
    error = "cannot decode the pixels of DICOM slice '" + s.File + "'";
    return false;
  }
  const size_t count = static_cast<size_t>(s.Width) * s.Height * s.Frames;
  if (s.Samples == 3)
  {
    s.RGB.assign(buffer.begin(), buffer.begin() + std::min(buffer.size(), count * 3));
    return true;
  }
  return Rescale(img, buffer, count, s, error);
}

// The value of a text element without its padding; "" where it is missing.
std::string TextOf(const gdcm::DataSet& data, const gdcm::Tag& tag)
{
  if (!data.FindDataElement(tag) || !data.GetDataElement(tag).GetByteValue())
  {
    return std::string();
  }
  const gdcm::ByteValue* value = data.GetDataElement(tag).GetByteValue();
  std::string text(value->GetPointer(), value->GetLength());
  while (!text.empty() && (text.back() == '\0' || text.back() == ' '))
  {
    text.pop_back();
  }
  return text;
}

// File f as slice s of a stack of `files` files whose first slice (null
// for the first itself) it must match in size and type.
bool ReadSlice(const std::string& f, const DicomSlice* first, size_t files, DicomSlice& s,
  std::string& error)
{
  if (!CheckFile(f, error))
  {
    return false;
  }
  gdcm::ImageReader reader;
  reader.SetFileName(f.c_str());
  if (!reader.Read())
  {
    error = NotAnImage(f);
    return false;
  }
  const gdcm::Image& img = reader.GetImage();
  const unsigned int* dims = img.GetDimensions();
  const gdcm::PixelFormat& pf = img.GetPixelFormat();
  s.File = f;
  s.Width = dims[0];
  s.Height = dims[1];
  s.Frames = img.GetNumberOfDimensions() > 2 ? dims[2] : 1;
  s.Samples = pf.GetSamplesPerPixel();
  if (first &&
    (s.Width != first->Width || s.Height != first->Height || s.Samples != first->Samples))
  {
    error = MismatchMessage("DICOM slice", f, Describe(s), first->File, Describe(*first));
    return false;
  }
  if (s.Samples != 1 && !(s.Samples == 3 && pf.GetBitsAllocated() == 8))
  {
    error = "DICOM slice '" + f + "' has " + std::to_string(s.Samples) + " samples of " +
      std::to_string(pf.GetBitsAllocated()) + " bits; only grey or 8-bit RGB is supported";
    return false;
  }
  if (s.Frames > 1 && files > 1)
  {
    error = "DICOM slice '" + f + "' has " + std::to_string(s.Frames) +
      " frames; a series of several files must have one frame per file";
    return false;
  }
  const gdcm::DataSet& data = reader.GetFile().GetDataSet();
  s.HasOrigin = data.FindDataElement(gdcm::Tag(0x0020, 0x0032));
  s.Series = TextOf(data, gdcm::Tag(0x0020, 0x000e));
  const double* o = img.GetOrigin();
  const double* dc = img.GetDirectionCosines();
  const double* sp = img.GetSpacing();
  for (int a = 0; a < 3; ++a)
  {
    s.Origin[a] = o[a];
    s.Row[a] = dc[a];
    s.Col[a] = dc[3 + a];
    s.Spacing[a] = sp[a];
  }
  return DecodePixels(img, s, error);
}

// The ordered slices into image; with useMetadata, with their geometry.
void StackImage(const std::vector<DicomSlice>& slices, const double normal[3], double spacing,
  bool useMetadata, vtkImageData* image, SliceRead& read)
{
  const DicomSlice& s0 = slices[0];
  const int depth = static_cast<int>(slices.size() == 1 ? s0.Frames : slices.size());
  image->SetDimensions(static_cast<int>(s0.Width), static_cast<int>(s0.Height), depth);
  if (useMetadata)
  {
    image->SetSpacing(s0.Spacing[0], s0.Spacing[1], spacing);
    image->SetOrigin(s0.Origin);
    image->SetDirectionMatrix(s0.Row[0], s0.Col[0], normal[0], s0.Row[1], s0.Col[1], normal[1],
      s0.Row[2], s0.Col[2], normal[2]);
  }
  const int comps = s0.Samples;
  image->AllocateScalars(comps == 3 ? VTK_UNSIGNED_CHAR : VTK_FLOAT, comps);
  image->GetPointData()->GetScalars()->SetName("Scalars");
  const size_t sliceValues = static_cast<size_t>(s0.Width) * s0.Height * comps;
  for (size_t k = 0; k < slices.size(); ++k)
  {
    if (comps == 3)
    {
      std::copy(slices[k].RGB.begin(), slices[k].RGB.end(),
        static_cast<unsigned char*>(image->GetScalarPointer()) + k * sliceValues);
    }
    else
    {
      std::copy(slices[k].Values.begin(), slices[k].Values.end(),
        static_cast<float*>(image->GetScalarPointer()) + k * sliceValues);
    }
    read.SliceFiles.push_back(slices[k].File);
  }
}
} // namespace

//------------------------------------------------------------------------------
bool DicomStackDimensions(const std::vector<std::string>& files, int dims[3], std::string& error)
{
  const std::string& f = files.front();
  if (!CheckFile(f, error))
  {
    return false;
  }
  // The header only: reading stops before the pixel data (a damaged
  // length there must not make the metadata path read gigabytes).
  gdcm::Reader reader;
  reader.SetFileName(f.c_str());
  bool read = false;
  try
  {
    read = reader.ReadUpToTag(gdcm::Tag(0x7fe0, 0x0010));
  }
  catch (const std::exception&)
  {
    read = false;
  }
  std::vector<unsigned int> d;
  if (read)
  {
    d = gdcm::ImageHelper::GetDimensionsValue(reader.GetFile());
  }
  if (!read || d.size() < 2 || d[0] == 0 || d[1] == 0)
  {
    error = NotAnImage(f);
    return false;
  }
  dims[0] = static_cast<int>(d[0]);
  dims[1] = static_cast<int>(d[1]);
  dims[2] = files.size() > 1 || d.size() < 3 || d[2] < 1 ? static_cast<int>(files.size())
                                                         : static_cast<int>(d[2]);
  return true;
}

//------------------------------------------------------------------------------
bool ReadDicomStack(const std::vector<std::string>& files, double fallbackSliceSpacing,
  bool useMetadata, vtkImageData* image, SliceRead& read)
{
  std::vector<DicomSlice> slices;
  for (size_t n = 0; n < files.size(); ++n)
  {
    DicomSlice s;
    if (!ReadSlice(files[n], slices.empty() ? nullptr : &slices[0], files.size(), s, read.Error))
    {
      return false;
    }
    slices.push_back(std::move(s));
    read.Progress(0.7 * (n + 1) / files.size());
  }
  double normal[3], spacing;
  if (!OrderDicomSlices(slices, fallbackSliceSpacing, normal, spacing, read))
  {
    return false;
  }
  StackImage(slices, normal, spacing, useMetadata, image, read);
  read.Progress(0.8);
  return true;
}
} // namespace slices
} // namespace octoray
