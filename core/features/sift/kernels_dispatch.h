#pragma once
// Which SIFT kernel table runs: SiftKernelDispatch() is the one place that chooses, by the rule of
// core/base/kernel_choice.h, and tests/core/features/sift/kernels_test.cc compares every available
// table with the scalar reference.
#include <vector>

#include "core/base/kernel_choice.h"
#include "core/features/sift/kernels.h"

namespace reconar {

// The scalar reference plus every SIMD table this CPU runs, narrowest first.
std::vector<SiftKernels> AvailableSiftKernels();
// Dispatcher "sift": the widest table this CPU runs, chosen once; RECONAR_SIFT_KERNEL=<name> forces one.
const KernelDispatch<SiftKernels>& SiftKernelDispatch();
const SiftKernels& ActiveSiftKernels();

}  // namespace reconar
