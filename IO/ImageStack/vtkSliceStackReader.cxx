#include "vtkSliceStackReader.h"

#include "octorayDicomCheck.h"
#include "octorayNaturalSort.h"

#include <octorayLattice.h>

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMatrix3x3.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"

// GDCM before OpenImageIO: OIIO's headers leave <byteswap.h> half-seen for
// GDCM's byte swapper.
#include <gdcmImage.h>
#include <gdcmImageHelper.h>
#include <gdcmReader.h>
#include <gdcmImageReader.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <sstream>

#include <sys/stat.h>

vtkStandardNewMacro(vtkSliceStackReader);

namespace
{
namespace fs = std::filesystem;

std::string Lower(std::string s)
{
  for (char& c : s)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return s;
}

// DICOM Part 10 files carry "DICM" after a 128-byte preamble.
bool HasDICMMarker(const std::string& name)
{
  std::ifstream f(name, std::ios::binary);
  char buf[132];
  if (!f.read(buf, sizeof(buf)))
  {
    return false;
  }
  return std::memcmp(buf + 128, "DICM", 4) == 0;
}

bool IsDICOMFile(const std::string& name)
{
  return Lower(fs::path(name).extension().string()) == ".dcm" || HasDICMMarker(name);
}

bool IsPictureExtension(const std::string& name)
{
  static const char* known[] = { ".png", ".tif", ".tiff", ".jpg", ".jpeg", ".bmp", ".exr",
    ".pgm", ".ppm", ".pnm", ".tga", ".hdr", ".gif", ".webp", ".jp2", ".sgi", ".rgb" };
  const std::string ext = Lower(fs::path(name).extension().string());
  return std::find(std::begin(known), std::end(known), ext) != std::end(known);
}

const char* TypeName(int vtkType)
{
  switch (vtkType)
  {
    case VTK_UNSIGNED_CHAR:
      return "uint8";
    case VTK_UNSIGNED_SHORT:
      return "uint16";
    case VTK_SHORT:
      return "int16";
    default:
      return "float";
  }
}

const char* ChannelName(int c)
{
  switch (c)
  {
    case 1:
      return "grey";
    case 2:
      return "grey+alpha";
    case 3:
      return "RGB";
    default:
      return "RGBA";
  }
}

std::string Describe(int w, int h, int c, int t)
{
  return std::to_string(w) + "x" + std::to_string(h) + " " + ChannelName(c) + " " + TypeName(t);
}

// Colour channel to 8 bits, by the type's full range (floats: 0..1).
template <typename T>
inline unsigned char ToByte(T v)
{
  if constexpr (std::is_same<T, unsigned char>::value)
  {
    return v;
  }
  else if constexpr (std::is_same<T, unsigned short>::value)
  {
    return static_cast<unsigned char>((static_cast<unsigned>(v) + 128) / 257);
  }
  else if constexpr (std::is_same<T, short>::value)
  {
    return static_cast<unsigned char>(std::clamp((static_cast<int>(v) + 128) / 257, 0, 255));
  }
  else
  {
    return static_cast<unsigned char>(std::lround(std::clamp(static_cast<double>(v), 0.0, 1.0) * 255));
  }
}

// An interpolated colour channel to 8 bits: rounded to the channel's own
// type first, so a sample on a slice gives exactly the slice's byte.
template <typename T>
inline unsigned char InterpolatedToByte(double v)
{
  if constexpr (std::is_integral<T>::value)
  {
    const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
    const double hi = static_cast<double>(std::numeric_limits<T>::max());
    return ToByte(static_cast<T>(std::lround(std::clamp(v, lo, hi))));
  }
  else
  {
    return ToByte(static_cast<T>(v));
  }
}

// The particles of the selected samples (octorayLattice.h: the selected
// pixels and, with filling, the planes interpolated between slices), in
// two passes over the planes: count the particles of each plane, then fill
// them at their offsets, so the output keeps plane order and needs no locks.
template <typename T>
void Extract(const T* data, int comps, const octoray::lattice::Axis axes[3], const long long dims[3],
  const double bg[2], const octoray::lattice::Lattice& lattice, vtkPolyData* output, bool vertices)
{
  const vtkIdType nk = static_cast<vtkIdType>(axes[2].Samples());
  // Grey, or the mean of R, G, B; background by intensity range or alpha 0
  // (an interpolated alpha is 0 only between two transparent pixels).
  auto intensity = [&](const double* px) -> double {
    if (comps >= 3)
    {
      return (px[0] + px[1] + px[2]) / 3.0;
    }
    return px[0];
  };
  auto isParticle = [&](const double* px) -> bool {
    if ((comps == 2 && px[1] == 0) || (comps == 4 && px[3] == 0))
    {
      return false;
    }
    const double v = intensity(px);
    return !(v >= bg[0] && v <= bg[1]);
  };
  std::vector<vtkIdType> counts(nk + 1, 0);
  vtkSMPTools::For(0, nk, [&](vtkIdType b, vtkIdType e) {
    double values[4];
    for (vtkIdType s = b; s < e; ++s)
    {
      vtkIdType n = 0;
      octoray::lattice::ForEachSampleInPlane(axes, data, dims, comps, s, values,
        [&](long long, long long, const double* px) { n += isParticle(px); });
      counts[s + 1] = n;
    }
  });
  std::partial_sum(counts.begin(), counts.end(), counts.begin());
  const vtkIdType total = counts[nk];

  auto pts = vtkSmartPointer<vtkFloatArray>::New();
  pts->SetNumberOfComponents(3);
  pts->SetNumberOfTuples(total);
  auto scalars = vtkSmartPointer<vtkFloatArray>::New();
  scalars->SetName("Scalars");
  scalars->SetNumberOfTuples(total);
  vtkSmartPointer<vtkUnsignedCharArray> colors;
  if (comps >= 3)
  {
    colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
    colors->SetName("Colors");
    colors->SetNumberOfComponents(3);
    colors->SetNumberOfTuples(total);
  }
  float* p = pts->GetPointer(0);
  float* sc = scalars->GetPointer(0);
  unsigned char* co = colors ? colors->GetPointer(0) : nullptr;
  vtkSMPTools::For(0, nk, [&](vtkIdType b, vtkIdType e) {
    double values[4];
    for (vtkIdType s = b; s < e; ++s)
    {
      vtkIdType n = counts[s];
      octoray::lattice::ForEachSampleInPlane(axes, data, dims, comps, s, values,
        [&](long long r0, long long r1, const double* px) {
          if (!isParticle(px))
          {
            return;
          }
          double xyz[3];
          lattice.Position(r0, r1, s, xyz);
          for (int a = 0; a < 3; ++a)
          {
            p[3 * n + a] = static_cast<float>(xyz[a]);
          }
          sc[n] = static_cast<float>(intensity(px));
          if (co)
          {
            for (int c = 0; c < 3; ++c)
            {
              co[3 * n + c] = InterpolatedToByte<T>(px[c]);
            }
          }
          ++n;
        });
    }
  });
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetData(pts);
  output->SetPoints(points);
  output->GetPointData()->AddArray(scalars);
  if (colors)
  {
    output->GetPointData()->SetScalars(colors);
  }
  else
  {
    output->GetPointData()->SetScalars(scalars);
  }
  if (vertices)
  {
    auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
    offsets->SetNumberOfTuples(total + 1);
    auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
    conn->SetNumberOfTuples(total);
    std::iota(offsets->GetPointer(0), offsets->GetPointer(0) + total + 1, 0);
    std::iota(conn->GetPointer(0), conn->GetPointer(0) + total, 0);
    auto verts = vtkSmartPointer<vtkCellArray>::New();
    verts->SetData(offsets, conn);
    output->SetVerts(verts);
  }
}

// Names, inodes, sizes and modification times of the inputs: a change on
// disk changes the reader's MTime, so the next Update() reads again.
std::string FilesSignature(const char* directory, const std::vector<std::string>& names,
  const std::vector<std::string>& slices)
{
  std::string signature;
  auto add = [&](const std::string& name) {
    struct stat st;
    if (::stat(name.c_str(), &st) == 0)
    {
      signature += name + ":" + std::to_string(st.st_ino) + ":" + std::to_string(st.st_size) +
        ":" + std::to_string(st.st_mtim.tv_sec) + "." + std::to_string(st.st_mtim.tv_nsec) + ";";
    }
    else
    {
      signature += name + ":-;";
    }
  };
  if (directory && *directory)
  {
    add(directory);
  }
  for (const auto& f : names)
  {
    add(f);
  }
  for (const auto& f : slices)
  {
    add(f.substr(0, f.rfind('#') == std::string::npos ? f.size() : f.rfind('#')));
  }
  return signature;
}
} // namespace

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
  vtkErrorMacro(<< message);
}

