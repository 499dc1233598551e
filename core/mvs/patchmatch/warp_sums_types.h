#pragma once
// Internal: the plain types of warp_sums.h, shared with the per-instruction-set translation units
// (include nothing from the standard library here: those units are compiled with their own flags).
namespace reconar {

struct WarpHomography {
  float h0x, h0y, h0z;  // H (x, y, 1)
  float c0x, c0y, c0z;  // H's first column (per unit of offset x)
  float c1x, c1y, c1z;  // H's second column (per unit of offset y)
};

struct WarpWindow {
  const float* offset_x;  // padded_count each
  const float* offset_y;
  const float* weights;
  const float* reference;  // centred reference grey values
  int padded_count;        // a multiple of kWarpLanes
};

struct WarpSums {
  float sum = 0.0f;
  float sum_squares = 0.0f;
  float sum_products = 0.0f;
};

// `image`: row-major floats, `stride` floats per row.
using WarpSumsFn = WarpSums (*)(const WarpHomography& h, const WarpWindow& window, const float* image, int stride);

namespace internal {
WarpSums WarpSumsScalar(const WarpHomography& h, const WarpWindow& window, const float* image, int stride);
#if defined(RECONAR_HAVE_AVX2_KERNELS)
WarpSums WarpSumsAvx2(const WarpHomography& h, const WarpWindow& window, const float* image, int stride);
#endif
#if defined(RECONAR_HAVE_NEON_KERNELS)
WarpSums WarpSumsNeon(const WarpHomography& h, const WarpWindow& window, const float* image, int stride);
#endif
}  // namespace internal

}  // namespace reconar
