// AVX-512F versions of the blur, DoG and extrema kernels; compiled with -mavx512f, used only when
// the CPU reports AVX-512F. The gradient kernel is shared with the AVX2 table. Tails shorter than
// a vector fall back to the reference.
#include <immintrin.h>

#include "core/features/sift/kernels.h"

namespace reconar {
namespace {

// GCC 12's _mm512_max_ps/_mm512_min_ps pass an undefined vector as the merge source, which
// -Wmaybe-uninitialized reports; the masked forms with an explicit source compute the same.
inline __m512 Max(__m512 a, __m512 b) { return _mm512_mask_max_ps(a, 0xFFFF, a, b); }
inline __m512 Min(__m512 a, __m512 b) { return _mm512_mask_min_ps(a, 0xFFFF, a, b); }

void ConvolveColumnsAvx512(const float* const* rows, const float* k, int r, int width, float* out) {
  const float* centre = rows[r];
  int x = 0;
  for (; x + 32 <= width; x += 32) {
    const __m512 k0 = _mm512_set1_ps(k[0]);
    __m512 acc0 = _mm512_mul_ps(k0, _mm512_loadu_ps(centre + x));
    __m512 acc1 = _mm512_mul_ps(k0, _mm512_loadu_ps(centre + x + 16));
    for (int i = 1; i <= r; ++i) {
      const __m512 ki = _mm512_set1_ps(k[i]);
      const float* up = rows[r - i] + x;
      const float* down = rows[r + i] + x;
      acc0 = _mm512_fmadd_ps(ki, _mm512_add_ps(_mm512_loadu_ps(up), _mm512_loadu_ps(down)), acc0);
      acc1 = _mm512_fmadd_ps(ki, _mm512_add_ps(_mm512_loadu_ps(up + 16), _mm512_loadu_ps(down + 16)), acc1);
    }
    _mm512_storeu_ps(out + x, acc0);
    _mm512_storeu_ps(out + x + 16, acc1);
  }
  if (x < width) sift_internal::ConvolveColumnsTail(rows, k, r, x, width, out);
}

// Input row j = rows[j] contributes k[|j - r|] to out0 and k[|j - r - 1|] to out1.
void ConvolveColumns2Avx512(const float* const* rows, const float* k, int r, int width, float* out0,
                            float* out1) {
  int x = 0;
  for (; x + 32 <= width; x += 32) {
    __m512 a0 = _mm512_setzero_ps(), a1 = _mm512_setzero_ps();
    __m512 b0 = _mm512_setzero_ps(), b1 = _mm512_setzero_ps();
    for (int j = 0; j <= 2 * r + 1; ++j) {
      const __m512 v0 = _mm512_loadu_ps(rows[j] + x);
      const __m512 v1 = _mm512_loadu_ps(rows[j] + x + 16);
      if (j <= 2 * r) {
        const __m512 ka = _mm512_set1_ps(k[j > r ? j - r : r - j]);
        a0 = _mm512_fmadd_ps(ka, v0, a0);
        a1 = _mm512_fmadd_ps(ka, v1, a1);
      }
      if (j >= 1) {
        const __m512 kb = _mm512_set1_ps(k[j - 1 > r ? j - 1 - r : r + 1 - j]);
        b0 = _mm512_fmadd_ps(kb, v0, b0);
        b1 = _mm512_fmadd_ps(kb, v1, b1);
      }
    }
    _mm512_storeu_ps(out0 + x, a0);
    _mm512_storeu_ps(out0 + x + 16, a1);
    _mm512_storeu_ps(out1 + x, b0);
    _mm512_storeu_ps(out1 + x + 16, b1);
  }
  if (x < width) sift_internal::ConvolveColumns2Tail(rows, k, r, x, width, out0, out1);
}

void ConvolveRowAvx512(const float* in, const float* k, int r, int width, float* out) {
  int x = 0;
  for (; x + 32 <= width; x += 32) {
    const __m512 k0 = _mm512_set1_ps(k[0]);
    __m512 acc0 = _mm512_mul_ps(k0, _mm512_loadu_ps(in + x));
    __m512 acc1 = _mm512_mul_ps(k0, _mm512_loadu_ps(in + x + 16));
    for (int i = 1; i <= r; ++i) {
      const __m512 ki = _mm512_set1_ps(k[i]);
      acc0 = _mm512_fmadd_ps(ki, _mm512_add_ps(_mm512_loadu_ps(in + x - i), _mm512_loadu_ps(in + x + i)), acc0);
      acc1 = _mm512_fmadd_ps(
          ki, _mm512_add_ps(_mm512_loadu_ps(in + x + 16 - i), _mm512_loadu_ps(in + x + 16 + i)), acc1);
    }
    _mm512_storeu_ps(out + x, acc0);
    _mm512_storeu_ps(out + x + 16, acc1);
  }
  if (x < width) ScalarSiftKernels().convolve_row(in + x, k, r, width - x, out + x);
}

void DifferenceOfGaussiansAvx512(const float* const* g, int width, float* const* out) {
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    const auto g0 = _mm512_loadu_ps(g[0] + x);
    const auto g1 = _mm512_loadu_ps(g[1] + x);
    const auto g2 = _mm512_loadu_ps(g[2] + x);
    const auto g3 = _mm512_loadu_ps(g[3] + x);
    _mm512_storeu_ps(out[0] + x, _mm512_sub_ps(g1, g0));
    _mm512_storeu_ps(out[1] + x, _mm512_sub_ps(g2, g1));
    _mm512_storeu_ps(out[2] + x, _mm512_sub_ps(g3, g2));
  }
  for (; x < width; ++x) {
    out[0][x] = g[1][x] - g[0][x];
    out[1][x] = g[2][x] - g[1][x];
    out[2][x] = g[3][x] - g[2][x];
  }
}

int FindExtremaAvx512(const float* const* dog, int x_begin, int x_end, float threshold, int32_t* out_x) {
  const __m512 zero = _mm512_setzero_ps();
  const __m512 thr = _mm512_set1_ps(threshold);
  int count = 0;
  int x = x_begin;
  for (; x + 16 <= x_end; x += 16) {
    const __m512 v = _mm512_loadu_ps(dog[4] + x);
    const __mmask16 strong = _mm512_cmp_ps_mask(_mm512_abs_ps(v), thr, _CMP_GT_OQ);
    if (strong == 0) continue;
    __m512 hi = Max(_mm512_loadu_ps(dog[4] + x - 1), _mm512_loadu_ps(dog[4] + x + 1));
    __m512 lo = Min(_mm512_loadu_ps(dog[4] + x - 1), _mm512_loadu_ps(dog[4] + x + 1));
    for (int j = 0; j < 9; ++j) {
      if (j == 4) continue;
      const __m512 a = _mm512_loadu_ps(dog[j] + x - 1);
      const __m512 b = _mm512_loadu_ps(dog[j] + x);
      const __m512 c = _mm512_loadu_ps(dog[j] + x + 1);
      hi = Max(hi, Max(a, Max(b, c)));
      lo = Min(lo, Min(a, Min(b, c)));
    }
    const __mmask16 is_max =
        _mm512_cmp_ps_mask(v, zero, _CMP_GT_OQ) & _mm512_cmp_ps_mask(v, hi, _CMP_GE_OQ);
    const __mmask16 is_min =
        _mm512_cmp_ps_mask(v, zero, _CMP_LT_OQ) & _mm512_cmp_ps_mask(v, lo, _CMP_LE_OQ);
    unsigned mask = static_cast<unsigned>(strong & (is_max | is_min));
    while (mask != 0) {
      out_x[count++] = x + __builtin_ctz(mask);
      mask &= mask - 1;
    }
  }
  if (x < x_end) count += ScalarSiftKernels().find_extrema(dog, x, x_end, threshold, out_x + count);
  return count;
}

}  // namespace

const SiftKernels& sift_internal::Avx512SiftKernels() {
  static const SiftKernels kernels{"avx512",       ConvolveColumnsAvx512, ConvolveColumns2Avx512,
                                   ConvolveRowAvx512, DifferenceOfGaussiansAvx512,     FindExtremaAvx512,
                                   Avx2SiftKernels().gradient_row};
  return kernels;
}

}  // namespace reconar