//------------------------------------------------------------------------------
bool vtkSliceStackReader::CollectFiles(std::vector<std::string>& files)
{
  files.clear();
  if (!this->FileNames.empty())
  {
    files = this->FileNames;
    return true;
  }
  if (this->FilePattern && *this->FilePattern)
  {
    const int first = this->FileNameRange[0];
    const int last = this->FileNameRange[1];
    std::vector<std::string> missing;
    for (int n = first; n <= last; ++n)
    {
      char buf[4096];
      std::snprintf(buf, sizeof(buf), this->FilePattern, n);
      std::error_code ec;
      (fs::is_regular_file(buf, ec) ? files : missing).emplace_back(buf);
    }
    if (files.empty())
    {
      this->Fail(std::string("the file pattern '") + this->FilePattern + "' with numbers " +
        std::to_string(first) + " to " + std::to_string(last) + " matches no file");
      return false;
    }
    if (!missing.empty())
    {
      this->Fail("slice file '" + missing.front() + "' is missing (file pattern '" +
        this->FilePattern + "', numbers " + std::to_string(first) + " to " +
        std::to_string(last) + "; " + std::to_string(missing.size()) + " missing)");
      return false;
    }
    return true;
  }
  if (this->DirectoryName && *this->DirectoryName)
  {
    std::error_code ec;
    if (!fs::is_directory(this->DirectoryName, ec))
    {
      this->Fail(std::string("'") + this->DirectoryName + "' is not a directory");
      return false;
    }
    for (const auto& entry : fs::directory_iterator(this->DirectoryName, ec))
    {
      const std::string name = entry.path().filename().string();
      // DICOMDIR is an index of a DICOM media, not a slice.
      if (!entry.is_regular_file() || name.empty() || name[0] == '.' || name == "DICOMDIR")
      {
        continue;
      }
      const std::string path = entry.path().string();
      if (IsPictureExtension(path) || IsDICOMFile(path))
      {
        files.push_back(path);
      }
    }
    if (files.empty())
    {
      this->Fail(std::string("the directory '") + this->DirectoryName +
        "' has no image or DICOM files");
      return false;
    }
    std::sort(files.begin(), files.end(), octoray::NaturalLess);
    return true;
  }
  this->Fail("no slices given: set file names, a directory or a file pattern");
  return false;
}

