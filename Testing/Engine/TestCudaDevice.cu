// The CUDA device's primitives under the build driver, held to the same
// checks as the CPU device's (DeviceChecks.h), at sizes that take one to
// thousands of blocks: the whole-octree tests compare the two backends'
// results, and these say which primitive differs. Compiled by nvcc with the
// engine's CUDA options where the CUDA backend is built.
#include "CudaOnlyTest.h"
#include "DeviceChecks.h"

#include <octoray/CudaDevice.h>
#include <octoray/FaultInjection.h>

// In octoray's namespace, not with a using-directive: nvcc's generated host
// code names CUDA's own `cuda` namespace, which octoray::cuda would hide.
namespace octoray::test
{
namespace
{
// Empty, one item, less than a block, part of a nested-list warp tile, one
// tile and one item more, and enough items for every histogram block and
// for several passes of the CUB kernels' tiles.
const std::size_t kSizes[] = { 0, 1, 5, 200, cuda::kNestedWarpTile + 1, 100003, 1000003 };

// check(n, device) for every size, on a fresh device each.
template <typename Check>
void OnEverySize(Check&& check)
{
  for (std::size_t n : kSizes)
  {
    SCOPED_TRACE("n " + std::to_string(n));
    CudaDevice d(-1);
    check(n, d);
  }
}
}

using CudaDeviceCUDA = CudaOnlyTest;

TEST_F(CudaDeviceCUDA, ForEachAndReduceCoverEveryItemOnce)
{
  OnEverySize([](std::size_t n, CudaDevice& d) { checks::ExpectLoopsCoverEveryItemOnce(d, n); });
}

// Staged in one pass (the arrays together past kStagingThreshold),
// whenReduced runs while the arrays along are on their way; below, they
// are copied directly and it does not.
TEST_F(CudaDeviceCUDA, StageReducedCopiesReducesAndCallsBack)
{
  OnEverySize([](std::size_t n, CudaDevice& d) {
    const bool staged = cuda::StagingRun(checks::StagedArrayBytes(n)).Length() >= cuda::kStagingThreshold;
    checks::ExpectStageReducedCopiesReducesAndCallsBack(d, n, staged);
  });
}

// Unit values the device reads itself (a caller's device or page-locked
// array): their codes made by a loop there, with nothing to stage.
TEST_F(CudaDeviceCUDA, UnitCodesOfValuesTheDeviceReads)
{
  OnEverySize([](std::size_t n, CudaDevice& d) {
    const std::vector<float> units = checks::UnitValues(n);
    checks::DeviceArray<CudaDevice, float> onDevice(d, units);
    float* pageLocked = nullptr;
    ASSERT_EQ(cudaMallocHost(&pageLocked, (n + 1) * sizeof(float)), cudaSuccess);
    std::copy(units.begin(), units.end(), pageLocked);
    for (const float* source : { static_cast<const float*>(onDevice.Get()), static_cast<const float*>(pageLocked) })
    {
      CudaDevice::Fills fills;
      const auto codes = d.PrepareUnitCodes(n ? source : nullptr, n, "test unit values", fills);
      EXPECT_TRUE(fills.empty()) << "nothing to stage";
      EXPECT_EQ(checks::HostCopy(d, codes.Get(), n), checks::UnitCodesOf(units));
    }
    cudaFreeHost(pageLocked);
  });
}

// That loop refused: the error names it, and nothing sticks.
TEST_F(CudaDeviceCUDA, UnitCodesLoopRefusedIsNamed)
{
  CudaDevice d(-1);
  const std::vector<float> units = checks::UnitValues(1000);
  checks::DeviceArray<CudaDevice, float> onDevice(d, units);
  CudaDevice::Fills fills;
  InjectCudaLaunchFailure("UnitCodesKernel");
  try
  {
    d.PrepareUnitCodes(onDevice.Get(), units.size(), "test unit values", fills);
    ADD_FAILURE() << "the refused launch went unreported";
  }
  catch (const Error& e)
  {
    EXPECT_EQ(std::string(e.what()).rfind("octoray: CUDA launch of UnitCodesKernel failed: ", 0), 0u) << e.what();
  }
  EXPECT_EQ(cudaGetLastError(), cudaSuccess);
  const auto codes = d.PrepareUnitCodes(onDevice.Get(), units.size(), "test unit values", fills);
  EXPECT_EQ(checks::HostCopy(d, codes.Get(), units.size()), checks::UnitCodesOf(units));
}

TEST_F(CudaDeviceCUDA, SmallLevelsReduceEachLevelAfterTheOneBelow)
{
  OnEverySize([](std::size_t n, CudaDevice& d) { checks::ExpectSmallLevelsReduceEachLevelAfterTheOneBelow(d, n); });
}

TEST_F(CudaDeviceCUDA, SelectKeepsOrderAndCounts)
{
  OnEverySize([](std::size_t n, CudaDevice& d) { checks::ExpectSelectKeepsOrderAndCounts(d, n); });
}

TEST_F(CudaDeviceCUDA, NestedListsHoldEachItemFromItsFirstListOn)
{
  OnEverySize([](std::size_t n, CudaDevice& d) { checks::ExpectNestedListsHoldEachItemFromItsFirstListOn(d, n); });
}

TEST_F(CudaDeviceCUDA, SortsAreStable)
{
  OnEverySize([](std::size_t n, CudaDevice& d) { checks::ExpectSortsStable(d, n, n); });
}

TEST_F(CudaDeviceCUDA, RunStartsAndFirstFailedStep)
{
  OnEverySize([](std::size_t n, CudaDevice& d) { checks::ExpectRunStartsAndFirstFailedStep(d, n); });
}
}
