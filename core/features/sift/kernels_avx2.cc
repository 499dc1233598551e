// AVX2 + FMA versions of the SIFT kernels; compiled with -mavx2 -mfma, used only when the CPU
// reports both. Tails shorter than a vector fall back to the reference.
#include <immintrin.h>

#include "core/features/sift/kernels.h"

namespace reconar {
namespace {

void ConvolveColumnsAvx2(const float* const* rows, const float* k, int r, int width, float* out) {
  const float* centre = rows[r];
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    const __m256 k0 = _mm256_set1_ps(k[0]);
    __m256 acc0 = _mm256_mul_ps(k0, _mm256_loadu_ps(centre + x));
    __m256 acc1 = _mm256_mul_ps(k0, _mm256_loadu_ps(centre + x + 8));
    for (int i = 1; i <= r; ++i) {
      const __m256 ki = _mm256_set1_ps(k[i]);
      const float* up = rows[r - i] + x;
      const float* down = rows[r + i] + x;
      acc0 = _mm256_fmadd_ps(ki, _mm256_add_ps(_mm256_loadu_ps(up), _mm256_loadu_ps(down)), acc0);
      acc1 = _mm256_fmadd_ps(ki, _mm256_add_ps(_mm256_loadu_ps(up + 8), _mm256_loadu_ps(down + 8)), acc1);
    }
    _mm256_storeu_ps(out + x, acc0);
    _mm256_storeu_ps(out + x + 8, acc1);
  }
  if (x < width) sift_internal::ConvolveColumnsTail(rows, k, r, x, width, out);
}

// Input row j = rows[j] contributes k[|j - r|] to out0 and k[|j - r - 1|] to out1.
void ConvolveColumns2Avx2(const float* const* rows, const float* k, int r, int width, float* out0, float* out1) {
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    __m256 a0 = _mm256_setzero_ps(), a1 = _mm256_setzero_ps();
    __m256 b0 = _mm256_setzero_ps(), b1 = _mm256_setzero_ps();
    for (int j = 0; j <= 2 * r + 1; ++j) {
      const __m256 v0 = _mm256_loadu_ps(rows[j] + x);
      const __m256 v1 = _mm256_loadu_ps(rows[j] + x + 8);
      if (j <= 2 * r) {
        const __m256 ka = _mm256_set1_ps(k[j > r ? j - r : r - j]);
        a0 = _mm256_fmadd_ps(ka, v0, a0);
        a1 = _mm256_fmadd_ps(ka, v1, a1);
      }
      if (j >= 1) {
        const __m256 kb = _mm256_set1_ps(k[j - 1 > r ? j - 1 - r : r + 1 - j]);
        b0 = _mm256_fmadd_ps(kb, v0, b0);
        b1 = _mm256_fmadd_ps(kb, v1, b1);
      }
    }
    _mm256_storeu_ps(out0 + x, a0);
    _mm256_storeu_ps(out0 + x + 8, a1);
    _mm256_storeu_ps(out1 + x, b0);
    _mm256_storeu_ps(out1 + x + 8, b1);
  }
  if (x < width) sift_internal::ConvolveColumns2Tail(rows, k, r, x, width, out0, out1);
}

void ConvolveRowAvx2(const float* in, const float* k, int r, int width, float* out) {
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    const __m256 k0 = _mm256_set1_ps(k[0]);
    __m256 acc0 = _mm256_mul_ps(k0, _mm256_loadu_ps(in + x));
    __m256 acc1 = _mm256_mul_ps(k0, _mm256_loadu_ps(in + x + 8));
    for (int i = 1; i <= r; ++i) {
      const __m256 ki = _mm256_set1_ps(k[i]);
      acc0 = _mm256_fmadd_ps(ki, _mm256_add_ps(_mm256_loadu_ps(in + x - i), _mm256_loadu_ps(in + x + i)), acc0);
      acc1 = _mm256_fmadd_ps(
          ki, _mm256_add_ps(_mm256_loadu_ps(in + x + 8 - i), _mm256_loadu_ps(in + x + 8 + i)), acc1);
    }
    _mm256_storeu_ps(out + x, acc0);
    _mm256_storeu_ps(out + x + 8, acc1);
  }
  if (x < width) ScalarSiftKernels().convolve_row(in + x, k, r, width - x, out + x);
}

void DifferenceOfGaussiansAvx2(const float* const* g, int width, float* const* out) {
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    const auto g0 = _mm256_loadu_ps(g[0] + x);
    const auto g1 = _mm256_loadu_ps(g[1] + x);
    const auto g2 = _mm256_loadu_ps(g[2] + x);
    const auto g3 = _mm256_loadu_ps(g[3] + x);
    _mm256_storeu_ps(out[0] + x, _mm256_sub_ps(g1, g0));
    _mm256_storeu_ps(out[1] + x, _mm256_sub_ps(g2, g1));
    _mm256_storeu_ps(out[2] + x, _mm256_sub_ps(g3, g2));
  }
  for (; x < width; ++x) {
    out[0][x] = g[1][x] - g[0][x];
    out[1][x] = g[2][x] - g[1][x];
    out[2][x] = g[3][x] - g[2][x];
  }
}

