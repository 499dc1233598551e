#pragma once
// Small helpers shared by the benchmark programs (never by the libraries).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/base/image.h"

namespace reconar::bench {

inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// Bilinear resize of an interleaved image (any channel count) with pixel i covering [i, i+1]: the
// output pixel centre (i + 0.5) samples the input at (i + 0.5) / scale, so a point x maps to
// x * scale (libapriltag's pixel convention; in the (0, 0)-centre convention (x + 0.5) * scale - 0.5).
inline Image<uint8_t> ResizeBilinear(const Image<uint8_t>& in, int width, int height) {
  const int channels = in.channels();
  Image<uint8_t> out(width, height, channels);
  const double sx = static_cast<double>(in.width()) / width, sy = static_cast<double>(in.height()) / height;
  for (int y = 0; y < height; ++y) {
    const double fy = std::clamp((y + 0.5) * sy - 0.5, 0.0, in.height() - 1.0);
    const int y0 = std::min(static_cast<int>(fy), in.height() - 2);
    const double wy = fy - y0;
    for (int x = 0; x < width; ++x) {
      const double fx = std::clamp((x + 0.5) * sx - 0.5, 0.0, in.width() - 1.0);
      const int x0 = std::min(static_cast<int>(fx), in.width() - 2);
      const double wx = fx - x0;
      for (int c = 0; c < channels; ++c) {
        auto at = [&](int row, int col) { return static_cast<double>(in.row(row)[col * channels + c]); };
        const double v = (1 - wy) * ((1 - wx) * at(y0, x0) + wx * at(y0, x0 + 1)) +
                         wy * ((1 - wx) * at(y0 + 1, x0) + wx * at(y0 + 1, x0 + 1));
        out.row(y)[x * channels + c] = static_cast<uint8_t>(std::lround(v));
      }
    }
  }
  return out;
}

}  // namespace reconar::bench
