#include "core/features/descriptor_distance.h"

#include <cstdlib>
#include <cstring>

#include "core/base/cpu_features.h"
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
  std::vector<DescriptorDistanceKernel> kernels = {ScalarDescriptorDistanceKernel()};
#if defined(RECONAR_FEATURES_HAVE_SSE2)
  kernels.push_back({"sse2", internal::DescriptorDistanceSse2, internal::DescriptorDistanceBatchSse2});
#endif
#if defined(RECONAR_FEATURES_HAVE_AVX2)
  if (HostCpuFeatures().avx2) {
    kernels.push_back({"avx2", internal::DescriptorDistanceAvx2, internal::DescriptorDistanceBatchAvx2});
  }
#endif
#if defined(RECONAR_FEATURES_HAVE_NEON)
  kernels.push_back({"neon", internal::DescriptorDistanceNeon, internal::DescriptorDistanceBatchNeon});
#endif
  return kernels;
}

// The one dispatch point: the last available kernel is the widest one this CPU runs.
const DescriptorDistanceKernel& ActiveDescriptorDistanceKernel() {
  static const DescriptorDistanceKernel active = [] {
    const std::vector<DescriptorDistanceKernel> kernels = AvailableDescriptorDistanceKernels();
    if (const char* forced = std::getenv("RECONAR_DESCRIPTOR_KERNEL")) {
      for (const DescriptorDistanceKernel& k : kernels) {
        if (std::strcmp(k.name, forced) == 0) return k;
      }
    }
    return kernels.back();
  }();
  return active;
}

}  // namespace reconar
