#include "platform/camera/pixel_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace reconar {
namespace {

// BT.601 in floating point, straight from the standard's equations (independent of the fixed point).
void ReferenceRgb(int y, int cb, int cr, YuvRange range, double rgb[3]) {
  double luma = y;
  double u = cb - 128.0;
  double v = cr - 128.0;
  if (range == YuvRange::kLimited) {
    luma = (y - 16) * 255.0 / 219.0;
    u *= 255.0 / 224.0;
    v *= 255.0 / 224.0;
  }
  rgb[0] = luma + 1.402 * v;
  rgb[1] = luma - 0.344136 * u - 0.714136 * v;
  rgb[2] = luma + 1.772 * u;
  for (int c = 0; c < 3; ++c) rgb[c] = std::min(255.0, std::max(0.0, rgb[c]));
}

std::vector<uint8_t> OneYuyvPair(uint8_t y0, uint8_t cb, uint8_t y1, uint8_t cr) { return {y0, cb, y1, cr}; }

TEST(PixelConvert, LimitedRangeLumaEndpoints) {
  const std::vector<uint8_t> yuyv = {16, 128, 235, 128, 0, 128, 255, 128};
  std::vector<uint8_t> gray(4);
  YuyvToGray(ImageView<const uint8_t>(8, 1, 8, yuyv.data()), YuvConversionOptions{YuvRange::kLimited},
             ImageView<uint8_t>(4, 1, 4, gray.data()));
  EXPECT_EQ(gray[0], 0);
  EXPECT_EQ(gray[1], 255);
  EXPECT_EQ(gray[2], 0);    // below black: clamped
  EXPECT_EQ(gray[3], 255);  // above white: clamped
  ExtractYuyvLuma(ImageView<const uint8_t>(8, 1, 8, yuyv.data()), ImageView<uint8_t>(4, 1, 4, gray.data()));
  EXPECT_EQ(gray, (std::vector<uint8_t>{16, 235, 0, 255}));
}

TEST(PixelConvert, NeutralChromaGivesGrayRgb) {
  for (YuvRange range : {YuvRange::kLimited, YuvRange::kFull}) {
    for (int y = 0; y < 256; y += 17) {
      const std::vector<uint8_t> yuyv = OneYuyvPair(static_cast<uint8_t>(y), 128, static_cast<uint8_t>(y), 128);
      std::vector<uint8_t> rgb(6), gray(2);
      YuyvToRgb(ImageView<const uint8_t>(4, 1, 4, yuyv.data()), YuvConversionOptions{range},
                ImageView<uint8_t>(6, 1, 6, rgb.data()));
      YuyvToGray(ImageView<const uint8_t>(4, 1, 4, yuyv.data()), YuvConversionOptions{range},
                 ImageView<uint8_t>(2, 1, 2, gray.data()));
      for (int c = 0; c < 6; ++c) EXPECT_EQ(rgb[c], gray[c / 3]) << "Y=" << y;
      if (range == YuvRange::kFull) {
        EXPECT_EQ(gray[0], y);
      }
    }
  }
  // Limited-range endpoints in RGB too.
  const std::vector<uint8_t> yuyv = OneYuyvPair(16, 128, 235, 128);
  std::vector<uint8_t> rgb(6);
  YuyvToRgb(ImageView<const uint8_t>(4, 1, 4, yuyv.data()), YuvConversionOptions{YuvRange::kLimited},
            ImageView<uint8_t>(6, 1, 6, rgb.data()));
  EXPECT_EQ(rgb, (std::vector<uint8_t>{0, 0, 0, 255, 255, 255}));
}

TEST(PixelConvert, MatchesFloatingPointBt601WithinRounding) {
  for (YuvRange range : {YuvRange::kLimited, YuvRange::kFull}) {
    double worst = 0;
    for (int y = 0; y < 256; y += 5) {
      for (int cb = 0; cb < 256; cb += 15) {
        for (int cr = 0; cr < 256; cr += 15) {
          const std::vector<uint8_t> yuyv =
              OneYuyvPair(static_cast<uint8_t>(y), static_cast<uint8_t>(cb), static_cast<uint8_t>(y),
                          static_cast<uint8_t>(cr));
          std::vector<uint8_t> rgb(6);
          YuyvToRgb(ImageView<const uint8_t>(4, 1, 4, yuyv.data()), YuvConversionOptions{range},
                    ImageView<uint8_t>(6, 1, 6, rgb.data()));
          double expected[3];
          ReferenceRgb(y, cb, cr, range, expected);
          for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(rgb[c] - expected[c]));
          }
        }
      }
    }
    // Integer output of a real value: 0.5 from rounding, plus the 16-bit coefficient error.
    EXPECT_LT(worst, 0.51) << (range == YuvRange::kFull ? "full" : "limited");
  }
}