int FindExtremaAvx2(const float* const* dog, int x_begin, int x_end, float threshold, int32_t* out_x) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 thr = _mm256_set1_ps(threshold);
  const __m256 sign_mask = _mm256_set1_ps(-0.0f);
  int count = 0;
  int x = x_begin;
  for (; x + 8 <= x_end; x += 8) {
    const __m256 v = _mm256_loadu_ps(dog[4] + x);
    const __m256 strong = _mm256_cmp_ps(_mm256_andnot_ps(sign_mask, v), thr, _CMP_GT_OQ);
    if (_mm256_movemask_ps(strong) == 0) continue;
    __m256 hi = _mm256_max_ps(_mm256_loadu_ps(dog[4] + x - 1), _mm256_loadu_ps(dog[4] + x + 1));
    __m256 lo = _mm256_min_ps(_mm256_loadu_ps(dog[4] + x - 1), _mm256_loadu_ps(dog[4] + x + 1));
    for (int j = 0; j < 9; ++j) {
      if (j == 4) continue;
      const __m256 a = _mm256_loadu_ps(dog[j] + x - 1);
      const __m256 b = _mm256_loadu_ps(dog[j] + x);
      const __m256 c = _mm256_loadu_ps(dog[j] + x + 1);
      hi = _mm256_max_ps(hi, _mm256_max_ps(a, _mm256_max_ps(b, c)));
      lo = _mm256_min_ps(lo, _mm256_min_ps(a, _mm256_min_ps(b, c)));
    }
    const __m256 is_max = _mm256_and_ps(_mm256_cmp_ps(v, zero, _CMP_GT_OQ), _mm256_cmp_ps(v, hi, _CMP_GE_OQ));
    const __m256 is_min = _mm256_and_ps(_mm256_cmp_ps(v, zero, _CMP_LT_OQ), _mm256_cmp_ps(v, lo, _CMP_LE_OQ));
    int mask = _mm256_movemask_ps(_mm256_and_ps(strong, _mm256_or_ps(is_max, is_min)));
    while (mask != 0) {
      const int bit = __builtin_ctz(static_cast<unsigned>(mask));
      out_x[count++] = x + bit;
      mask &= mask - 1;
    }
  }
  if (x < x_end) count += ScalarSiftKernels().find_extrema(dog, x, x_end, threshold, out_x + count);
  return count;
}

void GradientRowAvx2(const float* above, const float* row, const float* below, int x_begin, int x_end,
                     float* magnitude, float* angle) {
  using namespace sift_internal;
  const __m256 sign_mask = _mm256_set1_ps(-0.0f);
  const __m256 zero = _mm256_setzero_ps();
  const __m256 half_pi = _mm256_set1_ps(0.5f * kPi);
  const __m256 pi = _mm256_set1_ps(kPi);
  const __m256 two_pi = _mm256_set1_ps(2.0f * kPi);
  int x = x_begin;
  for (; x + 8 <= x_end; x += 8) {
    const __m256 dx = _mm256_sub_ps(_mm256_loadu_ps(row + x + 1), _mm256_loadu_ps(row + x - 1));
    const __m256 dy = _mm256_sub_ps(_mm256_loadu_ps(below + x), _mm256_loadu_ps(above + x));
    _mm256_storeu_ps(magnitude + (x - x_begin), _mm256_sqrt_ps(_mm256_fmadd_ps(dx, dx, _mm256_mul_ps(dy, dy))));
    const __m256 ax = _mm256_andnot_ps(sign_mask, dx);
    const __m256 ay = _mm256_andnot_ps(sign_mask, dy);
    const __m256 num = _mm256_min_ps(ax, ay);
    const __m256 den = _mm256_max_ps(ax, ay);
    const __m256 z = _mm256_and_ps(_mm256_div_ps(num, den), _mm256_cmp_ps(den, zero, _CMP_GT_OQ));
    const __m256 z2 = _mm256_mul_ps(z, z);
    __m256 p = _mm256_fmadd_ps(z2, _mm256_set1_ps(kAtanC11), _mm256_set1_ps(kAtanC9));
    p = _mm256_fmadd_ps(z2, p, _mm256_set1_ps(kAtanC7));
    p = _mm256_fmadd_ps(z2, p, _mm256_set1_ps(kAtanC5));
    p = _mm256_fmadd_ps(z2, p, _mm256_set1_ps(kAtanC3));
    p = _mm256_fmadd_ps(z2, p, _mm256_set1_ps(kAtanC1));
    __m256 a = _mm256_mul_ps(z, p);
    a = _mm256_blendv_ps(a, _mm256_sub_ps(half_pi, a), _mm256_cmp_ps(ay, ax, _CMP_GT_OQ));
    a = _mm256_blendv_ps(a, _mm256_sub_ps(pi, a), _mm256_cmp_ps(dx, zero, _CMP_LT_OQ));
    a = _mm256_blendv_ps(a, _mm256_sub_ps(two_pi, a), _mm256_cmp_ps(dy, zero, _CMP_LT_OQ));
    a = _mm256_blendv_ps(a, _mm256_sub_ps(a, two_pi), _mm256_cmp_ps(a, two_pi, _CMP_GE_OQ));
    _mm256_storeu_ps(angle + (x - x_begin), a);
  }
  if (x < x_end) {
    ScalarSiftKernels().gradient_row(above, row, below, x, x_end, magnitude + (x - x_begin),
                                        angle + (x - x_begin));
  }
}

}  // namespace

const SiftKernels& sift_internal::Avx2SiftKernels() {
  static const SiftKernels kernels{"avx2", ConvolveColumnsAvx2, ConvolveColumns2Avx2, ConvolveRowAvx2, DifferenceOfGaussiansAvx2, FindExtremaAvx2,
                                   GradientRowAvx2};
  return kernels;
}

}  // namespace reconar
