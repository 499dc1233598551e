// NEON warp sums (aarch64): four samples per step, the homography and the bilinear blend in lanes;
// NEON has no gather, so the four corners of each sample are loaded lane by lane.
#include <arm_neon.h>

#include "core/mvs/patchmatch/warp_sums_types.h"

namespace reconar::internal {

WarpSums WarpSumsNeon(const WarpHomography& h, const WarpWindow& window, const float* image, int stride) {
  const float32x4_t h0x = vdupq_n_f32(h.h0x), h0y = vdupq_n_f32(h.h0y), h0z = vdupq_n_f32(h.h0z);
  float32x4_t sum = vdupq_n_f32(0.0f), sum_squares = vdupq_n_f32(0.0f), sum_products = vdupq_n_f32(0.0f);
  for (int j = 0; j < window.padded_count; j += 4) {
    const float32x4_t ox = vld1q_f32(window.offset_x + j), oy = vld1q_f32(window.offset_y + j);
    const float32x4_t z = vfmaq_n_f32(vfmaq_n_f32(h0z, ox, h.c0z), oy, h.c1z);
    const float32x4_t inverse_z = vdivq_f32(vdupq_n_f32(1.0f), z);
    const float32x4_t u = vmulq_f32(vfmaq_n_f32(vfmaq_n_f32(h0x, ox, h.c0x), oy, h.c1x), inverse_z);
    const float32x4_t v = vmulq_f32(vfmaq_n_f32(vfmaq_n_f32(h0y, ox, h.c0y), oy, h.c1y), inverse_z);
    const int32x4_t u0 = vcvtq_s32_f32(u), v0 = vcvtq_s32_f32(v);  // truncation, as the scalar cast
    const float32x4_t au = vsubq_f32(u, vcvtq_f32_s32(u0)), av = vsubq_f32(v, vcvtq_f32_s32(v0));
    const int32x4_t index = vmlaq_n_s32(u0, v0, stride);
    int32_t lanes[4];
    vst1q_s32(lanes, index);
    float32x4_t p00 = vdupq_n_f32(0.0f), p01 = p00, p10 = p00, p11 = p00;
#define RECONAR_WARP_LANE(k)                     \
  {                                              \
    const float* p = image + lanes[k];           \
    p00 = vsetq_lane_f32(p[0], p00, k);          \
    p01 = vsetq_lane_f32(p[1], p01, k);          \
    p10 = vsetq_lane_f32(p[stride], p10, k);     \
    p11 = vsetq_lane_f32(p[stride + 1], p11, k); \
  }
    RECONAR_WARP_LANE(0)
    RECONAR_WARP_LANE(1)
    RECONAR_WARP_LANE(2)
    RECONAR_WARP_LANE(3)
#undef RECONAR_WARP_LANE
    const float32x4_t top = vfmaq_f32(p00, au, vsubq_f32(p01, p00));
    const float32x4_t bottom = vfmaq_f32(p10, au, vsubq_f32(p11, p10));
    const float32x4_t value = vfmaq_f32(top, av, vsubq_f32(bottom, top));
    const float32x4_t weighted = vmulq_f32(vld1q_f32(window.weights + j), value);
    sum = vaddq_f32(sum, weighted);
    sum_squares = vfmaq_f32(sum_squares, weighted, value);
    sum_products = vfmaq_f32(sum_products, weighted, vld1q_f32(window.reference + j));
  }
  WarpSums s;
  s.sum = vaddvq_f32(sum);
  s.sum_squares = vaddvq_f32(sum_squares);
  s.sum_products = vaddvq_f32(sum_products);
  return s;
}

}  // namespace reconar::internal
