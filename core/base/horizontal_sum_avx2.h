#pragma once
// The sum of the eight lanes of an AVX register, for the AVX2 kernels (include only from
// translation units compiled with RECONAR_AVX2_FLAGS).
#include <immintrin.h>

namespace reconar {

inline float HorizontalSumAvx2(__m256 v) {
  __m128 s = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  s = _mm_add_ps(s, _mm_movehl_ps(s, s));
  s = _mm_add_ss(s, _mm_shuffle_ps(s, s, 1));
  return _mm_cvtss_f32(s);
}

}  // namespace reconar
