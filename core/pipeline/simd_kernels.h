#pragma once
// The SIMD kernel each dispatcher of the product selected on this machine, for `reconar --version`.
// Each dispatcher chooses in one place of its own module (ActiveDescriptorDistanceKernel in
// core/features, BestSiftKernels in core/features/sift, ActiveNccKernel in core/mvs/pmvs, all on
// HostCpuFeatures() of core/base/cpu_features.h); this asks each of them by a direct call. It lives
// in core/pipeline, the lowest module that may include all three (DESIGN.md layering), and holds
// no registry: a new dispatcher adds one line to SimdKernelReport().
#include <string>
#include <vector>

namespace reconar {

struct SimdKernelChoice {
  std::string dispatcher;  // e.g. "sift"
  std::string kernel;      // e.g. "avx2"
};

// Every dispatcher's chosen kernel, sorted by dispatcher name. Asking runs the dispatchers'
// selection (each caches it; RECONAR_*_KERNEL environment overrides apply as in a run).
std::vector<SimdKernelChoice> SimdKernelReport();

}  // namespace reconar
