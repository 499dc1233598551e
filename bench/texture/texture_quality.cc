// How well renders of two models match the photos they were rendered for (the held-out photos of
// heldout_texture.sh): per photo, over the pixels both renders' coverage masks cover (eroded 3
// pixels, 4-connected, so that edge pixels mixing model and background do not count),
//  - PSNR over RGB, 255 peak;
//  - the same after each render's channels are scaled by the least-squares gain to the photo
//    (exposure-fitted: a camera on automatic exposes each photo its own way, which neither model
//    can know);
//  - SSIM of luma (the RGB mean), Gaussian window sigma 1.5 truncated at 3.5 sigma, mirrored at the
//    image border, C1 = (0.01 * 255)^2, C2 = (0.03 * 255)^2, averaged over the mask.
// Reads DIR/textured/NAME.png, DIR/textured/NAME.mask.png, DIR/textured/NAME.photo.png and
// DIR/vertex/NAME.png, DIR/vertex/NAME.mask.png (as `reconar render` writes them).
//
// Usage: texture_quality DIR NAME...
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/io/image_io.h"

namespace reconar {
namespace {

using Plane = std::vector<double>;

struct Metrics {
  double psnr = 0.0, psnr_fitted = 0.0, ssim = 0.0;
};

Result<Image<uint8_t>> Load(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(DecodedImage decoded, ReadImage(path));
  return std::move(decoded.rgb);
}

std::vector<uint8_t> Erode(const std::vector<uint8_t>& mask, int width, int height, int iterations) {
  std::vector<uint8_t> current = mask, next(mask.size());
  for (int it = 0; it < iterations; ++it) {
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const size_t i = static_cast<size_t>(y) * width + x;
        next[i] = current[i] && x > 0 && x + 1 < width && y > 0 && y + 1 < height && current[i - 1] &&
                  current[i + 1] && current[i - static_cast<size_t>(width)] && current[i + static_cast<size_t>(width)];
      }
    }
    current.swap(next);
  }
  return current;
}

// Separable Gaussian, mirrored border (d c b | a b c d | c b a is "reflect": a b | a b c d | d c).
Plane Blur(const Plane& in, int width, int height) {
  constexpr double kSigma = 1.5;
  const int radius = static_cast<int>(3.5 * kSigma + 0.5);
  std::vector<double> kernel(static_cast<size_t>(2 * radius + 1));
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k) sum += kernel[static_cast<size_t>(k + radius)] = std::exp(-0.5 * k * k / (kSigma * kSigma));
  for (double& w : kernel) w /= sum;
  auto reflect = [](int i, int n) {
    while (i < 0 || i >= n) i = i < 0 ? -i - 1 : 2 * n - i - 1;
    return i;
  };
  Plane horizontal(in.size()), out(in.size());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double acc = 0.0;
      for (int k = -radius; k <= radius; ++k) acc += kernel[static_cast<size_t>(k + radius)] * in[static_cast<size_t>(y) * width + reflect(x + k, width)];
      horizontal[static_cast<size_t>(y) * width + x] = acc;
    }
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double acc = 0.0;
      for (int k = -radius; k <= radius; ++k) acc += kernel[static_cast<size_t>(k + radius)] * horizontal[static_cast<size_t>(reflect(y + k, height)) * width + x];
      out[static_cast<size_t>(y) * width + x] = acc;
    }
  }
  return out;
}

double Psnr(double sum_squared, size_t count) { return 10.0 * std::log10(255.0 * 255.0 / (sum_squared / static_cast<double>(count))); }

