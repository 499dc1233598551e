#include <cmath>

#include "core/features/sift/kernels.h"

namespace reconar {
namespace sift_internal {

float FastAtan2Positive(float y, float x) {
  const float ax = std::fabs(x);
  const float ay = std::fabs(y);
  const float num = ax < ay ? ax : ay;
  const float den = ax < ay ? ay : ax;
  const float z = den > 0.0f ? num / den : 0.0f;
  const float z2 = z * z;
  float a = z * (kAtanC1 + z2 * (kAtanC3 + z2 * (kAtanC5 + z2 * (kAtanC7 + z2 * (kAtanC9 + z2 * kAtanC11)))));
  if (ay > ax) a = 0.5f * kPi - a;
  if (x < 0.0f) a = kPi - a;
  if (y < 0.0f) a = 2.0f * kPi - a;
  if (a >= 2.0f * kPi) a -= 2.0f * kPi;
  return a;
}

}  // namespace sift_internal

namespace {

void ConvolveColumnsRef(const float* const* rows, const float* k, int r, int width, float* out) {
  const float* centre = rows[r];
  for (int x = 0; x < width; ++x) {
    float acc = k[0] * centre[x];
    for (int i = 1; i <= r; ++i) acc += k[i] * (rows[r - i][x] + rows[r + i][x]);
    out[x] = acc;
  }
}

void ConvolveColumns2Ref(const float* const* rows, const float* k, int r, int width, float* out0, float* out1) {
  ConvolveColumnsRef(rows, k, r, width, out0);
  ConvolveColumnsRef(rows + 1, k, r, width, out1);
}

void ConvolveRowRef(const float* in, const float* k, int r, int width, float* out) {
  for (int x = 0; x < width; ++x) {
    float acc = k[0] * in[x];
    for (int i = 1; i <= r; ++i) acc += k[i] * (in[x - i] + in[x + i]);
    out[x] = acc;
  }
}

void DifferenceOfGaussiansRef(const float* const* g, int width, float* const* out) {
  for (int x = 0; x < width; ++x) {
    out[0][x] = g[1][x] - g[0][x];
    out[1][x] = g[2][x] - g[1][x];
    out[2][x] = g[3][x] - g[2][x];
  }
}

int FindExtremaRef(const float* const* dog, int x_begin, int x_end, float threshold, int32_t* out_x) {
  int count = 0;
  for (int x = x_begin; x < x_end; ++x) {
    const float v = dog[4][x];
    if (!(std::fabs(v) > threshold)) continue;
    bool is_max = v > 0.0f;
    bool is_min = v < 0.0f;
    for (int j = 0; j < 9 && (is_max || is_min); ++j) {
      const float* row = dog[j];
      for (int dx = -1; dx <= 1; ++dx) {
        if (j == 4 && dx == 0) continue;
        const float n = row[x + dx];
        is_max = is_max && v >= n;
        is_min = is_min && v <= n;
      }
    }
    if (is_max || is_min) out_x[count++] = x;
  }
  return count;
}

void GradientRowRef(const float* above, const float* row, const float* below, int x_begin, int x_end,
                    float* magnitude, float* angle) {
  for (int x = x_begin; x < x_end; ++x) {
    const float dx = row[x + 1] - row[x - 1];
    const float dy = below[x] - above[x];
    magnitude[x - x_begin] = std::sqrt(dx * dx + dy * dy);
    angle[x - x_begin] = sift_internal::FastAtan2Positive(dy, dx);
  }
}

}  // namespace

namespace sift_internal {

void ConvolveColumnsTail(const float* const* rows, const float* k, int r, int x, int width, float* out) {
  const float* shifted[2 * kMaxKernelRadius + 2];
  for (int i = 0; i < 2 * r + 1; ++i) shifted[i] = rows[i] + x;
  ConvolveColumnsRef(shifted, k, r, width - x, out + x);
}

void ConvolveColumns2Tail(const float* const* rows, const float* k, int r, int x, int width, float* out0,
                          float* out1) {
  const float* shifted[2 * kMaxKernelRadius + 2];
  for (int i = 0; i < 2 * r + 2; ++i) shifted[i] = rows[i] + x;
  ConvolveColumns2Ref(shifted, k, r, width - x, out0 + x, out1 + x);
}

}  // namespace sift_internal

const SiftKernels& ScalarSiftKernels() {
  static const SiftKernels kernels{"scalar", ConvolveColumnsRef, ConvolveColumns2Ref, ConvolveRowRef, DifferenceOfGaussiansRef, FindExtremaRef,
                                   GradientRowRef};
  return kernels;
}

}  // namespace reconar
