// NEON NCC sums (aarch64): two 4-lane blocks per step with fused multiply-add.
#include <arm_neon.h>

#include "core/mvs/pmvs/ncc_kernels.h"

namespace reconar::internal {

NccSums NccSumsNeon(const float* normalized_reference, const float* samples, int padded_count) {
  float32x4_t sum = vdupq_n_f32(0.0f), sum_squares = vdupq_n_f32(0.0f), sum_products = vdupq_n_f32(0.0f);
  for (int i = 0; i < padded_count; i += 4) {
    const float32x4_t b = vld1q_f32(samples + i);
    const float32x4_t r = vld1q_f32(normalized_reference + i);
    sum = vaddq_f32(sum, b);
    sum_squares = vfmaq_f32(sum_squares, b, b);
    sum_products = vfmaq_f32(sum_products, r, b);
  }
  NccSums s;
  s.sum = vaddvq_f32(sum);
  s.sum_squares = vaddvq_f32(sum_squares);
  s.sum_products = vaddvq_f32(sum_products);
  return s;
}

}  // namespace reconar::internal
