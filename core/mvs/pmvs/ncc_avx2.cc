// AVX2 + FMA NCC sums; this translation unit alone is compiled with RECONAR_AVX2_FLAGS and is only
// called once the CPU reports AVX2 and FMA (ncc.cc). One 8-lane block per step.
#include <immintrin.h>

#include "core/base/horizontal_sum_avx2.h"
#include "core/mvs/pmvs/ncc_kernels.h"

namespace reconar::internal {

NccSums NccSumsAvx2(const float* normalized_reference, const float* samples, int padded_count) {
  __m256 sum = _mm256_setzero_ps(), sum_squares = _mm256_setzero_ps(), sum_products = _mm256_setzero_ps();
  for (int i = 0; i < padded_count; i += 8) {
    const __m256 b = _mm256_loadu_ps(samples + i);
    const __m256 r = _mm256_loadu_ps(normalized_reference + i);
    sum = _mm256_add_ps(sum, b);
    sum_squares = _mm256_fmadd_ps(b, b, sum_squares);
    sum_products = _mm256_fmadd_ps(r, b, sum_products);
  }
  NccSums s;
  s.sum = HorizontalSumAvx2(sum);
  s.sum_squares = HorizontalSumAvx2(sum_squares);
  s.sum_products = HorizontalSumAvx2(sum_products);
  return s;
}

}  // namespace reconar::internal
