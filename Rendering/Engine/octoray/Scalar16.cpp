#include "Scalar16.h"

namespace octoray
{
// GCC vectorises this loop only where it may assume that no floating-point
// operation traps (-fno-trapping-math, set on this file alone in
// CMakeLists.txt: the codes are the same, only the exception flags could
// differ); without it, a scalar loop a value.
void EncodeUnitScalars(const float* values, std::size_t n, std::uint16_t* codes)
{
  for (std::size_t i = 0; i < n; ++i)
  {
    codes[i] = EncodeUnitScalar(values[i]).code;
  }
}
}
