#pragma once
// CPU-feature detection in one place. The SIMD dispatchers ask it through CpuRunsKernel
// (core/base/kernel_choice.h), which says which features each instruction set's kernels need.
#include <string>

namespace reconar {

struct CpuFeatures {
  bool sse2 = false;     // x86-64: part of the baseline
  bool avx2 = false;     // x86: AVX2
  bool fma = false;      // x86: FMA3 (the AVX2 kernels need both)
  bool avx512f = false;  // x86: AVX-512 Foundation
  bool neon = false;     // AArch64: Advanced SIMD, part of the baseline
};

// What this CPU runs, detected once (on x86 through the compiler's cpuid wrapper
// __builtin_cpu_supports; AArch64 always has NEON). Features of an architecture the program was
// not built for are false.
const CpuFeatures& HostCpuFeatures();
// The supported features, space-separated ("sse2 avx2 fma"); "none" when there are none.
std::string CpuFeatureNames(const CpuFeatures& features);

}  // namespace reconar
