#pragma once
// Internal: the per-instruction-set kernels behind ncc.h, each defined in its own translation unit
// (ncc_<isa>.cc) compiled with that ISA's flags and only called after ncc.cc has checked the CPU.
// Include nothing from the standard library here (see descriptor_distance_kernels.h).
#include "core/mvs/pmvs/ncc_sums.h"

namespace reconar::internal {

NccSums NccSumsScalar(const float* normalized_reference, const float* samples, int padded_count);
#if defined(RECONAR_HAVE_SSE2_KERNELS)
NccSums NccSumsSse2(const float* normalized_reference, const float* samples, int padded_count);
#endif
#if defined(RECONAR_HAVE_AVX2_KERNELS)
NccSums NccSumsAvx2(const float* normalized_reference, const float* samples, int padded_count);
#endif
#if defined(RECONAR_HAVE_NEON_KERNELS)
NccSums NccSumsNeon(const float* normalized_reference, const float* samples, int padded_count);
#endif

}  // namespace reconar::internal
