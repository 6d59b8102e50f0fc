// libFuzzer target: vtkParticleTextReader on arbitrary bytes (plain or
// gzip). The first byte picks strict/lenient and float/double; the rest is
// the file. The reader must fail cleanly (an error message naming the file)
// or produce points matching its arrays.
#include "FuzzTempFile.h"

#include "vtkDataArray.h"
#include "vtkNew.h"
#include "vtkObject.h"
#include "vtkParticleTextReader.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
  if (size < 1)
  {
    return 0;
  }
  vtkObject::GlobalWarningDisplayOff();
  const std::string path = FuzzWriteTemp(".particles", data + 1, size - 1);
  vtkNew<vtkParticleTextReader> r;
  r->SetFileName(path.c_str());
  r->SetNumberOfThreads(1 + (data[0] >> 7)); // one or two threads
  r->SetLenient(data[0] & 1);
  r->SetOutputPointsPrecision(
    (data[0] & 2) ? vtkAlgorithm::DOUBLE_PRECISION : vtkAlgorithm::SINGLE_PRECISION);
  r->Update();
  vtkPolyData* out = r->GetOutput();
  const vtkIdType n = out->GetNumberOfPoints();
  if (n == 0 && std::string(r->GetErrorMessage()).find(path) == std::string::npos)
  {
    std::abort(); // an empty result always says why, naming the file
  }
  vtkPointData* pd = out->GetPointData();
  for (int a = 0; a < pd->GetNumberOfArrays(); ++a)
  {
    if (pd->GetArray(a) && pd->GetArray(a)->GetNumberOfTuples() != n)
    {
      std::abort();
    }
  }
  ::unlink(path.c_str());
  return 0;
}
