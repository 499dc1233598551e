#include "core/io/gray.h"

#include <type_traits>

#include "core/base/check.h"

namespace reconar {

namespace {

// Rec.601 weights in 16-bit fixed point; they sum to 65536 so white stays 255.
constexpr uint32_t kWeightR = 19595;  // 0.299
constexpr uint32_t kWeightG = 38470;  // 0.587
constexpr uint32_t kWeightB = 7471;   // 0.114

void CheckChannels(const Image<uint8_t>& image) {
  RECONAR_CHECK(image.channels() == 1 || image.channels() == 3 || image.channels() == 4)
      << "gray conversion needs 1, 3 or 4 channels, got " << image.channels();
}

}  // namespace

void Gray8ToFloat(ImageView<const uint8_t> gray, ImageView<float> out) {
  RECONAR_CHECK(out.width == gray.width && out.height == gray.height)
      << "Gray8ToFloat: " << gray.width << "x" << gray.height << " into " << out.width << "x" << out.height;
  for (int y = 0; y < gray.height; ++y) {
    const uint8_t* in = gray.row(y);
    float* row = out.row(y);
    for (int x = 0; x < gray.width; ++x) row[x] = in[x] * (1.0f / 255.0f);
  }
}

Image<float> ToGrayFloat(const Image<uint8_t>& rgb) {
  CheckChannels(rgb);
  Image<float> gray(rgb.width(), rgb.height(), 1);
  const int c = rgb.channels();
  const size_t n = static_cast<size_t>(rgb.width()) * rgb.height();
  const uint8_t* src = rgb.data();
  float* dst = gray.data();
  if (c == 1) {
    Gray8ToFloat(rgb.view(), gray.view());
    return gray;
  }
  constexpr float kR = 0.299f / 255.0f;
  constexpr float kG = 0.587f / 255.0f;
  constexpr float kB = 0.114f / 255.0f;
  // A constant stride lets the compiler vectorise the common RGB case.
  const auto convert = [&](auto stride) {
    for (size_t i = 0; i < n; ++i) {
      const uint8_t* p = src + i * stride;
      const float v = kR * p[0] + kG * p[1] + kB * p[2];
      dst[i] = v > 1.0f ? 1.0f : v;  // the float weights may sum to a hair above 1
    }
  };
  if (c == 3) {
    convert(std::integral_constant<size_t, 3>());
  } else {
    convert(std::integral_constant<size_t, 4>());
  }
  return gray;
}

Image<uint8_t> ToGray8(const Image<uint8_t>& rgb) {
  CheckChannels(rgb);
  if (rgb.channels() == 1) return rgb;
  Image<uint8_t> gray(rgb.width(), rgb.height(), 1);
  const int c = rgb.channels();
  const size_t n = static_cast<size_t>(rgb.width()) * rgb.height();
  const uint8_t* src = rgb.data();
  uint8_t* dst = gray.data();
  const auto convert = [&](auto stride) {
    for (size_t i = 0; i < n; ++i) {
      const uint8_t* p = src + i * stride;
      dst[i] = static_cast<uint8_t>((kWeightR * p[0] + kWeightG * p[1] + kWeightB * p[2] + 32768) >> 16);
    }
  };
  if (c == 3) {
    convert(std::integral_constant<size_t, 3>());
  } else {
    convert(std::integral_constant<size_t, 4>());
  }
  return gray;
}

}  // namespace reconar