//------------------------------------------------------------------------------
bool vtkSliceStackReader::ReadPictures(const std::vector<std::string>& files, vtkImageData* image)
{
  using namespace OIIO;
  struct Page
  {
    std::string File;
    int Subimage;
  };
  // Header pass: every page's size and type, so a mismatch is reported before
  // any pixel is read and the volume is allocated once.
  std::vector<Page> pages;
  int w = 0, h = 0, c = 0, type = VTK_VOID;
  std::string firstName;
  for (const auto& f : files)
  {
    std::error_code ec;
    if (!fs::exists(f, ec))
    {
      this->Fail("slice file '" + f + "' does not exist");
      return false;
    }
    auto in = ImageInput::open(f);
    if (!in)
    {
      this->Fail("cannot read slice '" + f + "': " + OIIO::geterror());
      return false;
    }
    for (int s = 0;; ++s)
    {
      ImageSpec spec;
      if (!in->seek_subimage(s, 0, spec))
      {
        break;
      }
      int t = VTK_FLOAT;
      switch (spec.format.basetype)
      {
        case TypeDesc::UINT8:
          t = VTK_UNSIGNED_CHAR;
          break;
        case TypeDesc::UINT16:
          t = VTK_UNSIGNED_SHORT;
          break;
        case TypeDesc::INT16:
          t = VTK_SHORT;
          break;
        default:
          t = VTK_FLOAT;
      }
      const int sc = std::min(spec.nchannels, 4);
      const std::string name = s == 0 ? f : f + " (page " + std::to_string(s + 1) + ")";
      if (sc < 1 || spec.width < 1 || spec.height < 1)
      {
        this->Fail("slice '" + name + "' has no pixels");
        return false;
      }
      if (pages.empty())
      {
        w = spec.width;
        h = spec.height;
        c = sc;
        type = t;
        firstName = name;
      }
      else if (spec.width != w || spec.height != h || sc != c || t != type)
      {
        this->Fail("slice '" + name + "' is " + Describe(spec.width, spec.height, sc, t) +
          " but slice '" + firstName + "' is " + Describe(w, h, c, type) +
          "; all slices must have one size and type");
        return false;
      }
      pages.push_back({ f, s });
    }
  }

  image->SetDimensions(w, h, static_cast<int>(pages.size()));
  image->SetSpacing(this->Spacing);
  image->SetOrigin(this->Origin);
  image->AllocateScalars(type, c);
  image->GetPointData()->GetScalars()->SetName("Scalars");
  TypeDesc format = type == VTK_UNSIGNED_CHAR ? TypeDesc::UINT8
    : type == VTK_UNSIGNED_SHORT              ? TypeDesc::UINT16
    : type == VTK_SHORT                       ? TypeDesc::INT16
                                              : TypeDesc::FLOAT;
  const size_t pixelBytes = static_cast<size_t>(c) * format.size();
  const stride_t rowBytes = static_cast<stride_t>(pixelBytes) * w;
  char* base = static_cast<char*>(image->GetScalarPointer());
  this->SliceFiles.clear();
  std::unique_ptr<ImageInput> in;
  std::string open;
  for (size_t k = 0; k < pages.size(); ++k)
  {
    const Page& pg = pages[k];
    if (open != pg.File)
    {
      in = ImageInput::open(pg.File);
      open = pg.File;
      if (!in)
      {
        this->Fail("cannot read slice '" + pg.File + "': " + OIIO::geterror());
        return false;
      }
    }
    // A negative row stride flips the rows while reading, so that j grows
    // upwards as in VTK's own image readers.
    char* slice = base + k * static_cast<size_t>(rowBytes) * h;
    if (!in->read_image(pg.Subimage, 0, 0, c, format, slice + (h - 1) * rowBytes,
          static_cast<stride_t>(pixelBytes), -rowBytes, AutoStride))
    {
      this->Fail("cannot read the pixels of slice '" + pg.File + "': " + in->geterror());
      return false;
    }
    this->SliceFiles.push_back(
      pg.Subimage ? pg.File + "#" + std::to_string(pg.Subimage + 1) : pg.File);
    this->UpdateProgress(0.8 * (k + 1) / pages.size());
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkSliceStackReader::ReadDICOM(const std::vector<std::string>& files, vtkImageData* image)
{
  struct Slice
  {
    std::string File;
    std::vector<float> Values;            // rescaled grey values
    std::vector<unsigned char> RGB;       // or colour
    double Origin[3], Row[3], Col[3], Spacing[3];
    double Position = 0;
    unsigned int Frames = 1;
  };
  std::vector<Slice> slices;
  unsigned int w = 0, h = 0;
  int comps = 0;
  for (size_t n = 0; n < files.size(); ++n)
  {
    const std::string& f = files[n];
    std::error_code ec;
    if (!fs::exists(f, ec))
    {
      this->Fail("DICOM slice '" + f + "' does not exist");
      return false;
    }
    // GDCM aborts on some damaged files: their structure is checked first.
    const std::string damage = octoray::CheckDicomStructure(f);
    if (!damage.empty())
    {
      this->Fail("cannot read DICOM slice '" + f + "': " + damage);
      return false;
    }
    gdcm::ImageReader reader;
    reader.SetFileName(f.c_str());
    if (!reader.Read())
    {
      this->Fail("cannot read DICOM slice '" + f + "': not a DICOM image GDCM can decode");
      return false;
    }
    const gdcm::Image& img = reader.GetImage();
    Slice s;
    s.File = f;
    const unsigned int* dims = img.GetDimensions();
    s.Frames = img.GetNumberOfDimensions() > 2 ? dims[2] : 1;
    const gdcm::PixelFormat& pf = img.GetPixelFormat();
    const int sc = pf.GetSamplesPerPixel();
    const std::string desc = std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + " " +
      (sc == 1 ? "grey" : "RGB");
    if (slices.empty())
    {
      w = dims[0];
      h = dims[1];
      comps = sc;
    }
    else if (dims[0] != w || dims[1] != h || sc != comps)
    {
      this->Fail("DICOM slice '" + f + "' is " + desc + " but slice '" + slices[0].File + "' is " +
        std::to_string(w) + "x" + std::to_string(h) + " " + (comps == 1 ? "grey" : "RGB") +
        "; all slices must have one size and type");
      return false;
    }
    if (sc != 1 && !(sc == 3 && pf.GetBitsAllocated() == 8))
    {
      this->Fail("DICOM slice '" + f + "' has " + std::to_string(sc) + " samples of " +
        std::to_string(pf.GetBitsAllocated()) + " bits; only grey or 8-bit RGB is supported");
      return false;
    }
    if (s.Frames > 1 && files.size() > 1)
    {
      this->Fail("DICOM slice '" + f + "' has " + std::to_string(s.Frames) +
        " frames; a series of several files must have one frame per file");
      return false;
    }
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
    std::vector<char> buffer(img.GetBufferLength());
    if (!img.GetBuffer(buffer.data()))
    {
      this->Fail("cannot decode the pixels of DICOM slice '" + f + "'");
      return false;
    }
    const size_t count = static_cast<size_t>(w) * h * s.Frames;
    if (sc == 3)
    {
      s.RGB.assign(buffer.begin(), buffer.begin() + std::min(buffer.size(), count * 3));
    }
    else
    {
      // Modality LUT: stored value * slope + intercept (e.g. CT numbers in HU).
      const double slope = img.GetSlope();
      const double intercept = img.GetIntercept();
      s.Values.resize(count);
      auto convert = [&](auto* src) {
        for (size_t i = 0; i < count; ++i)
        {
          s.Values[i] = static_cast<float>(src[i] * slope + intercept);
        }
      };
      switch (pf.GetScalarType())
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
          this->Fail("DICOM slice '" + f + "' has a pixel type that is not supported");
          return false;
      }
    }
    slices.push_back(std::move(s));
    this->UpdateProgress(0.7 * (n + 1) / files.size());
  }

  // Order along the slice normal (row x column direction) by image position;
  // the file names say nothing about it.
  const Slice& s0 = slices[0];
  double normal[3] = { s0.Row[1] * s0.Col[2] - s0.Row[2] * s0.Col[1],
    s0.Row[2] * s0.Col[0] - s0.Row[0] * s0.Col[2], s0.Row[0] * s0.Col[1] - s0.Row[1] * s0.Col[0] };
  for (auto& s : slices)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (std::abs(s.Row[a] - s0.Row[a]) > 1e-4 || std::abs(s.Col[a] - s0.Col[a]) > 1e-4)
      {
        this->Fail("DICOM slice '" + s.File + "' has another orientation than slice '" + s0.File +
          "'; a stack needs parallel slices");
        return false;
      }
    }
    s.Position = s.Origin[0] * normal[0] + s.Origin[1] * normal[1] + s.Origin[2] * normal[2];
  }
  std::stable_sort(slices.begin(), slices.end(),
    [](const Slice& a, const Slice& b) { return a.Position < b.Position; });
  double sz = s0.Spacing[2] > 0 ? s0.Spacing[2] : this->Spacing[2];
  if (slices.size() > 1)
  {
    double minGap = HUGE_VAL, maxGap = 0;
    for (size_t k = 1; k < slices.size(); ++k)
    {
      const double gap = slices[k].Position - slices[k - 1].Position;
      minGap = std::min(minGap, gap);
      maxGap = std::max(maxGap, gap);
      if (gap < 1e-6)
      {
        this->Fail("DICOM slices '" + slices[k - 1].File + "' and '" + slices[k].File +
          "' are at the same position");
        return false;
      }
    }
    sz = (slices.back().Position - slices.front().Position) / (slices.size() - 1);
    if (maxGap - minGap > 0.01 * sz)
    {
      vtkWarningMacro(<< "DICOM slice spacing varies from " << minGap << " to " << maxGap
                      << "; the volume uses the mean, " << sz);
    }
  }

  const int depth = static_cast<int>(slices.size() == 1 ? slices[0].Frames : slices.size());
  image->SetDimensions(static_cast<int>(w), static_cast<int>(h), depth);
  if (this->UseMetadata)
  {
    image->SetSpacing(slices[0].Spacing[0], slices[0].Spacing[1], sz);
    image->SetOrigin(slices[0].Origin);
    image->SetDirectionMatrix(slices[0].Row[0], slices[0].Col[0], normal[0], slices[0].Row[1],
      slices[0].Col[1], normal[1], slices[0].Row[2], slices[0].Col[2], normal[2]);
  }
  else
  {
    image->SetSpacing(this->Spacing);
    image->SetOrigin(this->Origin);
  }
  image->AllocateScalars(comps == 3 ? VTK_UNSIGNED_CHAR : VTK_FLOAT, comps);
  image->GetPointData()->GetScalars()->SetName("Scalars");
  const size_t sliceValues = static_cast<size_t>(w) * h * comps;
  this->SliceFiles.clear();
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
    this->SliceFiles.push_back(slices[k].File);
  }
  this->UpdateProgress(0.8);
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
  std::vector<std::string> files;
  if (!this->CollectFiles(files))
  {
    return 0;
  }
  for (const auto& f : files)
  {
    std::error_code ec;
    if (fs::is_directory(f, ec))
    {
      this->Fail("slice '" + f + "' is a directory, not an image file");
      return 0;
    }
  }
  int dims[3] = { 0, 0, 0 };
  const bool dicom = IsDICOMFile(files.front());
  if (dicom)
  {
    std::error_code ec;
    if (!fs::exists(files.front(), ec))
    {
      this->Fail("DICOM slice '" + files.front() + "' does not exist");
      return 0;
    }
    // GDCM aborts on some damaged files (an assert()) or allocates what a
    // damaged length claims: the structure is checked first, without
    // reading values.
    const std::string damage = octoray::CheckDicomStructure(files.front());
    if (!damage.empty())
    {
      this->Fail("cannot read DICOM slice '" + files.front() + "': " + damage);
      return 0;
    }
    // The header only: reading stops before the pixel data (a damaged
    // length there must not make the metadata path read gigabytes).
    gdcm::Reader reader;
    reader.SetFileName(files.front().c_str());
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
      this->Fail(
        "cannot read DICOM slice '" + files.front() + "': not a DICOM image GDCM can decode");
      return 0;
    }
    dims[0] = static_cast<int>(d[0]);
    dims[1] = static_cast<int>(d[1]);
    dims[2] = files.size() > 1 || d.size() < 3 || d[2] < 1 ? static_cast<int>(files.size())
                                                           : static_cast<int>(d[2]);
  }
  else
  {
    for (const auto& f : files)
    {
      std::error_code ec;
      if (!fs::exists(f, ec))
      {
        this->Fail("slice file '" + f + "' does not exist");
        return 0;
      }
      auto in = OIIO::ImageInput::open(f);
      if (!in)
      {
        this->Fail("cannot read slice '" + f + "': " + OIIO::geterror());
        return 0;
      }
      if (dims[2] == 0)
      {
        dims[0] = in->spec().width;
        dims[1] = in->spec().height;
      }
      OIIO::ImageSpec spec;
      for (int s = 0; in->seek_subimage(s, 0, spec); ++s)
      {
        ++dims[2];
      }
    }
  }
  const int extent[6] = { 0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1 };
  vtkInformation* info = outputVector->GetInformationObject(1);
  info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  info->Set(vtkDataObject::SPACING(), this->Spacing, 3);
  info->Set(vtkDataObject::ORIGIN(), this->Origin, 3);
  return 1;
}

