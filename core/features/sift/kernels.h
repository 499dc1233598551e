#pragma once
// SIFT hot loops (blur, DoG, extrema, gradients) behind one table of function pointers.
// Each instruction set lives in its own translation unit (kernels_ref.cc, kernels_avx2.cc,
// kernels_avx512.cc, kernels_neon.cc), which include this header: it includes nothing from the
// standard library, so that no inline function is emitted with wider instructions. Which table runs
// is chosen in kernels_dispatch.h.
#include <cstdint>

namespace reconar {

struct SiftKernels {
  const char* name;

  // out[x] = k[0]*rows[r][x] + sum_{i=1..r} k[i]*(rows[r-i][x] + rows[r+i][x]) for x in [0, width).
  // rows holds 2r+1 row pointers centred on the output row; k is the half kernel (r+1 taps).
  void (*convolve_columns)(const float* const* rows, const float* half_kernel, int radius, int width,
                           float* out);
  // Two consecutive output rows in one sweep: rows holds 2r+2 row pointers, out0 is centred on
  // rows[r] and out1 on rows[r+1]. Each input row is loaded once for both outputs.
  void (*convolve_columns2)(const float* const* rows, const float* half_kernel, int radius, int width,
                            float* out0, float* out1);
  // out[x] = k[0]*in[x] + sum_i k[i]*(in[x-i] + in[x+i]); `in` is readable on [-r, width+r).
  void (*convolve_row)(const float* in, const float* half_kernel, int radius, int width, float* out);
  // Three DoG rows from four Gaussian rows of consecutive levels: out_l[x] = g[l+1][x] - g[l][x].
  // One pass reads each Gaussian row once.
  void (*difference_of_gaussians)(const float* const* g, int width, float* const* out);
  // dog holds 9 rows: dog[3*l + r] is level l (0 = below, 1 = centre, 2 = above), row r (0 = y-1,
  // 1 = y, 2 = y+1). Writes every x in [x_begin, x_end) whose centre value v has |v| > threshold
  // and is >= all 26 neighbours (v > 0) or <= all of them (v < 0); returns how many.
  // Needs x_begin >= 1 and x_end <= width - 1. out_x must hold x_end - x_begin entries.
  int (*find_extrema)(const float* const* dog, int x_begin, int x_end, float threshold, int32_t* out_x);
  // Central-difference gradient of row y (above = y-1, below = y+1) for x in [x_begin, x_end):
  // magnitude = |(I[x+1]-I[x-1], below[x]-above[x])|, angle = atan2(dy, dx) in [0, 2*pi).
  // Outputs are indexed from 0 (= x_begin).
  void (*gradient_row)(const float* above, const float* row, const float* below, int x_begin, int x_end,
                       float* magnitude, float* angle);
};

// The scalar reference every SIMD table is tested against.
const SiftKernels& ScalarSiftKernels();

namespace sift_internal {
// Polynomial atan2 shared by every kernel so that they agree to float rounding.
// Max error about 1e-5 rad; result in [0, 2*pi).
float FastAtan2Positive(float y, float x);
constexpr float kAtanC1 = 0.99997726f;
constexpr float kAtanC3 = -0.33262347f;
constexpr float kAtanC5 = 0.19354346f;
constexpr float kAtanC7 = -0.11643287f;
constexpr float kAtanC9 = 0.05265332f;
constexpr float kAtanC11 = -0.01172120f;
constexpr float kPi = 3.14159265358979f;
// Largest blur radius any kernel is called with (bounds the tails' row-pointer arrays).
constexpr int kMaxKernelRadius = 31;
// Reference computation of columns [x, width) for the SIMD kernels' tails.
void ConvolveColumnsTail(const float* const* rows, const float* half_kernel, int radius, int x, int width,
                         float* out);
void ConvolveColumns2Tail(const float* const* rows, const float* half_kernel, int radius, int x, int width,
                          float* out0, float* out1);
// The SIMD tables, each defined only where the target compiles it (core/base/kernel_choice.h).
#if defined(RECONAR_HAVE_AVX2_KERNELS)
const SiftKernels& Avx2SiftKernels();
#endif
#if defined(RECONAR_HAVE_AVX512_KERNELS)
const SiftKernels& Avx512SiftKernels();  // shares the AVX2 table's gradient kernel
#endif
#if defined(RECONAR_HAVE_NEON_KERNELS)
const SiftKernels& NeonSiftKernels();
#endif
}  // namespace sift_internal

}  // namespace reconar
