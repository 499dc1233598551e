#pragma once
// The inner loop of PatchMatch's photometric cost: warp every sample of a reference window by a
// plane-induced homography into a source image, read it bilinearly, and accumulate the three
// weighted sums of the NCC. For sample j with offset (ox_j, oy_j) from the window's pixel (x, y),
//   (hx, hy, hz) = h0 + ox_j c0 + oy_j c1,   h0 = H (x, y, 1), c0 and c1 H's first two columns,
//   s_j = bilinear(image, hx / hz, hy / hz),
//   sum = sum w_j s_j,  sum_squares = sum w_j s_j^2,  sum_products = sum w_j r_j s_j.
// The caller guarantees every sample lands in [0, width - 1) x [0, height - 1) with hz > 0
// (patchmatch_view.cc checks the corners of the window's box). Sample arrays are padded to a
// multiple of kWarpLanes with weight 0 and an offset inside the box.
//
// Every instruction set has its own kernel (scalar reference; AVX2 on x86-64; NEON on aarch64) in
// its own translation unit; WarpSumsKernelDispatch() is the one place where one is chosen, by the
// rule of core/base/kernel_choice.h. Tests compare every available kernel with the scalar reference.
#include <vector>

#include "core/base/kernel_choice.h"
#include "core/mvs/patchmatch/warp_sums_types.h"

namespace reconar {

inline constexpr int kWarpLanes = 8;
inline constexpr int PaddedWarpCount(int count) { return (count + kWarpLanes - 1) / kWarpLanes * kWarpLanes; }

struct WarpSumsKernel {
  const char* name = "";  // "scalar", "avx2", "neon"
  WarpSumsFn sums = nullptr;
};

const WarpSumsKernel& ScalarWarpSumsKernel();
// Every kernel compiled in and supported by this CPU, the scalar reference first.
std::vector<WarpSumsKernel> AvailableWarpSumsKernels();
// Dispatcher "warp": the widest kernel this CPU runs, chosen once; RECONAR_WARP_KERNEL=<name> forces one.
const KernelDispatch<WarpSumsKernel>& WarpSumsKernelDispatch();
const WarpSumsKernel& ActiveWarpSumsKernel();

}  // namespace reconar
