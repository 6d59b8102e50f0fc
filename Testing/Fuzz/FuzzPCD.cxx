// libFuzzer target: PCD files. The first byte holds flags (bit 0: double
// precision points); the rest is, at once, a file for vtkPCDReader and a raw
// LZF stream for the module's decoder (into an output of exactly the size
// bit 1..7 and the stream's length pick, so that AddressSanitizer sees any
// write past it). The reader must fail cleanly (an error naming the file)
// or produce points whose arrays all have one tuple per point.
#include "FuzzTempFile.h"
#include "octorayLZF.h"

#include "vtkCallbackCommand.h"
#include "vtkDataArray.h"
#include "vtkExecutive.h"
#include "vtkNew.h"
#include "vtkObject.h"
#include "vtkPCDReader.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
  if (size < 1)
  {
    return 0;
  }
  vtkObject::GlobalWarningDisplayOff();
  const unsigned char flags = data[0];
  const unsigned char* body = data + 1;
  const size_t n = size - 1;

  // The decoder alone: an output as large as the stream could fill, or
  // smaller, never more than 88 times the input.
  {
    const size_t room = std::min<size_t>(n * octoray::pcd::LzfMaximumExpansion,
      (n * (flags >> 1)) / 16 + (flags >> 1));
    std::vector<unsigned char> out(room);
    std::string error;
    size_t reports = 0;
    const bool ok = octoray::pcd::LzfDecompress(body, n, out.data(), out.size(), error,
      [&](size_t) { return ++reports < 1000; });
    if (!ok && error.empty() && reports < 1000)
    {
      std::abort(); // a failure always says why (unless stopped by progress)
    }
  }

  const std::string path = FuzzWriteTemp(".pcd", body, n);
  vtkNew<vtkPCDReader> r;
  r->SetFileName(path.c_str());
  r->SetOutputPointsPrecision(
    (flags & 1) ? vtkAlgorithm::DOUBLE_PRECISION : vtkAlgorithm::SINGLE_PRECISION);
  r->Update();
  vtkPolyData* out = r->GetOutput();
  const vtkIdType points = out->GetNumberOfPoints();
  const std::string error = r->GetErrorMessage();
  if (!error.empty() && (points != 0 || error.compare(0, path.size(), path) != 0))
  {
    std::abort(); // a failed read leaves nothing (a fresh reader) and names the file
  }
  vtkPointData* pd = out->GetPointData();
  for (int a = 0; a < pd->GetNumberOfArrays(); ++a)
  {
    if (pd->GetArray(a) && pd->GetArray(a)->GetNumberOfTuples() != points)
    {
      std::abort();
    }
  }
  ::unlink(path.c_str());
  return 0;
}
