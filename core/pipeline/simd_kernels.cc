#include "core/pipeline/simd_kernels.h"

#include "core/features/descriptor_distance.h"
#include "core/features/sift/kernels_dispatch.h"
#include "core/mvs/patchmatch/warp_sums.h"
#include "core/mvs/pmvs/ncc.h"

namespace reconar {

std::vector<KernelChoice> SimdKernelReport() {
  return {
      DescriptorDistanceKernelDispatch().choice,
      NccKernelDispatch().choice,
      SiftKernelDispatch().choice,
      WarpSumsKernelDispatch().choice,
  };
}

}  // namespace reconar
