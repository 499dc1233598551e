#include "core/mvs/patchmatch/warp_sums.h"

#include <cstddef>

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
  return KernelsThisCpuRuns<WarpSumsKernel>({
      ScalarWarpSumsKernel(),
#if defined(RECONAR_HAVE_AVX2_KERNELS)
      {"avx2", internal::WarpSumsAvx2},
#endif
#if defined(RECONAR_HAVE_NEON_KERNELS)
      {"neon", internal::WarpSumsNeon},
#endif
  });
}

const KernelDispatch<WarpSumsKernel>& WarpSumsKernelDispatch() {
  static const KernelDispatch<WarpSumsKernel> dispatch = ChooseKernel("warp", AvailableWarpSumsKernels());
  return dispatch;
}

const WarpSumsKernel& ActiveWarpSumsKernel() { return WarpSumsKernelDispatch().kernel; }

}  // namespace reconar
