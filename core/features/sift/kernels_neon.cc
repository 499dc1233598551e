// NEON versions of the SIFT kernels (baseline on aarch64). Tails fall back to the reference.
#include <arm_neon.h>

#include "core/features/sift/kernels.h"

namespace reconar {
namespace {

void ConvolveColumnsNeon(const float* const* rows, const float* k, int r, int width, float* out) {
  const float* centre = rows[r];
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    float32x4_t acc0 = vmulq_n_f32(vld1q_f32(centre + x), k[0]);
    float32x4_t acc1 = vmulq_n_f32(vld1q_f32(centre + x + 4), k[0]);
    for (int i = 1; i <= r; ++i) {
      const float* up = rows[r - i] + x;
      const float* down = rows[r + i] + x;
      acc0 = vfmaq_n_f32(acc0, vaddq_f32(vld1q_f32(up), vld1q_f32(down)), k[i]);
      acc1 = vfmaq_n_f32(acc1, vaddq_f32(vld1q_f32(up + 4), vld1q_f32(down + 4)), k[i]);
    }
    vst1q_f32(out + x, acc0);
    vst1q_f32(out + x + 4, acc1);
  }
  if (x < width) sift_internal::ConvolveColumnsTail(rows, k, r, x, width, out);
}

// Input row j = rows[j] contributes k[|j - r|] to out0 and k[|j - r - 1|] to out1.
void ConvolveColumns2Neon(const float* const* rows, const float* k, int r, int width, float* out0, float* out1) {
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    float32x4_t a0 = vdupq_n_f32(0.0f), a1 = vdupq_n_f32(0.0f);
    float32x4_t b0 = vdupq_n_f32(0.0f), b1 = vdupq_n_f32(0.0f);
    for (int j = 0; j <= 2 * r + 1; ++j) {
      const float32x4_t v0 = vld1q_f32(rows[j] + x);
      const float32x4_t v1 = vld1q_f32(rows[j] + x + 4);
      if (j <= 2 * r) {
        const float ka = k[j > r ? j - r : r - j];
        a0 = vfmaq_n_f32(a0, v0, ka);
        a1 = vfmaq_n_f32(a1, v1, ka);
      }
      if (j >= 1) {
        const float kb = k[j - 1 > r ? j - 1 - r : r + 1 - j];
        b0 = vfmaq_n_f32(b0, v0, kb);
        b1 = vfmaq_n_f32(b1, v1, kb);
      }
    }
    vst1q_f32(out0 + x, a0);
    vst1q_f32(out0 + x + 4, a1);
    vst1q_f32(out1 + x, b0);
    vst1q_f32(out1 + x + 4, b1);
  }
  if (x < width) sift_internal::ConvolveColumns2Tail(rows, k, r, x, width, out0, out1);
}

void ConvolveRowNeon(const float* in, const float* k, int r, int width, float* out) {
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    float32x4_t acc0 = vmulq_n_f32(vld1q_f32(in + x), k[0]);
    float32x4_t acc1 = vmulq_n_f32(vld1q_f32(in + x + 4), k[0]);
    for (int i = 1; i <= r; ++i) {
      acc0 = vfmaq_n_f32(acc0, vaddq_f32(vld1q_f32(in + x - i), vld1q_f32(in + x + i)), k[i]);
      acc1 = vfmaq_n_f32(acc1, vaddq_f32(vld1q_f32(in + x + 4 - i), vld1q_f32(in + x + 4 + i)), k[i]);
    }
    vst1q_f32(out + x, acc0);
    vst1q_f32(out + x + 4, acc1);
  }
  if (x < width) ScalarSiftKernels().convolve_row(in + x, k, r, width - x, out + x);
}

void DifferenceOfGaussiansNeon(const float* const* g, int width, float* const* out) {
  int x = 0;
  for (; x + 4 <= width; x += 4) {
    const auto g0 = vld1q_f32(g[0] + x);
    const auto g1 = vld1q_f32(g[1] + x);
    const auto g2 = vld1q_f32(g[2] + x);
    const auto g3 = vld1q_f32(g[3] + x);
    vst1q_f32(out[0] + x, vsubq_f32(g1, g0));
    vst1q_f32(out[1] + x, vsubq_f32(g2, g1));
    vst1q_f32(out[2] + x, vsubq_f32(g3, g2));
  }
  for (; x < width; ++x) {
    out[0][x] = g[1][x] - g[0][x];
    out[1][x] = g[2][x] - g[1][x];
    out[2][x] = g[3][x] - g[2][x];
  }
}

