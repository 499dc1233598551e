#pragma once
// The one rule by which every SIMD dispatcher picks its kernel: descriptor distance
// (core/features), SIFT (core/features/sift), PMVS's NCC (core/mvs/pmvs) and PatchMatch's warp
// sums (core/mvs/patchmatch).
//
// Compile time: a module's kernels for an instruction set exist only where its target defines
// RECONAR_HAVE_<ISA>_KERNELS (SSE2, AVX2, AVX512, NEON); reconar_add_kernel_sources in
// cmake/ReconarHelpers.cmake adds those sources, their flags and the definition together.
// Run time: the dispatcher lists its compiled kernels, scalar reference first and then narrowest to
// widest, keeps those this CPU runs (KernelsThisCpuRuns) and runs the widest (ChooseKernel), unless
// the environment variable RECONAR_<DISPATCHER>_KERNEL names another one of them:
// RECONAR_NCC_KERNEL=scalar runs PMVS's scalar reference. A value naming no kernel of that list is
// ignored with a warning on stderr and the widest runs: the choice is made on first use, possibly
// hours into a run, and one environment may serve machines of other instruction sets.
#include <cstddef>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace reconar {

// Whether this CPU runs the kernels of that name, given the flags they are compiled with:
// "scalar" always, "sse2", "avx2" (AVX2 + FMA), "avx512" (AVX-512F + AVX2 + FMA), "neon".
// Any other name is a programming error (RECONAR_CHECK).
bool CpuRunsKernel(std::string_view kernel);

// The kernels of `compiled` (each with a `name`) that this CPU runs, in the same order.
template <typename Kernel>
std::vector<Kernel> KernelsThisCpuRuns(std::initializer_list<Kernel> compiled) {
  std::vector<Kernel> runs;
  for (const Kernel& kernel : compiled) {
    if (CpuRunsKernel(kernel.name)) runs.push_back(kernel);
  }
  return runs;
}

// What a dispatcher chose and among which kernels: a line of `reconar --version`.
struct KernelChoice {
  std::string dispatcher;              // "ncc"
  std::vector<std::string> available;  // scalar first, then narrowest to widest
  size_t chosen = 0;                   // index into available
  bool overridden = false;             // the override variable named it

  const std::string& kernel() const { return available[chosen]; }
};

// The variable that overrides a dispatcher's choice: "ncc" -> "RECONAR_NCC_KERNEL".
std::string KernelOverrideVariable(std::string_view dispatcher);

// The choice among `available` (not empty) given the override variable's value, nullptr when it is
// unset. Sets *warning to why a value was ignored, else clears it.
KernelChoice ChooseKernelName(std::string_view dispatcher, std::vector<std::string> available,
                              const char* requested, std::string* warning);

// ChooseKernelName with the value of the dispatcher's override variable; logs the warning.
KernelChoice ChooseKernelFromEnvironment(std::string_view dispatcher, std::vector<std::string> available);

// A dispatcher's kernel and the choice that picked it. Each dispatcher keeps one, made on first use.
template <typename Kernel>
struct KernelDispatch {
  Kernel kernel;
  KernelChoice choice;
};

// The kernel of `available` (KernelsThisCpuRuns' list) that ChooseKernelFromEnvironment picks.
template <typename Kernel>
KernelDispatch<Kernel> ChooseKernel(std::string_view dispatcher, const std::vector<Kernel>& available) {
  std::vector<std::string> names;
  for (const Kernel& kernel : available) names.emplace_back(kernel.name);
  KernelChoice choice = ChooseKernelFromEnvironment(dispatcher, std::move(names));
  return {available[choice.chosen], std::move(choice)};
}

}  // namespace reconar