Metrics Measure(const Image<uint8_t>& render, const Image<uint8_t>& photo, const std::vector<uint8_t>& mask) {
  const int width = photo.width(), height = photo.height();
  const size_t n = static_cast<size_t>(width) * height;
  Metrics metrics;
  size_t count = 0;
  double squared = 0.0;
  std::array<double, 3> render_photo{}, render_render{};
  for (size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    ++count;
    for (size_t c = 0; c < 3; ++c) {
      const double r = render.data()[3 * i + c], p = photo.data()[3 * i + c];
      squared += (r - p) * (r - p);
      render_photo[c] += r * p;
      render_render[c] += r * r;
    }
  }
  if (count == 0) return metrics;
  metrics.psnr = Psnr(squared / 3.0, count);
  double fitted = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    for (size_t c = 0; c < 3; ++c) {
      const double gain = render_render[c] > 0.0 ? render_photo[c] / render_render[c] : 1.0;
      const double r = std::clamp(gain * render.data()[3 * i + c], 0.0, 255.0), p = photo.data()[3 * i + c];
      fitted += (r - p) * (r - p);
    }
  }
  metrics.psnr_fitted = Psnr(fitted / 3.0, count);
  Plane a(n), b(n), aa(n), bb(n), ab(n);
  for (size_t i = 0; i < n; ++i) {
    a[i] = (render.data()[3 * i] + render.data()[3 * i + 1] + render.data()[3 * i + 2]) / 3.0;
    b[i] = (photo.data()[3 * i] + photo.data()[3 * i + 1] + photo.data()[3 * i + 2]) / 3.0;
    aa[i] = a[i] * a[i];
    bb[i] = b[i] * b[i];
    ab[i] = a[i] * b[i];
  }
  const Plane ma = Blur(a, width, height), mb = Blur(b, width, height), saa = Blur(aa, width, height),
              sbb = Blur(bb, width, height), sab = Blur(ab, width, height);
  constexpr double kC1 = (0.01 * 255) * (0.01 * 255), kC2 = (0.03 * 255) * (0.03 * 255);
  double ssim = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    const double var_a = saa[i] - ma[i] * ma[i], var_b = sbb[i] - mb[i] * mb[i], cov = sab[i] - ma[i] * mb[i];
    ssim += ((2 * ma[i] * mb[i] + kC1) * (2 * cov + kC2)) / ((ma[i] * ma[i] + mb[i] * mb[i] + kC1) * (var_a + var_b + kC2));
  }
  metrics.ssim = ssim / static_cast<double>(count);
  return metrics;
}

int Run(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: texture_quality DIR NAME...\n");
    return 2;
  }
  const std::string dir = argv[1];
  const char* kinds[2] = {"textured", "vertex"};
  std::array<Metrics, 2> mean{};
  int photos = 0;
  for (int arg = 2; arg < argc; ++arg) {
    const std::string name = argv[arg];
    auto photo = Load(dir + "/textured/" + name + ".photo.png");
    if (!photo.ok()) {
      std::fprintf(stderr, "texture_quality: %s\n", photo.status().ToString().c_str());
      return 1;
    }
    const size_t n = static_cast<size_t>(photo->width()) * photo->height();
    std::vector<uint8_t> mask(n, 1);
    std::array<Image<uint8_t>, 2> renders;
    for (int k = 0; k < 2; ++k) {
      const std::string base = dir + "/" + kinds[k] + "/" + name;
      auto render = Load(base + ".png");
      auto coverage = Load(base + ".mask.png");
      if (!render.ok() || !coverage.ok()) {
        std::fprintf(stderr, "texture_quality: %s\n",
                     (render.ok() ? coverage.status() : render.status()).ToString().c_str());
        return 1;
      }
      if (render->width() != photo->width() || render->height() != photo->height() ||
          coverage->width() != photo->width() || coverage->height() != photo->height()) {
        std::fprintf(stderr, "texture_quality: %s: renders and photo differ in size\n", base.c_str());
        return 1;
      }
      for (size_t i = 0; i < n; ++i) mask[i] = mask[i] && coverage->data()[3 * i] > 127;
      renders[static_cast<size_t>(k)] = std::move(*render);
    }
    mask = Erode(mask, photo->width(), photo->height(), 3);
    std::printf("%-16s", name.c_str());
    for (int k = 0; k < 2; ++k) {
      const Metrics m = Measure(renders[static_cast<size_t>(k)], *photo, mask);
      std::printf("  %s %6.2f dB (exposure-fitted %6.2f) SSIM %.3f", kinds[k], m.psnr, m.psnr_fitted, m.ssim);
      mean[static_cast<size_t>(k)].psnr += m.psnr;
      mean[static_cast<size_t>(k)].psnr_fitted += m.psnr_fitted;
      mean[static_cast<size_t>(k)].ssim += m.ssim;
    }
    std::printf("\n");
    ++photos;
  }
  std::printf("%-16s", "MEAN");
  for (int k = 0; k < 2; ++k) {
    const Metrics& m = mean[static_cast<size_t>(k)];
    std::printf("  %s %6.2f dB (exposure-fitted %6.2f) SSIM %.3f", kinds[k], m.psnr / photos, m.psnr_fitted / photos,
                m.ssim / photos);
  }
  std::printf("\n%-16s  textured - vertex: %+.2f dB (exposure-fitted %+.2f), SSIM %+.3f\n", "",
              (mean[0].psnr - mean[1].psnr) / photos, (mean[0].psnr_fitted - mean[1].psnr_fitted) / photos,
              (mean[0].ssim - mean[1].ssim) / photos);
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
