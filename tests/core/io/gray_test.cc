#include "core/io/gray.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace reconar {
namespace {

Image<uint8_t> OnePixel(uint8_t r, uint8_t g, uint8_t b) {
  Image<uint8_t> image(1, 1, 3);
  image.data()[0] = r;
  image.data()[1] = g;
  image.data()[2] = b;
  return image;
}

TEST(GrayTest, Rec601Weights) {
  EXPECT_NEAR(ToGrayFloat(OnePixel(255, 0, 0)).data()[0], 0.299f, 1e-6f);
  EXPECT_NEAR(ToGrayFloat(OnePixel(0, 255, 0)).data()[0], 0.587f, 1e-6f);
  EXPECT_NEAR(ToGrayFloat(OnePixel(0, 0, 255)).data()[0], 0.114f, 1e-6f);
  EXPECT_EQ(ToGrayFloat(OnePixel(0, 0, 0)).data()[0], 0.0f);
  EXPECT_LE(ToGrayFloat(OnePixel(255, 255, 255)).data()[0], 1.0f);
  EXPECT_NEAR(ToGrayFloat(OnePixel(255, 255, 255)).data()[0], 1.0f, 1e-6f);
  EXPECT_EQ(ToGray8(OnePixel(255, 0, 0)).data()[0], 76);
  EXPECT_EQ(ToGray8(OnePixel(0, 255, 0)).data()[0], 150);
  EXPECT_EQ(ToGray8(OnePixel(0, 0, 255)).data()[0], 29);
}

TEST(GrayTest, GrayInputsStayExact) {
  for (int v = 0; v < 256; ++v) {
    const auto u = static_cast<uint8_t>(v);
    EXPECT_EQ(ToGray8(OnePixel(u, u, u)).data()[0], u);
    EXPECT_NEAR(ToGrayFloat(OnePixel(u, u, u)).data()[0], v / 255.0f, 1e-6f);
  }
}

TEST(GrayTest, Gray8MatchesRoundedFloatWithinOneLevel) {
  std::mt19937 rng(3);
  Image<uint8_t> rgb(64, 32, 3);
  for (size_t i = 0; i < rgb.size_bytes(); ++i) rgb.data()[i] = static_cast<uint8_t>(rng());
  const Image<uint8_t> gray8 = ToGray8(rgb);
  const Image<float> grayf = ToGrayFloat(rgb);
  ASSERT_EQ(gray8.channels(), 1);
  ASSERT_EQ(grayf.width(), 64);
  ASSERT_EQ(grayf.height(), 32);
  for (int i = 0; i < 64 * 32; ++i) {
    const uint8_t* p = rgb.data() + 3 * i;
    const double exact = 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
    EXPECT_LE(std::abs(gray8.data()[i] - exact), 0.51);
    EXPECT_NEAR(grayf.data()[i], exact / 255.0, 1e-5);
  }
}

TEST(GrayTest, SingleChannelInputIsScaled) {
  Image<uint8_t> gray(2, 1, 1);
  gray.data()[0] = 0;
  gray.data()[1] = 255;
  const Image<float> f = ToGrayFloat(gray);
  EXPECT_EQ(f.data()[0], 0.0f);
  EXPECT_EQ(f.data()[1], 1.0f);
  EXPECT_EQ(ToGray8(gray).data()[1], 255);
}

}  // namespace
}  // namespace reconar
