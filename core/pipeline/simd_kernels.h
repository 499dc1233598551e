#pragma once
// The SIMD kernel each dispatcher of the product chose on this machine, for `reconar --version`.
// Each dispatcher chooses in one place of its own module, by the one rule of
// core/base/kernel_choice.h: DescriptorDistanceKernelDispatch (core/features), SiftKernelDispatch
// (core/features/sift), NccKernelDispatch (core/mvs/pmvs), WarpSumsKernelDispatch
// (core/mvs/patchmatch). This asks each of them by a direct call; it lives in core/pipeline, the
// lowest module that may include all four, and holds no registry: a new dispatcher adds one line to
// SimdKernelReport().
#include <vector>

#include "core/base/kernel_choice.h"

namespace reconar {

// Every dispatcher's choice, sorted by dispatcher name. Asking runs the dispatchers' choice (each
// keeps it; RECONAR_<DISPATCHER>_KERNEL overrides apply as in a run).
std::vector<KernelChoice> SimdKernelReport();

}  // namespace reconar
