#include "core/pipeline/simd_kernels.h"

#include "core/features/descriptor_distance.h"
#include "core/features/sift/kernels.h"
#include "core/mvs/pmvs/ncc.h"

namespace reconar {

std::vector<SimdKernelChoice> SimdKernelReport() {
  return {
      {"descriptor_distance", ActiveDescriptorDistanceKernel().name},
      {"ncc", ActiveNccKernel().name},
      {"sift", BestSiftKernels().name},
  };
}

}  // namespace reconar
