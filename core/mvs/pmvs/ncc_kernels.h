#pragma once
// Internal: the per-instruction-set kernels behind ncc.h, each defined in its own translation unit
// (ncc_<isa>.cc) compiled with that ISA's flags and only called after ncc.cc has checked the CPU.
// Include nothing from the standard library here (see descriptor_distance_kernels.h).
#include "core/mvs/pmvs/ncc_sums.h"

namespace reconar::internal {

NccSums NccSumsScalar(const float* normalized_reference, const float* samples, int padded_count);
#if defined(RECONAR_PMVS_HAVE_SSE2)
NccSums NccSumsSse2(const float* normalized_reference, const float* samples, int padded_count);
#endif
#if defined(RECONAR_PMVS_HAVE_AVX2)
NccSums NccSumsAvx2(const float* normalized_reference, const float* samples, int padded_count);
#endif
#if defined(RECONAR_PMVS_HAVE_NEON)
NccSums NccSumsNeon(const float* normalized_reference, const float* samples, int padded_count);
#endif

}  // namespace reconar::internal
