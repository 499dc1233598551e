#include "core/mvs/pmvs/ncc.h"

#include <algorithm>
#include <cmath>

#include "core/mvs/pmvs/ncc_kernels.h"

namespace reconar {
namespace internal {

NccSums NccSumsScalar(const float* normalized_reference, const float* samples, int padded_count) {
  NccSums s;
  for (int i = 0; i < padded_count; ++i) {
    const float b = samples[i];
    s.sum += b;
    s.sum_squares += b * b;
    s.sum_products += normalized_reference[i] * b;
  }
  return s;
}

}  // namespace internal

const NccKernel& ScalarNccKernel() {
  static const NccKernel kernel{"scalar", internal::NccSumsScalar};
  return kernel;
}

std::vector<NccKernel> AvailableNccKernels() {
  return KernelsThisCpuRuns<NccKernel>({
      ScalarNccKernel(),
#if defined(RECONAR_HAVE_SSE2_KERNELS)
      {"sse2", internal::NccSumsSse2},
#endif
#if defined(RECONAR_HAVE_AVX2_KERNELS)
      {"avx2", internal::NccSumsAvx2},
#endif
#if defined(RECONAR_HAVE_NEON_KERNELS)
      {"neon", internal::NccSumsNeon},
#endif
  });
}

const KernelDispatch<NccKernel>& NccKernelDispatch() {
  static const KernelDispatch<NccKernel> dispatch = ChooseKernel("ncc", AvailableNccKernels());
  return dispatch;
}

const NccKernel& ActiveNccKernel() { return NccKernelDispatch().kernel; }

bool NormalizeNccReference(float* values, int count, int padded_count, float min_std) {
  if (count <= 1) return false;
  double sum = 0.0, sum_squares = 0.0;
  for (int i = 0; i < count; ++i) {
    sum += values[i];
    sum_squares += static_cast<double>(values[i]) * values[i];
  }
  const double mean = sum / count;
  const double variance_sum = sum_squares - sum * mean;
  const double min_variance = std::max(0.0625, static_cast<double>(min_std) * min_std);
  if (!(variance_sum >= min_variance * count)) return false;
  const double inv_norm = 1.0 / std::sqrt(variance_sum);
  for (int i = 0; i < count; ++i) values[i] = static_cast<float>((values[i] - mean) * inv_norm);
  for (int i = count; i < padded_count; ++i) values[i] = 0.0f;
  return true;
}

float NccFromSums(const NccSums& sums, int count) {
  const float variance_sum = sums.sum_squares - sums.sum * sums.sum / static_cast<float>(count);
  if (!(variance_sum > 1e-3f * static_cast<float>(count))) return -1.0f;
  const float ncc = sums.sum_products / std::sqrt(variance_sum);
  return ncc > 1.0f ? 1.0f : (ncc < -1.0f ? -1.0f : ncc);
}

}  // namespace reconar
