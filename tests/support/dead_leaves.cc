#include "tests/support/dead_leaves.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace reconar::testing {

RgbTexture DeadLeavesTexture(int width, int height, double contrast, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  RgbTexture texture;
  texture.rgb = Image<float>(width, height, 3);
  float wall[3];
  for (float& c : wall) c = static_cast<float>(80.0 + 100.0 * unit(random));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) std::copy(wall, wall + 3, texture.rgb.row(y) + 3 * x);
  }
  const double r_min = 2.0, r_max = 0.12 * width;
  const double a = 1.0 / (r_min * r_min), b = 1.0 / (r_max * r_max);
  const int discs = 3 * width * height / 1000;
  for (int i = 0; i < discs; ++i) {
    const double radius = 1.0 / std::sqrt(a - unit(random) * (a - b));
    const double cx = unit(random) * width, cy = unit(random) * height;
    float colour[3];
    const double shade = contrast * (2.0 * unit(random) - 1.0);
    for (int c = 0; c < 3; ++c) colour[c] = static_cast<float>(wall[c] + shade * (0.8 + 0.4 * unit(random)));
    const int x0 = std::max(0, static_cast<int>(cx - radius)), x1 = std::min(width - 1, static_cast<int>(cx + radius));
    const int y0 = std::max(0, static_cast<int>(cy - radius)), y1 = std::min(height - 1, static_cast<int>(cy + radius));
    for (int y = y0; y <= y1; ++y) {
      float* row = texture.rgb.row(y);
      for (int x = x0; x <= x1; ++x) {
        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) > radius * radius) continue;
        for (int c = 0; c < 3; ++c) row[3 * x + c] = colour[c];
      }
    }
  }
  return texture;
}

}  // namespace reconar::testing
