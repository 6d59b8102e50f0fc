#include "Scalar16.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define OCTORAY_UNIT_CODES_AVX2 1
#endif

namespace octoray
{
namespace
{
void EncodeEach(const float* values, std::size_t n, std::uint16_t* codes)
{
  for (std::size_t i = 0; i < n; ++i)
  {
    codes[i] = EncodeUnitScalar(values[i]).code;
  }
}

#if OCTORAY_UNIT_CODES_AVX2
// EncodeUnitScalar's arithmetic on sixteen values at a time: clamped,
// scaled, a half added and truncated (floor, for these non-negative
// values), packed into 16 bits. Returns how many values it coded: none
// where one of them is NaN or infinite, which EncodeEach then codes.
__attribute__((target("avx2"))) std::size_t EncodeFiniteAvx2(const float* values, std::size_t n,
  std::uint16_t* codes)
{
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 steps = _mm256_set1_ps(static_cast<float>(kScalarSteps)), half = _mm256_set1_ps(0.5f);
  const __m256i exponent = _mm256_set1_epi32(0x7F800000);
  __m256i nonFinite = _mm256_setzero_si256();
  std::size_t i = 0;
  for (; i + 16 <= n; i += 16)
  {
    __m256i eighth[2];
    for (int h = 0; h < 2; ++h)
    {
      const __m256 u = _mm256_loadu_ps(values + i + 8 * h);
      const __m256i bits = _mm256_and_si256(_mm256_castps_si256(u), exponent);
      nonFinite = _mm256_or_si256(nonFinite, _mm256_cmpeq_epi32(bits, exponent));
      const __m256 clamped = _mm256_min_ps(_mm256_max_ps(u, zero), one);
      eighth[h] = _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(clamped, steps), half));
    }
    // packus interleaves the two halves by 128-bit lane; the permute puts them back in order.
    const __m256i packed = _mm256_permute4x64_epi64(_mm256_packus_epi32(eighth[0], eighth[1]), 0xD8);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(codes + i), packed);
  }
  return _mm256_testz_si256(nonFinite, nonFinite) ? i : 0;
}
#endif
}

// Sixteen threads code as fast as they copy the floats so, one thread at
// 1.3-1.4 times a memcpy's time on an H200's host (hence the staging's
// pieces of codes half as long: StagingPieces.h). GCC's own vectorisation
// of this coding (SSE2, with -fno-trapping-math) was slower than the copy
// it replaced: a staged build of 10 M points with reflectivity took 2.15-2.45
// times the pinned copy so, where the floats' copy took 1.51-1.61
// (Benchmarks/gpu/variants-unit-codes.txt, scripts/gpu/unit-codes-host.cpp).
// CPUs without AVX2 code one value at a time. The tests hold both paths to
// the same codes (Scalar16.CodesOfManyValuesAreTheCodesOfEach).
void EncodeUnitScalars(const float* values, std::size_t n, std::uint16_t* codes)
{
  std::size_t done = 0;
#if OCTORAY_UNIT_CODES_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2");
  done = avx2 ? EncodeFiniteAvx2(values, n, codes) : 0;
#endif
  EncodeEach(values + done, n - done, codes + done);
}
}
