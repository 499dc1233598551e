#include "core/features/sift/kernels_dispatch.h"

namespace reconar {

std::vector<SiftKernels> AvailableSiftKernels() {
  return KernelsThisCpuRuns<SiftKernels>({
      ScalarSiftKernels(),
#if defined(RECONAR_HAVE_AVX2_KERNELS)
      sift_internal::Avx2SiftKernels(),
#endif
#if defined(RECONAR_HAVE_AVX512_KERNELS)
      sift_internal::Avx512SiftKernels(),
#endif
#if defined(RECONAR_HAVE_NEON_KERNELS)
      sift_internal::NeonSiftKernels(),
#endif
  });
}

const KernelDispatch<SiftKernels>& SiftKernelDispatch() {
  static const KernelDispatch<SiftKernels> dispatch = ChooseKernel("sift", AvailableSiftKernels());
  return dispatch;
}

const SiftKernels& ActiveSiftKernels() { return SiftKernelDispatch().kernel; }

}  // namespace reconar
