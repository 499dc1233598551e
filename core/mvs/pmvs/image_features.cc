#include "core/mvs/pmvs/image_features.h"

#include <algorithm>
#include <cmath>

namespace reconar {
namespace {

struct FloatImage {
  int width = 0, height = 0;
  std::vector<float> pixels;
  FloatImage(int w, int h) : width(w), height(h), pixels(static_cast<size_t>(w) * h, 0.0f) {}
  float& at(int x, int y) { return pixels[static_cast<size_t>(y) * width + x]; }
  float at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

std::vector<float> GaussianKernel(double sigma) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  std::vector<float> kernel(2 * radius + 1);
  double sum = 0.0;
  for (int i = -radius; i <= radius; ++i) sum += kernel[i + radius] = static_cast<float>(std::exp(-0.5 * i * i / (sigma * sigma)));
  for (float& k : kernel) k = static_cast<float>(k / sum);
  return kernel;
}

// Separable Gaussian blur with clamped borders.
FloatImage Blur(const FloatImage& in, double sigma) {
  const std::vector<float> kernel = GaussianKernel(sigma);
  const int radius = static_cast<int>(kernel.size() / 2);
  FloatImage tmp(in.width, in.height), out(in.width, in.height);
  for (int y = 0; y < in.height; ++y) {
    for (int x = 0; x < in.width; ++x) {
      float s = 0.0f;
      for (int k = -radius; k <= radius; ++k) s += kernel[k + radius] * in.at(std::clamp(x + k, 0, in.width - 1), y);
      tmp.at(x, y) = s;
    }
  }
  for (int y = 0; y < in.height; ++y) {
    for (int x = 0; x < in.width; ++x) {
      float s = 0.0f;
      for (int k = -radius; k <= radius; ++k) s += kernel[k + radius] * tmp.at(x, std::clamp(y + k, 0, in.height - 1));
      out.at(x, y) = s;
    }
  }
  return out;
}

FloatImage HarrisResponse(const FloatImage& image, const SeedFeatureOptions& options) {
  const FloatImage smooth = Blur(image, options.harris_sigma);
  FloatImage xx(image.width, image.height), yy(image.width, image.height), xy(image.width, image.height);
  for (int y = 1; y + 1 < image.height; ++y) {
    for (int x = 1; x + 1 < image.width; ++x) {
      const float gx = 0.5f * (smooth.at(x + 1, y) - smooth.at(x - 1, y));
      const float gy = 0.5f * (smooth.at(x, y + 1) - smooth.at(x, y - 1));
      xx.at(x, y) = gx * gx;
      yy.at(x, y) = gy * gy;
      xy.at(x, y) = gx * gy;
    }
  }
  const FloatImage sxx = Blur(xx, options.harris_sigma), syy = Blur(yy, options.harris_sigma),
                   sxy = Blur(xy, options.harris_sigma);
  FloatImage response(image.width, image.height);
  const float k = static_cast<float>(options.harris_k);
  for (size_t i = 0; i < response.pixels.size(); ++i) {
    const float a = sxx.pixels[i], b = syy.pixels[i], c = sxy.pixels[i];
    response.pixels[i] = a * b - c * c - k * (a + b) * (a + b);
  }
  return response;
}

FloatImage DogResponse(const FloatImage& image, const SeedFeatureOptions& options) {
  const FloatImage fine = Blur(image, options.dog_sigma);
  const FloatImage coarse = Blur(image, options.dog_sigma * std::sqrt(2.0));
  FloatImage response(image.width, image.height);
  for (size_t i = 0; i < response.pixels.size(); ++i) response.pixels[i] = std::abs(fine.pixels[i] - coarse.pixels[i]);
  return response;
}

// The strongest `per_block` strict 3x3 local maxima of each block, away from a 4-pixel border.
void CollectBlockMaxima(const FloatImage& response, SeedFeature::Type type, const SeedFeatureOptions& options,
                        std::vector<SeedFeature>* features) {
  const int border = 4;
  std::vector<SeedFeature> block;
  for (int by = 0; by < response.height; by += options.block_size) {
    for (int bx = 0; bx < response.width; bx += options.block_size) {
      block.clear();
      const int y_end = std::min(by + options.block_size, response.height - border);
      const int x_end = std::min(bx + options.block_size, response.width - border);
      for (int y = std::max(by, border); y < y_end; ++y) {
        for (int x = std::max(bx, border); x < x_end; ++x) {
          const float v = response.at(x, y);
          if (!(v > 0.0f)) continue;
          bool is_max = true;
          for (int dy = -1; dy <= 1 && is_max; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
              if ((dx != 0 || dy != 0) && response.at(x + dx, y + dy) >= v) {
                is_max = false;
                break;
              }
            }
          }
          if (is_max) block.push_back({static_cast<float>(x), static_cast<float>(y), v, type});
        }
      }
      const size_t keep = std::min(block.size(), static_cast<size_t>(options.per_block));
      std::partial_sort(block.begin(), block.begin() + keep, block.end(),
                        [](const SeedFeature& a, const SeedFeature& b) { return a.response > b.response; });
      features->insert(features->end(), block.begin(), block.begin() + keep);
    }
  }
}

}  // namespace

std::vector<SeedFeature> DetectSeedFeatures(ImageView<const uint8_t> gray, const SeedFeatureOptions& options) {
  std::vector<SeedFeature> features;
  if (gray.width < 16 || gray.height < 16) return features;
  FloatImage image(gray.width, gray.height);
  for (int y = 0; y < gray.height; ++y) {
    for (int x = 0; x < gray.width; ++x) image.at(x, y) = gray.at(x, y);
  }
  CollectBlockMaxima(HarrisResponse(image, options), SeedFeature::kHarris, options, &features);
  CollectBlockMaxima(DogResponse(image, options), SeedFeature::kDog, options, &features);
  return features;
}

}  // namespace reconar
