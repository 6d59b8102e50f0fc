// octoray engine: compiler glue shared by the CPU and CUDA backends.
#pragma once

#include <cstddef>
#include <cstdint>

// Functions that run per point, per node or per pixel are written once and
// marked OCTORAY_HD: host-and-device under nvcc, plain inline C++ otherwise.
#if defined(__CUDACC__)
#define OCTORAY_HD __host__ __device__ __forceinline__
#define OCTORAY_DEVICE_CODE 1
#else
#define OCTORAY_HD inline
#define OCTORAY_DEVICE_CODE 0
#endif

namespace octoray
{
// Deepest level of the octree: 21 bits per axis fill a 63-bit Morton key.
constexpr int kMaxLevel = 21;
constexpr std::uint32_t kInvalidIndex = 0xFFFFFFFFu;
}
