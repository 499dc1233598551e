#pragma once
// CPU-feature detection in one place, and the list of SIMD kernels the dispatchers selected.
// Every SIMD dispatcher (descriptor distance in core/features, the SIFT kernel tables in
// core/features/sift, the NCC kernel in core/mvs/pmvs) keeps its own kernel table but asks
// HostCpuFeatures() whether the CPU runs a kernel, and registers itself here so that
// `reconar --version` can say which kernel each one chose on this machine.
#include <string>
#include <vector>

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

// A dispatcher: its name and a function returning the name of the kernel it selected.
struct SimdDispatcher {
  const char* name;
  const char* (*selected_kernel)();
};
// Called once per dispatcher from a namespace-scope initialiser in the dispatcher's own file:
//   const bool kRegistered = RegisterSimdDispatcher({"ncc", [] { return ActiveNccKernel().name; }});
// Returns true so that it can initialise a constant.
bool RegisterSimdDispatcher(SimdDispatcher dispatcher);

struct SimdKernelChoice {
  std::string dispatcher;  // e.g. "sift"
  std::string kernel;      // e.g. "avx2"
};
// The kernel each dispatcher linked into this program selected, sorted by dispatcher name.
// Asking runs the dispatchers' selection (it is cached by each dispatcher).
std::vector<SimdKernelChoice> SelectedSimdKernels();

}  // namespace reconar
