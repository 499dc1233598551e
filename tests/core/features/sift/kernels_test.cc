#include "core/features/sift/kernels_dispatch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

namespace reconar {
namespace {

std::vector<float> RandomRow(int n, std::mt19937& rng) {
  std::uniform_real_distribution<float> dist(-1.0f, 1.0f);
  std::vector<float> row(n);
  for (float& v : row) v = dist(rng);
  return row;
}

class SiftKernelsTest : public ::testing::TestWithParam<SiftKernels> {};

TEST_P(SiftKernelsTest, ConvolutionsMatchReference) {
  const SiftKernels& ref = ScalarSiftKernels();
  const SiftKernels& k = GetParam();
  std::mt19937 rng(7);
  for (int radius : {1, 3, 8, 13, 30}) {
    for (int width : {1, 7, 16, 37, 260}) {
      std::vector<float> taps = RandomRow(radius + 1, rng);
      std::vector<std::vector<float>> rows;
      std::vector<const float*> pointers;
      for (int i = 0; i < 2 * radius + 1; ++i) rows.push_back(RandomRow(width, rng));
      for (const auto& r : rows) pointers.push_back(r.data());
      std::vector<float> expected(width), actual(width);
      ref.convolve_columns(pointers.data(), taps.data(), radius, width, expected.data());
      k.convolve_columns(pointers.data(), taps.data(), radius, width, actual.data());
      for (int x = 0; x < width; ++x) ASSERT_NEAR(actual[x], expected[x], 1e-5f) << k.name << " x=" << x;

      // Two-row form: one more input row, outputs centred on rows r and r + 1.
      rows.push_back(RandomRow(width, rng));
      pointers.push_back(rows.back().data());
      std::vector<float> expected1(width), actual0(width), actual1(width);
      ref.convolve_columns(pointers.data() + 1, taps.data(), radius, width, expected1.data());
      k.convolve_columns2(pointers.data(), taps.data(), radius, width, actual0.data(), actual1.data());
      for (int x = 0; x < width; ++x) {
        ASSERT_NEAR(actual0[x], expected[x], 1e-5f) << k.name << " two-row x=" << x;
        ASSERT_NEAR(actual1[x], expected1[x], 1e-5f) << k.name << " two-row x=" << x;
      }

      std::vector<float> padded = RandomRow(width + 2 * radius, rng);
      ref.convolve_row(padded.data() + radius, taps.data(), radius, width, expected.data());
      k.convolve_row(padded.data() + radius, taps.data(), radius, width, actual.data());
      for (int x = 0; x < width; ++x) ASSERT_NEAR(actual[x], expected[x], 1e-5f) << k.name << " x=" << x;
    }
  }
}

TEST_P(SiftKernelsTest, SubtractAndExtremaMatchReferenceExactly) {
  const SiftKernels& ref = ScalarSiftKernels();
  const SiftKernels& k = GetParam();
  std::mt19937 rng(11);
  for (int width : {3, 10, 33, 301}) {
    std::vector<std::vector<float>> rows;
    std::vector<const float*> pointers;
    for (int i = 0; i < 9; ++i) rows.push_back(RandomRow(width, rng));
    // Plant some extrema and ties.
    rows[4][width / 2] = 5.0f;
    if (width > 4) rows[4][1] = -5.0f;
    for (const auto& r : rows) pointers.push_back(r.data());
    std::vector<int32_t> expected(width), actual(width);
    for (float threshold : {0.0f, 0.5f, 0.95f}) {
      const int n_ref = ref.find_extrema(pointers.data(), 1, width - 1, threshold, expected.data());
      const int n = k.find_extrema(pointers.data(), 1, width - 1, threshold, actual.data());
      ASSERT_EQ(n, n_ref) << k.name;
      for (int i = 0; i < n; ++i) EXPECT_EQ(actual[i], expected[i]);
      EXPECT_GE(n_ref, 1);
    }
    std::vector<std::vector<float>> dog_ref(3, std::vector<float>(width)), dog(3, std::vector<float>(width));
    float* out_ref[3] = {dog_ref[0].data(), dog_ref[1].data(), dog_ref[2].data()};
    float* out[3] = {dog[0].data(), dog[1].data(), dog[2].data()};
    ref.difference_of_gaussians(pointers.data(), width, out_ref);
    k.difference_of_gaussians(pointers.data(), width, out);
    EXPECT_EQ(dog, dog_ref);
    for (int x = 0; x < width; ++x) EXPECT_EQ(dog_ref[2][x], rows[3][x] - rows[2][x]);
  }
}

TEST_P(SiftKernelsTest, GradientMatchesReferenceAndAtan2) {
  const SiftKernels& ref = ScalarSiftKernels();
  const SiftKernels& k = GetParam();
  std::mt19937 rng(5);
  const int width = 203;
  std::vector<float> above = RandomRow(width, rng), row = RandomRow(width, rng), below = RandomRow(width, rng);
  row[50] = row[52];  // dx = 0
  above[51] = below[51];
  std::vector<float> mag_ref(width), ang_ref(width), mag(width), ang(width);
  ref.gradient_row(above.data(), row.data(), below.data(), 1, width - 1, mag_ref.data(), ang_ref.data());
  k.gradient_row(above.data(), row.data(), below.data(), 1, width - 1, mag.data(), ang.data());
  for (int i = 0; i < width - 2; ++i) {
    const int x = i + 1;
    const double dx = row[x + 1] - row[x - 1];
    const double dy = below[x] - above[x];
    double truth = std::atan2(dy, dx);
    if (truth < 0) truth += 2 * M_PI;
    ASSERT_NEAR(mag[i], mag_ref[i], 1e-5f);
    ASSERT_NEAR(mag_ref[i], std::hypot(dx, dy), 1e-5);
    double err = std::fabs(ang_ref[i] - truth);
    err = std::min(err, 2 * M_PI - err);
    ASSERT_LT(err, 2e-5) << "reference atan2 at x=" << x;
    double diff = std::fabs(ang[i] - ang_ref[i]);
    diff = std::min(diff, 2 * M_PI - diff);
    ASSERT_LT(diff, 1e-5) << k.name << " x=" << x;
    ASSERT_GE(ang[i], 0.0f);
    ASSERT_LT(ang[i], static_cast<float>(2 * M_PI));
  }
}

INSTANTIATE_TEST_SUITE_P(AllAvailable, SiftKernelsTest, ::testing::ValuesIn(AvailableSiftKernels()),
                         [](const ::testing::TestParamInfo<SiftKernels>& param_info) {
                           return std::string(param_info.param.name);
                         });

TEST(SiftKernelsDispatch, ActiveIsTheWidestAvailable) {
  const std::vector<SiftKernels> available = AvailableSiftKernels();
  const SiftKernels& active = ActiveSiftKernels();
  EXPECT_STREQ(available.front().name, "scalar");
  bool found = false;
  for (const SiftKernels& k : available) found = found || k.convolve_row == active.convolve_row;
  EXPECT_TRUE(found);
  if (std::getenv("RECONAR_SIFT_KERNEL") == nullptr) {
    EXPECT_STREQ(active.name, available.back().name);
  }
#if defined(__aarch64__)
  EXPECT_STREQ(available.back().name, "neon");
#endif
}

}  // namespace
}  // namespace reconar
