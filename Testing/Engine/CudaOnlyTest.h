// The skip of CUDA tests where no GPU is usable, for the suites of every
// backend (TestSupport.h) and for those that only the CUDA backend has;
// light enough for nvcc to compile in TestCudaDevice.cu.
#pragma once

#include <octoray/Engine.h>

#include <gtest/gtest.h>

#include <string>

namespace octoray::test
{
// Why a CUDA test cannot run here, as its skip says it; empty where it can.
inline std::string CudaSkipReason()
{
  std::string why;
  return CudaAvailable(&why) ? std::string() : "CUDA backend not usable here: " + why;
}

// The fixture of suites that only the CUDA backend has: skipped, saying
// why, where no GPU is usable.
class CudaOnlyTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    const std::string why = CudaSkipReason();
    if (!why.empty())
    {
      GTEST_SKIP() << why;
    }
  }
};
}
