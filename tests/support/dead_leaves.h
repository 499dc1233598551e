#pragma once
// Low-contrast "dead leaves" pictures for the rendered scenes' surfaces (corridor_walk.h): opaque
// discs with radii drawn from p(r) ~ r^-3, the scale-invariant model of natural images' statistics
// (Lee, Mumford and Huang, IJCV 2001), on a painted wall's colour. Test support only.
#include <Eigen/Core>
#include <algorithm>
#include <cstdint>

#include "core/base/image.h"

namespace reconar::testing {

struct RgbTexture {
  Image<float> rgb;  // 3 channels, grey levels

  // Bilinear sample at (u, v) in [0, 1]^2 (clamped): (0, 0) is the first pixel's centre, (1, 1) the
  // last's. Inline: the ray tracers' inner loop.
  Eigen::Vector3f Sample(double u, double v) const {
    const double x = std::clamp(u, 0.0, 1.0) * (rgb.width() - 1);
    const double y = std::clamp(v, 0.0, 1.0) * (rgb.height() - 1);
    const int x0 = std::min(static_cast<int>(x), rgb.width() - 2);
    const int y0 = std::min(static_cast<int>(y), rgb.height() - 2);
    const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
    Eigen::Vector3f out = Eigen::Vector3f::Zero();
    const float weights[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    for (int k = 0; k < 4; ++k) {
      const float* pixel = rgb.row(y0 + k / 2) + 3 * (x0 + k % 2);
      out += weights[k] * Eigen::Vector3f(pixel[0], pixel[1], pixel[2]);
    }
    return out;
  }
};

// A wall's colour (each channel 80..180), each disc within about +-`contrast` grey levels of it.
// Every seed gives a different picture.
RgbTexture DeadLeavesTexture(int width, int height, double contrast, uint32_t seed);

}  // namespace reconar::testing
