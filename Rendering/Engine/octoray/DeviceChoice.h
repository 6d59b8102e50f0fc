// Which CUDA device a process draws with. Ranks of a parallel job (pvbatch
// under mpiexec, one rank per GPU) on a host with several GPUs spread over
// them by their rank on that host; a setting or OCTORAY_CUDA_DEVICE
// overrides the choice. Host-only and CUDA-free, so it is tested anywhere.
#pragma once

#include <cstdlib>
#include <string>

namespace octoray
{
// What MPI launchers and batch systems export for a process's rank among
// the processes on its own host, in the order they are looked up.
inline const char* const kLocalRankVariables[] = {
  "OMPI_COMM_WORLD_LOCAL_RANK", // Open MPI
  "MPI_LOCALRANKID",            // MPICH (Hydra), Intel MPI
  "MV2_COMM_WORLD_LOCAL_RANK",  // MVAPICH2
  "PMI_LOCAL_RANK",             // PMI-2 launchers
  "PALS_LOCAL_RANKID",          // HPE Cray PALS
  "SLURM_LOCALID",              // srun
};

// A non-negative integer from `text`, or -1.
inline int ParseIndex(const char* text)
{
  if (!text || !*text)
  {
    return -1;
  }
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  return (*end == '\0' && value >= 0 && value < (1L << 30)) ? static_cast<int>(value) : -1;
}

// The process's rank on its host from the launcher's environment; -1 when
// no launcher says (a serial run, or a launcher we do not know).
inline int LocalRankFromEnvironment()
{
  for (const char* name : kLocalRankVariables)
  {
    const int rank = ParseIndex(std::getenv(name));
    if (rank >= 0)
    {
      return rank;
    }
  }
  return -1;
}

// The device to use among `deviceCount`: `requested` when it is a valid
// index (the caller's setting, else OCTORAY_CUDA_DEVICE), otherwise
// localRank % deviceCount (rank 0 when unknown). -1 when there is no device.
// A requested index past the devices wraps like a rank, so that a script
// written for an 8-GPU host still runs on a 2-GPU one.
inline int ChooseCudaDevice(int requested, int localRank, int deviceCount)
{
  if (deviceCount <= 0)
  {
    return -1;
  }
  if (requested < 0)
  {
    requested = ParseIndex(std::getenv("OCTORAY_CUDA_DEVICE"));
  }
  if (requested >= 0)
  {
    return requested % deviceCount;
  }
  return (localRank < 0 ? 0 : localRank) % deviceCount;
}
}
