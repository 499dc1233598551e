#pragma once
// Bilinear sampling of interleaved 8-bit images, with the pixel-centre convention of DESIGN.md
// (the centre of the top-left pixel is (0, 0)): the edge pixels extend by half a pixel, further
// out is outside.
#include <algorithm>
#include <cstdint>

#include "core/base/image.h"

namespace reconar {

// The bilinear sample of every channel of `image` at (x, y) into out[0..channels); false (out
// untouched) outside [-0.5, width - 0.5) x [-0.5, height - 0.5) or for a non-finite position.
inline bool SampleBilinear(const Image<uint8_t>& image, double x, double y, float* out) {
  const int width = image.width(), height = image.height(), channels = image.channels();
  if (!(x > -0.5 && y > -0.5 && x < width - 0.5 && y < height - 0.5)) return false;
  x = std::clamp(x, 0.0, width - 1.0);
  y = std::clamp(y, 0.0, height - 1.0);
  const int x0 = std::min(static_cast<int>(x), std::max(width - 2, 0));
  const int y0 = std::min(static_cast<int>(y), std::max(height - 2, 0));
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const float ax = static_cast<float>(x - x0), ay = static_cast<float>(y - y0);
  const uint8_t* p00 = image.row(y0) + channels * x0;
  const uint8_t* p01 = image.row(y0) + channels * x1;
  const uint8_t* p10 = image.row(y1) + channels * x0;
  const uint8_t* p11 = image.row(y1) + channels * x1;
  for (int c = 0; c < channels; ++c) {
    const float top = p00[c] + ax * (p01[c] - p00[c]);
    const float bottom = p10[c] + ax * (p11[c] - p10[c]);
    out[c] = top + ay * (bottom - top);
  }
  return true;
}

}  // namespace reconar
