// NEON descriptor distance kernels (aarch64): vabdq_u8 for |a-b|, vmull_u8 squares into 16 bit
// (255^2 fits), vpadalq_u16 pairwise-accumulates into 32-bit lanes.
#include <arm_neon.h>

#include "core/features/descriptor_distance_kernels.h"

namespace reconar::internal {
namespace {

inline uint32x4_t SquaredDiffStep(uint8x16_t a, uint8x16_t b, uint32x4_t acc) {
  const uint8x16_t d = vabdq_u8(a, b);
  acc = vpadalq_u16(acc, vmull_u8(vget_low_u8(d), vget_low_u8(d)));
  return vpadalq_u16(acc, vmull_high_u8(d, d));
}

inline int32_t Distance(const uint8x16_t q[8], const uint8_t* p) {
  uint32x4_t acc0 = vdupq_n_u32(0);
  uint32x4_t acc1 = vdupq_n_u32(0);
  for (int j = 0; j < 8; j += 2) {
    acc0 = SquaredDiffStep(q[j], vld1q_u8(p + 16 * j), acc0);
    acc1 = SquaredDiffStep(q[j + 1], vld1q_u8(p + 16 * j + 16), acc1);
  }
  return static_cast<int32_t>(vaddvq_u32(vaddq_u32(acc0, acc1)));
}

}  // namespace

int32_t DescriptorDistanceNeon(const uint8_t* a, const uint8_t* b) {
  uint8x16_t q[8];
  for (int j = 0; j < 8; ++j) q[j] = vld1q_u8(a + 16 * j);
  return Distance(q, b);
}

void DescriptorDistanceBatchNeon(const uint8_t* query, const uint8_t* base, const int32_t* ids,
                                 int count, int32_t* out) {
  uint8x16_t q[8];
  for (int j = 0; j < 8; ++j) q[j] = vld1q_u8(query + 16 * j);
  for (int i = 0; i < count; ++i) out[i] = Distance(q, base + static_cast<int64_t>(ids[i]) * 128);
}

}  // namespace reconar::internal
