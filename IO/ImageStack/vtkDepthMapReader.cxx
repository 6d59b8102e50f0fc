#include "vtkDepthMapReader.h"

#include "octorayVertexCells.h"

#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkDepthMapReader);

//------------------------------------------------------------------------------
vtkDepthMapReader::vtkDepthMapReader()
{
  this->SetNumberOfInputPorts(0);
}

//------------------------------------------------------------------------------
vtkDepthMapReader::~vtkDepthMapReader()
{
  this->SetFileName(nullptr);
  this->SetColorFileName(nullptr);
}

//------------------------------------------------------------------------------
void vtkDepthMapReader::SetIntrinsics(double fx, double fy, double cx, double cy)
{
  this->SetFocalLengthX(fx);
  this->SetFocalLengthY(fy);
  this->SetPrincipalPointX(cx);
  this->SetPrincipalPointY(cy);
}

//------------------------------------------------------------------------------
void vtkDepthMapReader::Fail(const std::string& message)
{
  this->ErrorMessage = message;
  vtkErrorMacro(<< message);
}

namespace
{
using namespace OIIO;

// The depth image's values: the channel named Z or depth if there is one,
// else the first; integers as their stored values (not normalised to 0..1).
bool ReadDepth(const char* name, std::vector<float>& depth, int& w, int& h, std::string& error)
{
  auto in = ImageInput::open(name);
  if (!in)
  {
    error = std::string("cannot read depth image '") + name + "': " + OIIO::geterror();
    return false;
  }
  const ImageSpec spec = in->spec();
  w = spec.width;
  h = spec.height;
  int channel = 0;
  for (int c = 0; c < spec.nchannels; ++c)
  {
    const std::string n = spec.channelnames.size() > static_cast<size_t>(c) ? spec.channelnames[c] : "";
    if (n == "Z" || n == "depth" || n == "Depth")
    {
      channel = c;
      break;
    }
  }
  depth.resize(static_cast<size_t>(w) * h);
  auto read = [&](TypeDesc type, auto sample) {
    std::vector<decltype(sample)> raw(depth.size());
    const bool ok = in->read_image(0, 0, channel, channel + 1, type, raw.data());
    std::copy(raw.begin(), raw.end(), depth.begin());
    return ok;
  };
  const bool integer = spec.format.is_floating_point() == false;
  bool ok;
  if (integer && spec.format.basetype == TypeDesc::UINT16)
  {
    ok = read(TypeDesc::UINT16, static_cast<unsigned short>(0));
  }
  else if (integer && spec.format.basetype == TypeDesc::UINT8)
  {
    ok = read(TypeDesc::UINT8, static_cast<unsigned char>(0));
  }
  else if (!integer)
  {
    ok = in->read_image(0, 0, channel, channel + 1, TypeDesc::FLOAT, depth.data());
  }
  else
  {
    error = std::string("depth image '") + name + "' has pixel type " + spec.format.c_str() +
      "; expected 8- or 16-bit unsigned integers or floats";
    return false;
  }
  if (!ok)
  {
    error = std::string("cannot read the pixels of depth image '") + name + "': " + in->geterror();
    return false;
  }
  in->close();
  return true;
}

// The colour image as RGB bytes (grey repeated), w x h like the depth image.
bool ReadColour(const char* name, const char* depthName, int w, int h,
  std::vector<unsigned char>& rgb, std::string& error)
{
  auto cin = ImageInput::open(name);
  if (!cin)
  {
    error = std::string("cannot read colour image '") + name + "': " + OIIO::geterror();
    return false;
  }
  const ImageSpec& cs = cin->spec();
  if (cs.width != w || cs.height != h)
  {
    error = std::string("colour image '") + name + "' is " + std::to_string(cs.width) + "x" +
      std::to_string(cs.height) + " but depth image '" + depthName + "' is " + std::to_string(w) +
      "x" + std::to_string(h);
    return false;
  }
  std::vector<unsigned char> all(static_cast<size_t>(w) * h * cs.nchannels);
  if (!cin->read_image(0, 0, 0, cs.nchannels, TypeDesc::UINT8, all.data()))
  {
    error =
      std::string("cannot read the pixels of colour image '") + name + "': " + cin->geterror();
    return false;
  }
  rgb.resize(static_cast<size_t>(w) * h * 3);
  for (size_t p = 0; p < static_cast<size_t>(w) * h; ++p)
  {
    for (int c = 0; c < 3; ++c)
    {
      rgb[3 * p + c] = all[p * cs.nchannels + std::min(c, cs.nchannels - 1)];
    }
  }
  return true;
}
} // namespace

