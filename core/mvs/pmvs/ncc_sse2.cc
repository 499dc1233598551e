// SSE2 NCC sums (baseline on x86-64): two 4-lane blocks per step.
#include <emmintrin.h>

#include "core/mvs/pmvs/ncc_kernels.h"

namespace reconar::internal {
namespace {

inline float HorizontalSum(__m128 v) {
  v = _mm_add_ps(v, _mm_movehl_ps(v, v));
  v = _mm_add_ss(v, _mm_shuffle_ps(v, v, 1));
  return _mm_cvtss_f32(v);
}

}  // namespace

NccSums NccSumsSse2(const float* normalized_reference, const float* samples, int padded_count) {
  __m128 sum = _mm_setzero_ps(), sum_squares = _mm_setzero_ps(), sum_products = _mm_setzero_ps();
  for (int i = 0; i < padded_count; i += 4) {
    const __m128 b = _mm_loadu_ps(samples + i);
    const __m128 r = _mm_loadu_ps(normalized_reference + i);
    sum = _mm_add_ps(sum, b);
    sum_squares = _mm_add_ps(sum_squares, _mm_mul_ps(b, b));
    sum_products = _mm_add_ps(sum_products, _mm_mul_ps(r, b));
  }
  NccSums s;
  s.sum = HorizontalSum(sum);
  s.sum_squares = HorizontalSum(sum_squares);
  s.sum_products = HorizontalSum(sum_products);
  return s;
}

}  // namespace reconar::internal