int FindExtremaNeon(const float* const* dog, int x_begin, int x_end, float threshold, int32_t* out_x) {
  const float32x4_t zero = vdupq_n_f32(0.0f);
  const float32x4_t thr = vdupq_n_f32(threshold);
  int count = 0;
  int x = x_begin;
  for (; x + 4 <= x_end; x += 4) {
    const float32x4_t v = vld1q_f32(dog[4] + x);
    const uint32x4_t strong = vcgtq_f32(vabsq_f32(v), thr);
    if (vmaxvq_u32(strong) == 0) continue;
    float32x4_t hi = vmaxq_f32(vld1q_f32(dog[4] + x - 1), vld1q_f32(dog[4] + x + 1));
    float32x4_t lo = vminq_f32(vld1q_f32(dog[4] + x - 1), vld1q_f32(dog[4] + x + 1));
    for (int j = 0; j < 9; ++j) {
      if (j == 4) continue;
      const float32x4_t a = vld1q_f32(dog[j] + x - 1);
      const float32x4_t b = vld1q_f32(dog[j] + x);
      const float32x4_t c = vld1q_f32(dog[j] + x + 1);
      hi = vmaxq_f32(hi, vmaxq_f32(a, vmaxq_f32(b, c)));
      lo = vminq_f32(lo, vminq_f32(a, vminq_f32(b, c)));
    }
    const uint32x4_t is_max = vandq_u32(vcgtq_f32(v, zero), vcgeq_f32(v, hi));
    const uint32x4_t is_min = vandq_u32(vcltq_f32(v, zero), vcleq_f32(v, lo));
    uint32_t lanes[4];
    vst1q_u32(lanes, vandq_u32(strong, vorrq_u32(is_max, is_min)));
    for (int i = 0; i < 4; ++i) {
      if (lanes[i] != 0) out_x[count++] = x + i;
    }
  }
  if (x < x_end) count += ScalarSiftKernels().find_extrema(dog, x, x_end, threshold, out_x + count);
  return count;
}

void GradientRowNeon(const float* above, const float* row, const float* below, int x_begin, int x_end,
                     float* magnitude, float* angle) {
  using namespace sift_internal;
  const float32x4_t zero = vdupq_n_f32(0.0f);
  const float32x4_t half_pi = vdupq_n_f32(0.5f * kPi);
  const float32x4_t pi = vdupq_n_f32(kPi);
  const float32x4_t two_pi = vdupq_n_f32(2.0f * kPi);
  int x = x_begin;
  for (; x + 4 <= x_end; x += 4) {
    const float32x4_t dx = vsubq_f32(vld1q_f32(row + x + 1), vld1q_f32(row + x - 1));
    const float32x4_t dy = vsubq_f32(vld1q_f32(below + x), vld1q_f32(above + x));
    vst1q_f32(magnitude + (x - x_begin), vsqrtq_f32(vfmaq_f32(vmulq_f32(dy, dy), dx, dx)));
    const float32x4_t ax = vabsq_f32(dx);
    const float32x4_t ay = vabsq_f32(dy);
    const float32x4_t num = vminq_f32(ax, ay);
    const float32x4_t den = vmaxq_f32(ax, ay);
    const uint32x4_t nonzero = vcgtq_f32(den, zero);
    const float32x4_t z = vbslq_f32(nonzero, vdivq_f32(num, den), zero);
    const float32x4_t z2 = vmulq_f32(z, z);
    float32x4_t p = vfmaq_f32(vdupq_n_f32(kAtanC9), z2, vdupq_n_f32(kAtanC11));
    p = vfmaq_f32(vdupq_n_f32(kAtanC7), z2, p);
    p = vfmaq_f32(vdupq_n_f32(kAtanC5), z2, p);
    p = vfmaq_f32(vdupq_n_f32(kAtanC3), z2, p);
    p = vfmaq_f32(vdupq_n_f32(kAtanC1), z2, p);
    float32x4_t a = vmulq_f32(z, p);
    a = vbslq_f32(vcgtq_f32(ay, ax), vsubq_f32(half_pi, a), a);
    a = vbslq_f32(vcltq_f32(dx, zero), vsubq_f32(pi, a), a);
    a = vbslq_f32(vcltq_f32(dy, zero), vsubq_f32(two_pi, a), a);
    a = vbslq_f32(vcgeq_f32(a, two_pi), vsubq_f32(a, two_pi), a);
    vst1q_f32(angle + (x - x_begin), a);
  }
  if (x < x_end) {
    ScalarSiftKernels().gradient_row(above, row, below, x, x_end, magnitude + (x - x_begin),
                                        angle + (x - x_begin));
  }
}

}  // namespace

const SiftKernels& sift_internal::NeonSiftKernels() {
  static const SiftKernels kernels{"neon", ConvolveColumnsNeon, ConvolveColumns2Neon, ConvolveRowNeon, DifferenceOfGaussiansNeon, FindExtremaNeon,
                                   GradientRowNeon};
  return kernels;
}

}  // namespace reconar
