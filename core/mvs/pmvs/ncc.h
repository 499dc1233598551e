#pragma once
// Normalised cross-correlation of two sample vectors, the photometric measure of PMVS
// (Furukawa & Ponce 2010, sec. 3.1.2): one vector is a reference already normalised to zero mean
// and unit norm (NormalizeNccReference), the other raw intensities. Then
//   NCC = sum(r_i b_i) / sqrt(sum b_i^2 - (sum b_i)^2 / n)
// because sum r_i = 0. Vectors are padded with zeros to a multiple of kNccLanes floats, which
// changes none of the three sums, so every kernel runs whole SIMD blocks.
//
// Every instruction set has its own kernel (scalar reference, SSE2 and AVX2 on x86-64, NEON on
// aarch64) in its own translation unit; NccKernelDispatch() is the one place where one is chosen,
// by the rule of core/base/kernel_choice.h. Tests compare every available kernel with the scalar
// reference.
#include <vector>

#include "core/base/kernel_choice.h"
#include "core/mvs/pmvs/ncc_sums.h"

namespace reconar {

inline constexpr int kNccLanes = 8;
inline constexpr int PaddedNccCount(int count) { return (count + kNccLanes - 1) / kNccLanes * kNccLanes; }

// The three sums over padded_count floats (a multiple of kNccLanes).
using NccSumsFn = NccSums (*)(const float* normalized_reference, const float* samples, int padded_count);

struct NccKernel {
  const char* name = "";  // "scalar", "sse2", "avx2", "neon"
  NccSumsFn sums = nullptr;
};

const NccKernel& ScalarNccKernel();
// Every kernel compiled in and supported by this CPU, the scalar reference first.
std::vector<NccKernel> AvailableNccKernels();
// Dispatcher "ncc": the widest kernel this CPU runs, chosen once; RECONAR_NCC_KERNEL=<name> forces one.
const KernelDispatch<NccKernel>& NccKernelDispatch();
const NccKernel& ActiveNccKernel();

// Normalises values[0, count) in place to zero mean and unit norm and zeroes [count, padded).
// Returns false (values untouched) when their standard deviation is below min_std (and always
// when it is below a quarter grey level): too little texture for the NCC to mean anything.
bool NormalizeNccReference(float* values, int count, int padded_count, float min_std);

// NCC in [-1, 1] of raw samples against a normalised reference; -1 when the samples have no
// variance (nothing to correlate).
float NccFromSums(const NccSums& sums, int count);

inline float Ncc(const NccKernel& kernel, const float* normalized_reference, const float* samples, int count) {
  return NccFromSums(kernel.sums(normalized_reference, samples, PaddedNccCount(count)), count);
}

}  // namespace reconar
