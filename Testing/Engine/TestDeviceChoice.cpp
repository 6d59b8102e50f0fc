// The CUDA device a process picks (DeviceChoice.h): by its rank on the host,
// for any number of devices, overridden by a setting or OCTORAY_CUDA_DEVICE.
// Host-only: it runs where there is no GPU.
#include <octoray/DeviceChoice.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <set>
#include <string>

using namespace octoray;

namespace
{
// Sets (or, with nullptr, unsets) an environment variable for one scope.
class ScopedVariable
{
public:
  ScopedVariable(const char* name, const char* value)
    : Name(name)
  {
    if (const char* old = std::getenv(name))
    {
      Old = old;
      HadOld = true;
    }
    value ? setenv(name, value, 1) : unsetenv(name);
  }
  ~ScopedVariable() { HadOld ? setenv(Name.c_str(), Old.c_str(), 1) : unsetenv(Name.c_str()); }

private:
  std::string Name, Old;
  bool HadOld = false;
};

// Every launcher variable unset, and no override, for one scope.
struct CleanEnvironment
{
  ScopedVariable ompi{ "OMPI_COMM_WORLD_LOCAL_RANK", nullptr }, mpich{ "MPI_LOCALRANKID", nullptr },
    mvapich{ "MV2_COMM_WORLD_LOCAL_RANK", nullptr }, pmi{ "PMI_LOCAL_RANK", nullptr },
    pals{ "PALS_LOCAL_RANKID", nullptr }, slurm{ "SLURM_LOCALID", nullptr },
    override{ "OCTORAY_CUDA_DEVICE", nullptr };
};
}

TEST(DeviceChoice, RanksSpreadOverAnyNumberOfDevices)
{
  CleanEnvironment clean;
  for (int devices = 1; devices <= 16; ++devices)
  {
    // Ranks 0..2N-1 on one host: each device serves exactly two of them.
    std::multiset<int> used;
    for (int rank = 0; rank < 2 * devices; ++rank)
    {
      const int device = ChooseCudaDevice(-1, rank, devices);
      ASSERT_GE(device, 0);
      ASSERT_LT(device, devices);
      used.insert(device);
    }
    for (int d = 0; d < devices; ++d)
    {
      EXPECT_EQ(used.count(d), 2u) << devices << " devices, device " << d;
    }
  }
  EXPECT_EQ(ChooseCudaDevice(-1, 5, 4), 1);
  EXPECT_EQ(ChooseCudaDevice(-1, -1, 4), 0) << "no known rank: the first device";
  EXPECT_EQ(ChooseCudaDevice(-1, 3, 0), -1) << "no device at all";
}

TEST(DeviceChoice, SettingAndVariableOverrideTheRank)
{
  CleanEnvironment clean;
  EXPECT_EQ(ChooseCudaDevice(2, 1, 4), 2);
  EXPECT_EQ(ChooseCudaDevice(6, 1, 4), 2) << "past the devices: wraps like a rank";
  ScopedVariable chosen("OCTORAY_CUDA_DEVICE", "3");
  EXPECT_EQ(ChooseCudaDevice(-1, 1, 4), 3);
  EXPECT_EQ(ChooseCudaDevice(0, 1, 4), 0) << "the setting wins over the variable";
  ScopedVariable junk("OCTORAY_CUDA_DEVICE", "gpu1");
  EXPECT_EQ(ChooseCudaDevice(-1, 1, 4), 1) << "a value that is no index is ignored";
}

TEST(DeviceChoice, LocalRankFromEachLauncher)
{
  CleanEnvironment clean;
  EXPECT_EQ(LocalRankFromEnvironment(), -1);
  for (const char* name : kLocalRankVariables)
  {
    ScopedVariable rank(name, "7");
    EXPECT_EQ(LocalRankFromEnvironment(), 7) << name;
  }
  {
    ScopedVariable ompi("OMPI_COMM_WORLD_LOCAL_RANK", "2");
    ScopedVariable slurm("SLURM_LOCALID", "5");
    EXPECT_EQ(LocalRankFromEnvironment(), 2) << "the MPI launcher's own word comes first";
  }
  for (const char* bad : { "", "-1", "x", "3x", "99999999999" })
  {
    ScopedVariable rank("MPI_LOCALRANKID", bad);
    EXPECT_EQ(LocalRankFromEnvironment(), -1) << "'" << bad << "'";
  }
}
