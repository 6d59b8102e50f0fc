// libFuzzer target: vtkSliceStackReader's metadata path (RequestInformation:
// OpenImageIO's or GDCM's header read of each slice) on arbitrary bytes.
// The first byte picks the file type (by extension: PNG, TIFF, DICOM, BMP,
// JPEG); the rest is the file. Only our code is instrumented for coverage,
// so the fuzzer mostly mutates blindly inside the libraries; the point is
// that the reader never crashes and always names the slice when it fails.
#include "FuzzTempFile.h"

#include "vtkNew.h"
#include "vtkObject.h"
#include "vtkSliceStackReader.h"

#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
  if (size < 1)
  {
    return 0;
  }
  static const char* ext[] = { ".png", ".tif", ".dcm", ".bmp", ".jpg" };
  vtkObject::GlobalWarningDisplayOff();
  const std::string path = FuzzWriteTemp(ext[data[0] % 5], data + 1, size - 1);
  vtkNew<vtkSliceStackReader> r;
  r->AddFileName(path.c_str());
  r->UpdateInformation();
  const std::string error = r->GetErrorMessage();
  if (!error.empty() && error.find(path) == std::string::npos)
  {
    std::abort(); // every error names the slice
  }
  ::unlink(path.c_str());
  return 0;
}
