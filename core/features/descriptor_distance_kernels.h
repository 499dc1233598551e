#pragma once
// Internal: the per-instruction-set kernels behind descriptor_distance.h. Each is defined in its
// own translation unit (descriptor_distance_<isa>.cc) compiled with that ISA's flags, and only
// called after descriptor_distance.cc has checked the CPU supports it (core/base/kernel_choice.h). Include nothing from the
// standard library in those units so no inline function is emitted with wider instructions.
#include <cstdint>

namespace reconar::internal {

int32_t DescriptorDistanceScalar(const uint8_t* a, const uint8_t* b);
void DescriptorDistanceBatchScalar(const uint8_t* query, const uint8_t* base, const int32_t* ids,
                                   int count, int32_t* out);

#if defined(RECONAR_HAVE_SSE2_KERNELS)
int32_t DescriptorDistanceSse2(const uint8_t* a, const uint8_t* b);
void DescriptorDistanceBatchSse2(const uint8_t* query, const uint8_t* base, const int32_t* ids,
                                 int count, int32_t* out);
#endif

#if defined(RECONAR_HAVE_AVX2_KERNELS)
int32_t DescriptorDistanceAvx2(const uint8_t* a, const uint8_t* b);
void DescriptorDistanceBatchAvx2(const uint8_t* query, const uint8_t* base, const int32_t* ids,
                                 int count, int32_t* out);
#endif

#if defined(RECONAR_HAVE_NEON_KERNELS)
int32_t DescriptorDistanceNeon(const uint8_t* a, const uint8_t* b);
void DescriptorDistanceBatchNeon(const uint8_t* query, const uint8_t* base, const int32_t* ids,
                                 int count, int32_t* out);
#endif

}  // namespace reconar::internal