TEST(PixelConvert, KnownColoursFullRange) {
  // Pure red in JFIF: Y = 76.245, Cb = 84.97, Cr = 255.5 → (76, 85, 255) decodes to about (254, 0, 0).
  const std::vector<uint8_t> yuyv = OneYuyvPair(76, 85, 76, 255);
  std::vector<uint8_t> rgb(6);
  YuyvToRgb(ImageView<const uint8_t>(4, 1, 4, yuyv.data()), YuvConversionOptions{YuvRange::kFull},
            ImageView<uint8_t>(6, 1, 6, rgb.data()));
  EXPECT_NEAR(rgb[0], 255, 1);
  EXPECT_NEAR(rgb[1], 0, 1);
  EXPECT_NEAR(rgb[2], 0, 1);
}

// A 6x4 NV12 image with odd, padded strides, against the YUYV layout of the same samples.
TEST(PixelConvert, Nv12AndYuyvAgreeWithOddStrides) {
  const int w = 6, h = 4, luma_pitch = 9, yuyv_pitch = 13;
  std::vector<uint8_t> luma(luma_pitch * h, 0xEE), chroma(luma_pitch * h / 2, 0xEE), yuyv(yuyv_pitch * h, 0xEE);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) luma[y * luma_pitch + x] = static_cast<uint8_t>(20 + 30 * x + 7 * y);
  }
  for (int y = 0; y < h / 2; ++y) {
    for (int x = 0; x < w / 2; ++x) {
      chroma[y * luma_pitch + 2 * x] = static_cast<uint8_t>(60 + 40 * x + 10 * y);
      chroma[y * luma_pitch + 2 * x + 1] = static_cast<uint8_t>(200 - 50 * x - 20 * y);
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; x += 2) {
      uint8_t* p = &yuyv[y * yuyv_pitch + 2 * x];
      p[0] = luma[y * luma_pitch + x];
      p[1] = chroma[(y / 2) * luma_pitch + x];
      p[2] = luma[y * luma_pitch + x + 1];
      p[3] = chroma[(y / 2) * luma_pitch + x + 1];
    }
  }
  for (YuvRange range : {YuvRange::kLimited, YuvRange::kFull}) {
    const int rgb_pitch = 3 * w + 5;
    std::vector<uint8_t> from_nv12(rgb_pitch * h, 0), from_yuyv(rgb_pitch * h, 0);
    Nv12ToRgb(ImageView<const uint8_t>(w, h, luma_pitch, luma.data()),
              ImageView<const uint8_t>(w, h / 2, luma_pitch, chroma.data()), YuvConversionOptions{range},
              ImageView<uint8_t>(3 * w, h, rgb_pitch, from_nv12.data()));
    YuyvToRgb(ImageView<const uint8_t>(2 * w, h, yuyv_pitch, yuyv.data()), YuvConversionOptions{range},
              ImageView<uint8_t>(3 * w, h, rgb_pitch, from_yuyv.data()));
    EXPECT_EQ(from_nv12, from_yuyv);
    // Padding of the output rows stays untouched.
    for (int y = 0; y < h; ++y) EXPECT_EQ(from_nv12[y * rgb_pitch + 3 * w], 0);
    // Each pixel equals the single-pixel conversion of its own samples.
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const int pair = x & ~1;
        const std::vector<uint8_t> one = OneYuyvPair(luma[y * luma_pitch + x], chroma[(y / 2) * luma_pitch + pair],
                                                     luma[y * luma_pitch + x], chroma[(y / 2) * luma_pitch + pair + 1]);
        std::vector<uint8_t> rgb(6);
        YuyvToRgb(ImageView<const uint8_t>(4, 1, 4, one.data()), YuvConversionOptions{range},
                  ImageView<uint8_t>(6, 1, 6, rgb.data()));
        for (int c = 0; c < 3; ++c) EXPECT_EQ(from_nv12[y * rgb_pitch + 3 * x + c], rgb[c]);
      }
    }
  }
  std::vector<uint8_t> gray(w * h);
  LumaToGray(ImageView<const uint8_t>(w, h, luma_pitch, luma.data()), YuvConversionOptions{YuvRange::kFull},
             ImageView<uint8_t>(w, h, w, gray.data()));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) EXPECT_EQ(gray[y * w + x], luma[y * luma_pitch + x]);
  }
}

TEST(PixelConvert, PassthroughHelpers) {
  const std::vector<uint8_t> rgb = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
  std::vector<uint8_t> gray(4);
  RgbToGray(ImageView<const uint8_t>(12, 1, 12, rgb.data()), ImageView<uint8_t>(4, 1, 4, gray.data()));
  EXPECT_EQ(gray, (std::vector<uint8_t>{76, 150, 29, 255}));  // 0.299, 0.587, 0.114 of 255, rounded
  std::vector<uint8_t> back(12);
  GrayToRgb(ImageView<const uint8_t>(4, 1, 4, gray.data()), ImageView<uint8_t>(12, 1, 12, back.data()));
  EXPECT_EQ(back[3], 150);
  EXPECT_EQ(back[4], 150);
  EXPECT_EQ(back[5], 150);
}

}  // namespace
}  // namespace reconar
