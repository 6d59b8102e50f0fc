#include "octoraySlicePictures.h"

#include "octoraySliceChecks.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkPointData.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <memory>

namespace fs = std::filesystem;

namespace octoray
{
namespace slices
{
namespace
{
using namespace OIIO;

// The VTK type a picture's pixels are kept in, and its name: their own,
// read as they are stored (OpenImageIO would scale integers to 0..1 in
// float, and round doubles: int32 2147483647 came back as 1.0, uint32
// 4000000001 as 0.931); half floats as float.
struct PixelType
{
  TypeDesc::BASETYPE Stored;
  int Kept;
  const char* Name;
};
constexpr PixelType kPixelTypes[] = {
  { TypeDesc::UINT8, VTK_UNSIGNED_CHAR, "uint8" },
  { TypeDesc::INT8, VTK_SIGNED_CHAR, "int8" },
  { TypeDesc::UINT16, VTK_UNSIGNED_SHORT, "uint16" },
  { TypeDesc::INT16, VTK_SHORT, "int16" },
  { TypeDesc::UINT32, VTK_UNSIGNED_INT, "uint32" },
  { TypeDesc::INT32, VTK_INT, "int32" },
  { TypeDesc::UINT64, VTK_UNSIGNED_LONG_LONG, "uint64" },
  { TypeDesc::INT64, VTK_LONG_LONG, "int64" },
  { TypeDesc::FLOAT, VTK_FLOAT, "float" },
  { TypeDesc::DOUBLE, VTK_DOUBLE, "double" },
};

int VTKTypeOf(TypeDesc format)
{
  for (const PixelType& t : kPixelTypes)
  {
    if (t.Stored == format.basetype)
    {
      return t.Kept;
    }
  }
  return VTK_FLOAT; // half
}

const PixelType& PixelTypeOf(int vtkType)
{
  const PixelType* end = std::end(kPixelTypes);
  const PixelType* found = std::find_if(std::begin(kPixelTypes), end, [&](const PixelType& t) { return t.Kept == vtkType; });
  return found != end ? *found : PixelTypeOf(VTK_FLOAT);
}

TypeDesc FormatOf(int vtkType)
{
  return PixelTypeOf(vtkType).Stored;
}

const char* TypeName(int vtkType)
{
  return PixelTypeOf(vtkType).Name;
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

// One page of a picture file: one slice.
struct Page
{
  std::string File;
  int Subimage;
};

// What every page must share with the first.
struct PageFormat
{
  int Width = 0, Height = 0, Channels = 0, Type = VTK_VOID;
  std::string Name; // the first page's

  std::string Describe() const
  {
    return std::to_string(this->Width) + "x" + std::to_string(this->Height) + " " +
      ChannelName(this->Channels) + " " + TypeName(this->Type);
  }
};

std::unique_ptr<ImageInput> Open(const std::string& f, std::string& error)
{
  auto in = ImageInput::open(f);
  if (!in)
  {
    error = "cannot read slice '" + f + "': " + OIIO::geterror();
  }
  return in;
}

// For the header passes: a missing file is said so, before OpenImageIO
// says it cannot read it.
std::unique_ptr<ImageInput> OpenHeader(const std::string& f, std::string& error)
{
  std::error_code ec;
  if (!fs::exists(f, ec))
  {
    error = "slice file '" + f + "' does not exist";
    return nullptr;
  }
  return Open(f, error);
}

// Header pass: every page's size and type, so that a mismatch is reported
// before any pixel is read and the volume is allocated once.
bool ListPages(const std::vector<std::string>& files, std::vector<Page>& pages,
  PageFormat& format, std::string& error)
{
  for (const auto& f : files)
  {
    auto in = OpenHeader(f, error);
    if (!in)
    {
      return false;
    }
    for (int s = 0;; ++s)
    {
      ImageSpec spec;
      if (!in->seek_subimage(s, 0, spec))
      {
        break;
      }
      PageFormat page;
      page.Width = spec.width;
      page.Height = spec.height;
      page.Channels = std::min(spec.nchannels, 4);
      page.Type = VTKTypeOf(spec.format);
      page.Name = s == 0 ? f : f + " (page " + std::to_string(s + 1) + ")";
      if (page.Channels < 1 || page.Width < 1 || page.Height < 1)
      {
        error = "slice '" + page.Name + "' has no pixels";
        return false;
      }
      if (pages.empty())
      {
        format = page;
      }
      else if (page.Width != format.Width || page.Height != format.Height ||
        page.Channels != format.Channels || page.Type != format.Type)
      {
        error =
          MismatchMessage("slice", page.Name, page.Describe(), format.Name, format.Describe());
        return false;
      }
      pages.push_back({ f, s });
    }
  }
  return true;
}

// Pixel pass: page k into slice k of image, which has the pages' format.
bool ReadPages(const std::vector<Page>& pages, const PageFormat& format, vtkImageData* image,
  SliceRead& read)
{
  const int w = format.Width, h = format.Height, c = format.Channels;
  const TypeDesc type = FormatOf(format.Type);
  const size_t pixelBytes = static_cast<size_t>(c) * type.size();
  const stride_t rowBytes = static_cast<stride_t>(pixelBytes) * w;
  char* base = static_cast<char*>(image->GetScalarPointer());
  std::unique_ptr<ImageInput> in;
  std::string open;
  for (size_t k = 0; k < pages.size(); ++k)
  {
    const Page& pg = pages[k];
    if (open != pg.File)
    {
      open = pg.File;
      if (!(in = Open(pg.File, read.Error)))
      {
        return false;
      }
    }
    // A negative row stride flips the rows while reading, so that j grows
    // upwards as in VTK's own image readers.
    char* slice = base + k * static_cast<size_t>(rowBytes) * h;
    if (!in->read_image(pg.Subimage, 0, 0, c, type, slice + (h - 1) * rowBytes,
          static_cast<stride_t>(pixelBytes), -rowBytes, AutoStride))
    {
      return read.Fail("cannot read the pixels of slice '" + pg.File + "': " + in->geterror());
    }
    read.SliceFiles.push_back(
      pg.Subimage ? pg.File + "#" + std::to_string(pg.Subimage + 1) : pg.File);
    read.Progress(0.8 * (k + 1) / pages.size());
  }
  return true;
}
} // namespace

//------------------------------------------------------------------------------
bool PictureStackDimensions(const std::vector<std::string>& files, int dims[3], std::string& error)
{
  dims[0] = dims[1] = dims[2] = 0;
  for (const auto& f : files)
  {
    auto in = OpenHeader(f, error);
    if (!in)
    {
      return false;
    }
    if (dims[2] == 0)
    {
      dims[0] = in->spec().width;
      dims[1] = in->spec().height;
    }
    ImageSpec spec;
    for (int s = 0; in->seek_subimage(s, 0, spec); ++s)
    {
      ++dims[2];
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool ReadPictureStack(const std::vector<std::string>& files, vtkImageData* image, SliceRead& read)
{
  std::vector<Page> pages;
  PageFormat format;
  if (!ListPages(files, pages, format, read.Error))
  {
    return false;
  }
  image->SetDimensions(format.Width, format.Height, static_cast<int>(pages.size()));
  image->AllocateScalars(format.Type, format.Channels);
  image->GetPointData()->GetScalars()->SetName("Scalars");
  return ReadPages(pages, format, image, read);
}
} // namespace slices
} // namespace octoray
