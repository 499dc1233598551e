// AVX2 + FMA warp sums; this translation unit alone is compiled with RECONAR_AVX2_FLAGS and is only
// called once the CPU reports AVX2 and FMA (warp_sums.cc). Eight samples per step: the homography
// in lanes; the bilinear corners by four gathers of horizontal pixel pairs (64 bits, four lanes
// each: half the gathered elements of one gather per corner), the pairs split by shuffles.
#include <immintrin.h>

#include "core/base/horizontal_sum_avx2.h"
#include "core/mvs/patchmatch/warp_sums_types.h"

namespace reconar::internal {

WarpSums WarpSumsAvx2(const WarpHomography& h, const WarpWindow& window, const float* image, int stride) {
  const __m256 h0x = _mm256_set1_ps(h.h0x), h0y = _mm256_set1_ps(h.h0y), h0z = _mm256_set1_ps(h.h0z);
  const __m256 c0x = _mm256_set1_ps(h.c0x), c0y = _mm256_set1_ps(h.c0y), c0z = _mm256_set1_ps(h.c0z);
  const __m256 c1x = _mm256_set1_ps(h.c1x), c1y = _mm256_set1_ps(h.c1y), c1z = _mm256_set1_ps(h.c1z);
  const __m256i row = _mm256_set1_epi32(stride);
  const __m256i order = _mm256_setr_epi32(0, 1, 4, 5, 2, 3, 6, 7);
  const long long* pairs = reinterpret_cast<const long long*>(image);  // NOLINT: gathered at 4-byte steps
  __m256 sum = _mm256_setzero_ps(), sum_squares = _mm256_setzero_ps(), sum_products = _mm256_setzero_ps();
  for (int j = 0; j < window.padded_count; j += 8) {
    const __m256 ox = _mm256_loadu_ps(window.offset_x + j), oy = _mm256_loadu_ps(window.offset_y + j);
    const __m256 z = _mm256_fmadd_ps(c1z, oy, _mm256_fmadd_ps(c0z, ox, h0z));
    const __m256 inverse_z = _mm256_div_ps(_mm256_set1_ps(1.0f), z);
    const __m256 u = _mm256_mul_ps(_mm256_fmadd_ps(c1x, oy, _mm256_fmadd_ps(c0x, ox, h0x)), inverse_z);
    const __m256 v = _mm256_mul_ps(_mm256_fmadd_ps(c1y, oy, _mm256_fmadd_ps(c0y, ox, h0y)), inverse_z);
    const __m256i u0 = _mm256_cvttps_epi32(u), v0 = _mm256_cvttps_epi32(v);
    const __m256 au = _mm256_sub_ps(u, _mm256_cvtepi32_ps(u0)), av = _mm256_sub_ps(v, _mm256_cvtepi32_ps(v0));
    // Samples 0, 1, 4, 5 in the low half and 2, 3, 6, 7 in the high one, so that the in-lane
    // shuffles of the two gathers' pairs give the samples back in order.
    const __m256i index = _mm256_permutevar8x32_epi32(_mm256_add_epi32(_mm256_mullo_epi32(v0, row), u0), order);
    const __m256i below = _mm256_add_epi32(index, row);
    const __m256 top_a = _mm256_castsi256_ps(_mm256_i32gather_epi64(pairs, _mm256_castsi256_si128(index), 4));
    const __m256 top_b = _mm256_castsi256_ps(_mm256_i32gather_epi64(pairs, _mm256_extracti128_si256(index, 1), 4));
    const __m256 bottom_a = _mm256_castsi256_ps(_mm256_i32gather_epi64(pairs, _mm256_castsi256_si128(below), 4));
    const __m256 bottom_b = _mm256_castsi256_ps(_mm256_i32gather_epi64(pairs, _mm256_extracti128_si256(below, 1), 4));
    const __m256 p00 = _mm256_shuffle_ps(top_a, top_b, _MM_SHUFFLE(2, 0, 2, 0));
    const __m256 p01 = _mm256_shuffle_ps(top_a, top_b, _MM_SHUFFLE(3, 1, 3, 1));
    const __m256 p10 = _mm256_shuffle_ps(bottom_a, bottom_b, _MM_SHUFFLE(2, 0, 2, 0));
    const __m256 p11 = _mm256_shuffle_ps(bottom_a, bottom_b, _MM_SHUFFLE(3, 1, 3, 1));
    const __m256 top = _mm256_fmadd_ps(au, _mm256_sub_ps(p01, p00), p00);
    const __m256 bottom = _mm256_fmadd_ps(au, _mm256_sub_ps(p11, p10), p10);
    const __m256 value = _mm256_fmadd_ps(av, _mm256_sub_ps(bottom, top), top);
    const __m256 weighted = _mm256_mul_ps(_mm256_loadu_ps(window.weights + j), value);
    sum = _mm256_add_ps(sum, weighted);
    sum_squares = _mm256_fmadd_ps(weighted, value, sum_squares);
    sum_products = _mm256_fmadd_ps(weighted, _mm256_loadu_ps(window.reference + j), sum_products);
  }
  WarpSums s;
  s.sum = HorizontalSumAvx2(sum);
  s.sum_squares = HorizontalSumAvx2(sum_squares);
  s.sum_products = HorizontalSumAvx2(sum_products);
  return s;
}

}  // namespace reconar::internal
