#pragma once
// Squared L2 distance between 128-byte uint8 descriptors (quantised SIFT), in integer arithmetic.
// The largest possible value, 128 * 255^2 = 8'323'200, fits an int32 with room to spare.
//
// Every instruction set has its own kernel (scalar reference, SSE2 and AVX2 on x86-64, NEON on
// aarch64), each in its own translation unit; DescriptorDistanceKernelDispatch() is the single
// place where one is chosen for the running CPU, by the rule of core/base/kernel_choice.h. Tests
// compare every available kernel with the scalar reference.
#include <cstdint>
#include <vector>

#include "core/base/kernel_choice.h"

namespace reconar {

inline constexpr int kDescriptorSize = 128;  // bytes per descriptor, rows are contiguous

// Squared distance between two descriptors.
using DescriptorDistanceFn = int32_t (*)(const uint8_t* a, const uint8_t* b);
// out[i] = squared distance between `query` and descriptor ids[i] of `base` (row-major, 128 B rows).
using DescriptorDistanceBatchFn = void (*)(const uint8_t* query, const uint8_t* base,
                                           const int32_t* ids, int count, int32_t* out);

struct DescriptorDistanceKernel {
  const char* name = "";  // "scalar", "sse2", "avx2", "neon"
  DescriptorDistanceFn distance = nullptr;
  DescriptorDistanceBatchFn batch = nullptr;
};

// The portable reference every SIMD kernel is tested against.
const DescriptorDistanceKernel& ScalarDescriptorDistanceKernel();

// Every kernel compiled in and supported by this CPU, the scalar reference first.
std::vector<DescriptorDistanceKernel> AvailableDescriptorDistanceKernels();

// Dispatcher "descriptor": the widest available kernel, chosen once; RECONAR_DESCRIPTOR_KERNEL=<name>
// forces another (for debugging).
const KernelDispatch<DescriptorDistanceKernel>& DescriptorDistanceKernelDispatch();
const DescriptorDistanceKernel& ActiveDescriptorDistanceKernel();

// Convenience wrapper around the active kernel.
inline int32_t DescriptorSquaredDistance(const uint8_t* a, const uint8_t* b) {
  return ActiveDescriptorDistanceKernel().distance(a, b);
}

}  // namespace reconar
