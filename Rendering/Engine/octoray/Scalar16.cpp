#include "Scalar16.h"

#if defined(__SSE2__)
#include <emmintrin.h>
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
}

// EncodeUnitScalar's arithmetic on eight values at a time: clamped, scaled,
// a half added and truncated (floor, for these non-negative values), packed
// into 16 bits; where any value of the run is NaN or infinite, the run is
// coded again one value at a time. GCC's own vectorisation of EncodeEach
// (SSE2, with -fno-trapping-math) took 5.4 ms for 10 M values where a
// memcpy of them took 3.2, a staging thread's piece then costing more than
// the bus saves; this takes 2.6 ms. The tests hold the two to the same
// codes (Scalar16.CodesOfManyValuesAreTheCodesOfEach).
void EncodeUnitScalars(const float* values, std::size_t n, std::uint16_t* codes)
{
  std::size_t i = 0;
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
  const __m128 steps = _mm_set1_ps(static_cast<float>(kScalarSteps)), half = _mm_set1_ps(0.5f);
  const __m128i exponent = _mm_set1_epi32(0x7F800000);
  // Codes up to 65532 pack as signed 16-bit values once offset by 32768.
  const __m128i offset = _mm_set1_epi32(32768);
  const __m128i flip = _mm_set1_epi16(static_cast<short>(0x8000));
  __m128i nonFinite = _mm_setzero_si128();
  for (; i + 8 <= n; i += 8)
  {
    __m128i quarter[2];
    for (int h = 0; h < 2; ++h)
    {
      const __m128 u = _mm_loadu_ps(values + i + 4 * h);
      const __m128i bits = _mm_and_si128(_mm_castps_si128(u), exponent);
      nonFinite = _mm_or_si128(nonFinite, _mm_cmpeq_epi32(bits, exponent));
      const __m128 clamped = _mm_min_ps(_mm_max_ps(u, zero), one);
      const __m128 scaled = _mm_add_ps(_mm_mul_ps(clamped, steps), half);
      quarter[h] = _mm_sub_epi32(_mm_cvttps_epi32(scaled), offset);
    }
    const __m128i packed = _mm_xor_si128(_mm_packs_epi32(quarter[0], quarter[1]), flip);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(codes + i), packed);
  }
  if (_mm_movemask_epi8(nonFinite))
  {
    i = 0;
  }
#endif
  EncodeEach(values + i, n - i, codes + i);
}
}
