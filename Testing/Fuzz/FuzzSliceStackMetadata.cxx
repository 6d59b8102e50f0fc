// libFuzzer target: vtkSliceStackReader's metadata path (RequestInformation:
// OpenImageIO's header read of each slice, or for DICOM our structure check
// and then GDCM's header read) on arbitrary bytes. The first byte picks the
// file type by extension: PNG, TIFF, BMP, JPEG or DICOM (the reader also
// takes any file with "DICM" at byte 128 for DICOM). Only our code is
// instrumented for coverage, so the fuzzer mostly mutates blindly inside the
// libraries; the point is that the reader never crashes (GDCM 3.0 aborts on
// some damaged files: regressions/slice_stack/dicom_* are those the structure
// check now stops) and always names the slice when it fails.
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
  static const char* ext[] = { ".png", ".tif", ".bmp", ".jpg", ".dcm" };
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