//------------------------------------------------------------------------------
int vtkDepthMapReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  this->ErrorMessage.clear();
  this->NumberOfInvalidPixels = 0;
  if (!this->FileName || !*this->FileName)
  {
    this->Fail("no depth image file name was set");
    return 0;
  }
  if (!(this->FocalLengthX > 0) || !(this->FocalLengthY > 0))
  {
    this->Fail(std::string(this->FileName) +
      ": the focal lengths fx and fy must be set and positive (pixels); got fx=" +
      std::to_string(this->FocalLengthX) + ", fy=" + std::to_string(this->FocalLengthY));
    return 0;
  }
  // Settings under which no pixel can be a point: said, not read as an
  // image of invalid pixels.
  std::ostringstream range;
  if (!(this->DepthScale > 0) || !std::isfinite(this->DepthScale))
  {
    range << this->FileName << ": DepthScale must be finite and positive (output units per stored value); got "
          << this->DepthScale;
  }
  else if (!(this->MinimumDepth < this->MaximumDepth))
  {
    range << this->FileName << ": MinimumDepth (" << this->MinimumDepth << ") must lie below MaximumDepth ("
          << this->MaximumDepth << ")";
  }
  if (!range.str().empty())
  {
    this->Fail(range.str());
    return 0;
  }
  std::vector<float> depth;
  std::vector<unsigned char> rgb;
  int w = 0, h = 0;
  std::string error;
  if (!ReadDepth(this->FileName, depth, w, h, error) ||
    (this->ColorFileName && *this->ColorFileName &&
      !ReadColour(this->ColorFileName, this->FileName, w, h, rgb, error)))
  {
    this->Fail(error);
    return 0;
  }
  this->UpdateProgress(0.5);
  this->MakePoints(depth.data(), w, h, rgb.empty() ? nullptr : rgb.data(), output);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
// Pinhole back-projection of every Stride-th pixel whose scaled depth is in
// range; the others are counted as invalid.
void vtkDepthMapReader::MakePoints(
  const float* depth, int w, int h, const unsigned char* rgb, vtkPolyData* output)
{
  auto pts = vtkSmartPointer<vtkFloatArray>::New();
  pts->SetNumberOfComponents(3);
  auto z = vtkSmartPointer<vtkFloatArray>::New();
  z->SetName("Depth");
  vtkSmartPointer<vtkUnsignedCharArray> colors;
  if (rgb)
  {
    colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
    colors->SetName("Colors");
    colors->SetNumberOfComponents(3);
  }
  const double fx = this->FocalLengthX, fy = this->FocalLengthY;
  const double cx = this->PrincipalPointX, cy = this->PrincipalPointY;
  for (int v = 0; v < h; v += this->Stride)
  {
    for (int u = 0; u < w; u += this->Stride)
    {
      const size_t p = static_cast<size_t>(v) * w + u;
      const double d = depth[p] * this->DepthScale;
      if (!std::isfinite(d) || d <= 0 || d < this->MinimumDepth || d > this->MaximumDepth)
      {
        ++this->NumberOfInvalidPixels;
        continue;
      }
      const float xyz[3] = { static_cast<float>((u - cx) * d / fx),
        static_cast<float>((v - cy) * d / fy), static_cast<float>(d) };
      pts->InsertNextTypedTuple(xyz);
      z->InsertNextValue(xyz[2]);
      if (colors)
      {
        colors->InsertNextTypedTuple(&rgb[3 * p]);
      }
    }
  }
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetData(pts);
  output->SetPoints(points);
  output->GetPointData()->AddArray(z);
  if (colors)
  {
    output->GetPointData()->SetScalars(colors);
  }
  else
  {
    output->GetPointData()->SetScalars(z);
  }
  if (this->GenerateVertices)
  {
    output->SetVerts(octoray::VertexCells(pts->GetNumberOfTuples()));
  }
}

//------------------------------------------------------------------------------
void vtkDepthMapReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "ColorFileName: " << (this->ColorFileName ? this->ColorFileName : "(none)")
     << "\n";
  os << indent << "Intrinsics (fx fy cx cy): " << this->FocalLengthX << " " << this->FocalLengthY
     << " " << this->PrincipalPointX << " " << this->PrincipalPointY << "\n";
  os << indent << "DepthScale: " << this->DepthScale << "\n";
  os << indent << "MinimumDepth: " << this->MinimumDepth << "\n";
  os << indent << "MaximumDepth: " << this->MaximumDepth << "\n";
  os << indent << "Stride: " << this->Stride << "\n";
  os << indent << "GenerateVertices: " << this->GenerateVertices << "\n";
  os << indent << "NumberOfInvalidPixels: " << this->NumberOfInvalidPixels << "\n";
}