//------------------------------------------------------------------------------
void vtkSliceStackReader::MakeParticles(vtkImageData* image, vtkPolyData* output)
{
  int dims[3];
  image->GetDimensions(dims);
  octoray::lattice::Axis axes[3];
  const long long size[3] = { dims[0], dims[1], dims[2] };
  for (int a = 0; a < 3; ++a)
  {
    const int lo = this->RegionOfInterest[2 * a];
    const int hi = this->RegionOfInterest[2 * a + 1];
    const int first = lo < 0 ? 0 : std::min(lo, dims[a] - 1);
    const int last = hi < 0 ? dims[a] - 1 : std::min(hi, dims[a] - 1);
    if (last < first)
    {
      output->SetPoints(vtkSmartPointer<vtkPoints>::New());
      return;
    }
    axes[a].First = first;
    axes[a].Stride = std::max(1, this->Stride[a]);
    axes[a].Count = (last - first) / axes[a].Stride + 1;
  }
  const double* spacing = image->GetSpacing();
  if (this->FillBetweenSlices)
  {
    // Planes between the slices, so that the particles are no farther apart
    // along the slice axis than across it (octorayLattice.h).
    const double step[3] = { spacing[0] * axes[0].Stride, spacing[1] * axes[1].Stride,
      spacing[2] * axes[2].Stride };
    const long long count[3] = { axes[0].Count, axes[1].Count, axes[2].Count };
    int fill[3];
    octoray::lattice::FillFactors(step, count, fill);
    for (int a = 0; a < 3; ++a)
    {
      axes[a].Fill = fill[a];
    }
  }
  const octoray::lattice::Lattice lattice = octoray::lattice::LatticeOf(
    axes, image->GetOrigin(), spacing, image->GetDirectionMatrix()->GetData());
  const int comps = image->GetNumberOfScalarComponents();
  switch (image->GetScalarType())
  {
    vtkTemplateMacro(Extract(static_cast<const VTK_TT*>(image->GetScalarPointer()), comps, axes, size,
      this->BackgroundRange, lattice, output, this->GenerateVertices));
  }
  // The lattice of the particles, for the octree mapper's leaf grid.
  auto field = vtkSmartPointer<vtkDoubleArray>::New();
  field->SetName(octoray::lattice::kFieldArrayName);
  field->SetNumberOfComponents(octoray::lattice::kFieldArrayComponents);
  field->SetNumberOfTuples(1);
  octoray::lattice::ToTuple(lattice, field->GetPointer(0));
  output->GetFieldData()->AddArray(field);
}

