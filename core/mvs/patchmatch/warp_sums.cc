#include "core/mvs/patchmatch/warp_sums.h"

#include <cstddef>
#include <cstdlib>
#include <cstring>

#include "core/base/cpu_features.h"

namespace reconar {
namespace internal {

WarpSums WarpSumsScalar(const WarpHomography& h, const WarpWindow& window, const float* image, int stride) {
  WarpSums s;
  const size_t row = static_cast<size_t>(stride);
  for (int j = 0; j < window.padded_count; ++j) {
    const float ox = window.offset_x[j], oy = window.offset_y[j];
    const float inverse_z = 1.0f / (h.h0z + h.c0z * ox + h.c1z * oy);
    const float u = (h.h0x + h.c0x * ox + h.c1x * oy) * inverse_z;
    const float v = (h.h0y + h.c0y * ox + h.c1y * oy) * inverse_z;
    const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
    const float au = u - static_cast<float>(u0), av = v - static_cast<float>(v0);
    const float* p = image + static_cast<size_t>(v0) * row + static_cast<size_t>(u0);
    const float top = p[0] + au * (p[1] - p[0]);
    const float bottom = p[row] + au * (p[row + 1] - p[row]);
    const float value = top + av * (bottom - top);
    const float w = window.weights[j];
    s.sum += w * value;
    s.sum_squares += w * value * value;
    s.sum_products += w * window.reference[j] * value;
  }
  return s;
}

}  // namespace internal

const WarpSumsKernel& ScalarWarpSumsKernel() {
  static const WarpSumsKernel kernel{"scalar", internal::WarpSumsScalar};
  return kernel;
}

std::vector<WarpSumsKernel> AvailableWarpSumsKernels() {
  std::vector<WarpSumsKernel> kernels = {ScalarWarpSumsKernel()};
#if defined(RECONAR_PATCHMATCH_HAVE_AVX2)
  if (HostCpuFeatures().avx2 && HostCpuFeatures().fma) kernels.push_back({"avx2", internal::WarpSumsAvx2});
#endif
#if defined(RECONAR_PATCHMATCH_HAVE_NEON)
  kernels.push_back({"neon", internal::WarpSumsNeon});
#endif
  return kernels;
}

const WarpSumsKernel& ActiveWarpSumsKernel() {
  static const WarpSumsKernel active = [] {
    const std::vector<WarpSumsKernel> kernels = AvailableWarpSumsKernels();
    if (const char* forced = std::getenv("RECONAR_WARP_KERNEL")) {
      for (const WarpSumsKernel& k : kernels) {
        if (std::strcmp(k.name, forced) == 0) return k;
      }
    }
    return kernels.back();
  }();
  return active;
}

}  // namespace reconar
