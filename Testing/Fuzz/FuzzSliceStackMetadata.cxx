// libFuzzer target: vtkSliceStackReader's metadata path (RequestInformation:
// OpenImageIO's or GDCM's header read of each slice) on arbitrary bytes.
// The first byte picks the file type (by extension: PNG, TIFF, BMP, JPEG,
// and DICOM when OCTORAY_FUZZ_DICOM=1); the rest is the file. DICOM is off
// by default: GDCM aborts on some damaged files (known-gdcm/README.md), which
// would make every `make test` fail on a bug that is not ours. Only our code is instrumented for coverage,
// so the fuzzer mostly mutates blindly inside the libraries; the point is
// that the reader never crashes and always names the slice when it fails.
#include "FuzzTempFile.h"

#include "vtkNew.h"
#include "vtkObject.h"
#include "vtkSliceStackReader.h"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
  if (size < 1)
  {
    return 0;
  }
  static const char* ext[] = { ".png", ".tif", ".bmp", ".jpg", ".dcm" };
  static const bool dicom = std::getenv("OCTORAY_FUZZ_DICOM") && *std::getenv("OCTORAY_FUZZ_DICOM") == '1';
  // The reader recognises DICOM by the "DICM" marker at byte 128 too,
  // whatever the extension: without DICOM mode such inputs are skipped.
  if (!dicom && size >= 1 + 132 && std::memcmp(data + 1 + 128, "DICM", 4) == 0)
  {
    return 0;
  }
  vtkObject::GlobalWarningDisplayOff();
  const std::string path = FuzzWriteTemp(ext[data[0] % (dicom ? 5 : 4)], data + 1, size - 1);
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