//------------------------------------------------------------------------------
int vtkSliceStackReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  vtkImageData* image = vtkImageData::GetData(outputVector, 1);
  this->ErrorMessage.clear();
  this->SliceFiles.clear();
  this->IsDICOM = false;
  output->Initialize();
  image->Initialize();

  // A failed update puts back the outputs of the last successful one (or
  // leaves them empty): the pipeline has already emptied them, and a failure
  // half-way must not leave a half-read stack.
  auto fail = [&]() {
    if (this->LastOutput)
    {
      output->ShallowCopy(this->LastOutput);
      image->ShallowCopy(this->LastImage);
      this->SliceFiles = this->LastSliceFiles;
      this->IsDICOM = this->LastIsDICOM;
    }
    else
    {
      output->Initialize();
      image->Initialize();
      this->SliceFiles.clear();
      this->IsDICOM = false;
    }
    return 0;
  };
  std::vector<std::string> files;
  if (!this->CollectFiles(files))
  {
    return fail();
  }
  for (const auto& f : files)
  {
    std::error_code ec;
    if (fs::is_directory(f, ec))
    {
      this->Fail("slice '" + f + "' is a directory, not an image file");
      return fail();
    }
  }
  size_t dicom = 0;
  for (const auto& f : files)
  {
    dicom += IsDICOMFile(f);
  }
  if (dicom && dicom != files.size())
  {
    this->Fail("the slices mix DICOM and other image files (e.g. '" + files.front() + "')");
    return fail();
  }
  this->IsDICOM = dicom > 0;
  this->UpdateProgress(0.0);
  auto freshImage = vtkSmartPointer<vtkImageData>::New();
  auto fresh = vtkSmartPointer<vtkPolyData>::New();
  bool ok = false;
  try
  {
    ok = this->IsDICOM ? this->ReadDICOM(files, freshImage) : this->ReadPictures(files, freshImage);
    if (ok)
    {
      this->MakeParticles(freshImage, fresh);
    }
  }
  catch (const std::exception& e)
  {
    this->Fail(std::string("reading the slices failed: ") + e.what() + " (first slice '" +
      files.front() + "')");
    ok = false;
  }
  if (!ok)
  {
    return fail();
  }
  output->ShallowCopy(fresh);
  image->ShallowCopy(freshImage);
  this->LastOutput = fresh;
  this->LastImage = freshImage;
  this->LastSliceFiles = this->SliceFiles;
  this->LastIsDICOM = this->IsDICOM;
  // The slices just read are part of the signature from now on; that is not
  // a change on disk.
  this->FileSignature = FilesSignature(this->DirectoryName, this->FileNames, this->SliceFiles);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
vtkMTimeType vtkSliceStackReader::GetMTime()
{
  const vtkMTimeType own = this->Superclass::GetMTime();
  const std::string signature =
    FilesSignature(this->DirectoryName, this->FileNames, this->SliceFiles);
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
  os << indent << "IsDICOM: " << this->IsDICOM << "\n";
}
