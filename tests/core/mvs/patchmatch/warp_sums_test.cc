#include "core/mvs/patchmatch/warp_sums.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/base/prng.h"

namespace reconar {
namespace {

// Uniform floats in [low, high) from the project's generator.
class Random {
 public:
  float Uniform(float low, float high) { return static_cast<float>(generator_.Uniform(low, high)); }

 private:
  SplitMix64 generator_{7};
};

// Every kernel against the scalar reference on random windows (any count, padded), random
// projective warps that keep the window inside the image, and a random image.
TEST(WarpSumsTest, EveryKernelMatchesTheScalarReference) {
  const std::vector<WarpSumsKernel> kernels = AvailableWarpSumsKernels();
  ASSERT_FALSE(kernels.empty());
  EXPECT_STREQ(kernels.front().name, "scalar");
  bool active_listed = false;
  for (const WarpSumsKernel& k : kernels) active_listed |= std::strcmp(k.name, ActiveWarpSumsKernel().name) == 0;
  EXPECT_TRUE(active_listed);
  std::printf("active warp kernel: %s (%zu available)\n", ActiveWarpSumsKernel().name, kernels.size());

  Random random;
  const int width = 67, height = 49;
  std::vector<float> image(static_cast<size_t>(width) * height);
  for (float& v : image) v = random.Uniform(0.0f, 1.0f);
  int trials = 0;
  for (int attempt = 0; trials < 400 && attempt < 10000; ++attempt) {
    const int count = 1 + static_cast<int>(random.Uniform(0.0f, 121.0f));
    const int padded = PaddedWarpCount(count);
    std::vector<float> ox(static_cast<size_t>(padded)), oy(ox.size()), w(ox.size()), r(ox.size());
    for (int j = 0; j < padded; ++j) {
      const bool real = j < count;
      ox[static_cast<size_t>(j)] = real ? std::round(random.Uniform(-5.5f, 5.5f)) : ox[0];
      oy[static_cast<size_t>(j)] = real ? std::round(random.Uniform(-5.5f, 5.5f)) : oy[0];
      w[static_cast<size_t>(j)] = real ? random.Uniform(0.0f, 1.0f) : 0.0f;
      r[static_cast<size_t>(j)] = real ? random.Uniform(-0.5f, 0.5f) : 0.0f;
    }
    // H = scale * [[1 + a, b, tx], [c, 1 + d, ty], [e, f, 1]] about a random pixel.
    const float x = random.Uniform(6.0f, width - 7.0f), y = random.Uniform(6.0f, height - 7.0f);
    const float a = random.Uniform(-0.3f, 0.3f), b = random.Uniform(-0.3f, 0.3f), c = random.Uniform(-0.3f, 0.3f);
    const float d = random.Uniform(-0.3f, 0.3f), e = random.Uniform(-0.002f, 0.002f),
                f = random.Uniform(-0.002f, 0.002f);
    const float tx = random.Uniform(-20.0f, 20.0f), ty = random.Uniform(-15.0f, 15.0f);
    const float scale = random.Uniform(0.5f, 2.0f);
    const float m[3][3] = {{scale * (1 + a), scale * b, scale * tx},
                           {scale * c, scale * (1 + d), scale * ty},
                           {scale * e, scale * f, scale}};
    const WarpHomography h{m[0][0] * x + m[0][1] * y + m[0][2],
                           m[1][0] * x + m[1][1] * y + m[1][2],
                           m[2][0] * x + m[2][1] * y + m[2][2],
                           m[0][0],
                           m[1][0],
                           m[2][0],
                           m[0][1],
                           m[1][1],
                           m[2][1]};
    bool inside = true;
    for (int j = 0; j < padded && inside; ++j) {
      const float hz = h.h0z + h.c0z * ox[static_cast<size_t>(j)] + h.c1z * oy[static_cast<size_t>(j)];
      const float u = (h.h0x + h.c0x * ox[static_cast<size_t>(j)] + h.c1x * oy[static_cast<size_t>(j)]) / hz;
      const float v = (h.h0y + h.c0y * ox[static_cast<size_t>(j)] + h.c1y * oy[static_cast<size_t>(j)]) / hz;
      inside = hz > 0.0f && u >= 0.01f && v >= 0.01f && u <= width - 1.01f && v <= height - 1.01f;
    }
    if (!inside) continue;
    ++trials;
    const WarpWindow window{ox.data(), oy.data(), w.data(), r.data(), padded};
    const WarpSums expected = ScalarWarpSumsKernel().sums(h, window, image.data(), width);
    float weight_sum = 0.0f;
    for (float v : w) weight_sum += v;
    for (const WarpSumsKernel& k : kernels) {
      const WarpSums got = k.sums(h, window, image.data(), width);
      // Float sums of <= 128 terms of size <= 1 in another order and with fused multiply-adds.
      const float tolerance = 1e-5f * (weight_sum + 1.0f);
      EXPECT_NEAR(got.sum, expected.sum, tolerance) << k.name << " trial " << trials;
      EXPECT_NEAR(got.sum_squares, expected.sum_squares, tolerance) << k.name << " trial " << trials;
      EXPECT_NEAR(got.sum_products, expected.sum_products, tolerance) << k.name << " trial " << trials;
    }
  }
  EXPECT_EQ(trials, 400);
}

}  // namespace
}  // namespace reconar
