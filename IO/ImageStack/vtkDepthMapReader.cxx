#include "vtkDepthMapReader.h"

#include "vtkCellArray.h"
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

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <numeric>
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

//------------------------------------------------------------------------------
int vtkDepthMapReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  using namespace OIIO;
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
  auto in = ImageInput::open(this->FileName);
  if (!in)
  {
    this->Fail(std::string("cannot read depth image '") + this->FileName + "': " + OIIO::geterror());
    return 0;
  }
  const ImageSpec spec = in->spec();
  const int w = spec.width, h = spec.height;
  // Depth is the channel named Z or depth if there is one, else the first.
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
  std::vector<float> depth(static_cast<size_t>(w) * h);
  // Integers are read as their stored values (not normalised to 0..1).
  const bool integer = spec.format.is_floating_point() == false;
  bool ok;
  if (integer && spec.format.basetype == TypeDesc::UINT16)
  {
    std::vector<unsigned short> raw(depth.size());
    ok = in->read_image(0, 0, channel, channel + 1, TypeDesc::UINT16, raw.data());
    std::copy(raw.begin(), raw.end(), depth.begin());
  }
  else if (integer && spec.format.basetype == TypeDesc::UINT8)
  {
    std::vector<unsigned char> raw(depth.size());
    ok = in->read_image(0, 0, channel, channel + 1, TypeDesc::UINT8, raw.data());
    std::copy(raw.begin(), raw.end(), depth.begin());
  }
  else if (!integer)
  {
    ok = in->read_image(0, 0, channel, channel + 1, TypeDesc::FLOAT, depth.data());
  }
  else
  {
    this->Fail(std::string("depth image '") + this->FileName + "' has pixel type " +
      spec.format.c_str() + "; expected 8- or 16-bit unsigned integers or floats");
    return 0;
  }
  if (!ok)
  {
    this->Fail(std::string("cannot read the pixels of depth image '") + this->FileName + "': " +
      in->geterror());
    return 0;
  }
  in->close();

  std::vector<unsigned char> rgb;
  if (this->ColorFileName && *this->ColorFileName)
  {
    auto cin = ImageInput::open(this->ColorFileName);
    if (!cin)
    {
      this->Fail(std::string("cannot read colour image '") + this->ColorFileName +
        "': " + OIIO::geterror());
      return 0;
    }
    const ImageSpec& cs = cin->spec();
    if (cs.width != w || cs.height != h)
    {
      this->Fail(std::string("colour image '") + this->ColorFileName + "' is " +
        std::to_string(cs.width) + "x" + std::to_string(cs.height) + " but depth image '" +
        this->FileName + "' is " + std::to_string(w) + "x" + std::to_string(h));
      return 0;
    }
    std::vector<unsigned char> all(static_cast<size_t>(w) * h * cs.nchannels);
    if (!cin->read_image(0, 0, 0, cs.nchannels, TypeDesc::UINT8, all.data()))
    {
      this->Fail(std::string("cannot read the pixels of colour image '") + this->ColorFileName +
        "': " + cin->geterror());
      return 0;
    }
    rgb.resize(static_cast<size_t>(w) * h * 3);
    for (size_t p = 0; p < static_cast<size_t>(w) * h; ++p)
    {
      for (int c = 0; c < 3; ++c)
      {
        rgb[3 * p + c] = all[p * cs.nchannels + std::min(c, cs.nchannels - 1)];
      }
    }
  }
  this->UpdateProgress(0.5);

  auto pts = vtkSmartPointer<vtkFloatArray>::New();
  pts->SetNumberOfComponents(3);
  auto z = vtkSmartPointer<vtkFloatArray>::New();
  z->SetName("Depth");
  vtkSmartPointer<vtkUnsignedCharArray> colors;
  if (!rgb.empty())
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
  const vtkIdType n = pts->GetNumberOfTuples();
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
    auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
    offsets->SetNumberOfTuples(n + 1);
    auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
    conn->SetNumberOfTuples(n);
    std::iota(offsets->GetPointer(0), offsets->GetPointer(0) + n + 1, 0);
    std::iota(conn->GetPointer(0), conn->GetPointer(0) + n, 0);
    auto verts = vtkSmartPointer<vtkCellArray>::New();
    verts->SetData(offsets, conn);
    output->SetVerts(verts);
  }
  this->UpdateProgress(1.0);
  return 1;
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
