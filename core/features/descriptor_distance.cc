#include "core/features/descriptor_distance.h"

#include "core/features/descriptor_distance_kernels.h"

namespace reconar {
namespace internal {

int32_t DescriptorDistanceScalar(const uint8_t* a, const uint8_t* b) {
  int32_t sum = 0;
  for (int i = 0; i < kDescriptorSize; ++i) {
    const int32_t d = static_cast<int32_t>(a[i]) - static_cast<int32_t>(b[i]);
    sum += d * d;
  }
  return sum;
}

void DescriptorDistanceBatchScalar(const uint8_t* query, const uint8_t* base, const int32_t* ids,
                                   int count, int32_t* out) {
  for (int i = 0; i < count; ++i) {
    out[i] = DescriptorDistanceScalar(query, base + static_cast<int64_t>(ids[i]) * kDescriptorSize);
  }
}

}  // namespace internal

const DescriptorDistanceKernel& ScalarDescriptorDistanceKernel() {
  static const DescriptorDistanceKernel kernel{"scalar", internal::DescriptorDistanceScalar,
                                               internal::DescriptorDistanceBatchScalar};
  return kernel;
}

std::vector<DescriptorDistanceKernel> AvailableDescriptorDistanceKernels() {
  return KernelsThisCpuRuns<DescriptorDistanceKernel>({
      ScalarDescriptorDistanceKernel(),
#if defined(RECONAR_HAVE_SSE2_KERNELS)
      {"sse2", internal::DescriptorDistanceSse2, internal::DescriptorDistanceBatchSse2},
#endif
#if defined(RECONAR_HAVE_AVX2_KERNELS)
      {"avx2", internal::DescriptorDistanceAvx2, internal::DescriptorDistanceBatchAvx2},
#endif
#if defined(RECONAR_HAVE_NEON_KERNELS)
      {"neon", internal::DescriptorDistanceNeon, internal::DescriptorDistanceBatchNeon},
#endif
  });
}

const KernelDispatch<DescriptorDistanceKernel>& DescriptorDistanceKernelDispatch() {
  static const KernelDispatch<DescriptorDistanceKernel> dispatch =
      ChooseKernel("descriptor", AvailableDescriptorDistanceKernels());
  return dispatch;
}

const DescriptorDistanceKernel& ActiveDescriptorDistanceKernel() { return DescriptorDistanceKernelDispatch().kernel; }

}  // namespace reconar
