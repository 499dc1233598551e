#include "core/features/sift/sift.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>

#include "core/base/elapsed.h"
#include "core/features/sift/kernels_dispatch.h"

namespace reconar {
namespace {

constexpr int kBorder = 5;              // no keypoints closer than this to an octave's edge
using sift_internal::kMaxKernelRadius;
constexpr int kMaxRefineSteps = 5;
constexpr int kOrientationBins = 36;
constexpr float kOrientationSigmaFactor = 1.5f;  // window sigma = 1.5 * keypoint sigma (Lowe 5)
constexpr float kOrientationRadiusFactor = 3.0f;
constexpr float kOrientationPeakRatio = 0.8f;
constexpr int kDescriptorWidth = 4;   // 4x4 spatial cells
constexpr int kDescriptorBins = 8;    // 8 orientations each
constexpr float kDescriptorCellFactor = 3.0f;  // a cell spans 3 keypoint sigmas
constexpr float kDescriptorClip = 0.2f;
constexpr float kDescriptorQuantisation = 512.0f;
constexpr float kTwoPi = 2.0f * sift_internal::kPi;

using Clock = std::chrono::steady_clock;
int Reflect101(int i, int n) {
  if (n == 1) return 0;
  while (i < 0 || i >= n) {
    if (i < 0) i = -i;
    if (i >= n) i = 2 * n - 2 - i;
  }
  return i;
}

struct GaussianKernel {
  int radius = 0;
  std::array<float, kMaxKernelRadius + 1> taps{};
};

GaussianKernel MakeGaussianKernel(double sigma) {
  GaussianKernel kernel;
  kernel.radius = std::clamp(static_cast<int>(std::lround(4.0 * sigma)), 1, kMaxKernelRadius);
  double sum = 0;
  std::array<double, kMaxKernelRadius + 1> taps{};
  for (int i = 0; i <= kernel.radius; ++i) {
    taps[i] = std::exp(-0.5 * i * i / (sigma * sigma));
    sum += i == 0 ? taps[i] : 2 * taps[i];
  }
  for (int i = 0; i <= kernel.radius; ++i) kernel.taps[i] = static_cast<float>(taps[i] / sum);
  return kernel;
}

int FirstOctaveWidth(int width, int first_octave) { return first_octave < 0 ? 2 * width : width; }

int CountOctaves(int width, int height, const SiftOptions& options) {
  int w = FirstOctaveWidth(width, options.first_octave);
  int h = FirstOctaveWidth(height, options.first_octave);
  int count = 0;
  while (std::min(w, h) >= 16 && (options.max_octaves <= 0 || count < options.max_octaves)) {
    ++count;
    w /= 2;
    h /= 2;
  }
  return count;
}

// Largest descriptor window half-width for any keypoint (sigma below sigma * 2^((S+1)/S)).
int MaxWindowRadius(const SiftOptions& options) {
  const double max_sigma = options.sigma * std::pow(2.0, (options.levels_per_octave + 1.0) / options.levels_per_octave);
  const double descriptor = kDescriptorCellFactor * max_sigma * std::sqrt(2.0) * (kDescriptorWidth + 1) * 0.5;
  const double orientation = kOrientationRadiusFactor * kOrientationSigmaFactor * max_sigma;
  return static_cast<int>(std::ceil(std::max(descriptor, orientation))) + 1;
}

// Working memory of one extraction, carved from the arena once per image.
struct Scratch {
  float* planes[4];
  bool plane_used[4] = {false, false, false, false};
  float* padded_row;          // two rows of width + 3 * kMaxKernelRadius
  const float** row_pointers; // 2 * kMaxKernelRadius + 2
  float* dog_rows;            // 9 rows
  int32_t* candidates;        // width
  float* magnitude_row;       // width
  float* angle_row;           // width
  float* weights_x;           // 2 * window radius + 1
  float* weights_y;
};

ImageView<float> AcquirePlane(Scratch& scratch, int width, int height) {
  for (int i = 0; i < 4; ++i) {
    if (!scratch.plane_used[i]) {
      scratch.plane_used[i] = true;
      return ImageView<float>(width, height, width, scratch.planes[i]);
    }
  }
  RECONAR_CHECK(false) << "SIFT plane pool exhausted";
  return {};
}

void ReleasePlane(Scratch& scratch, const ImageView<float>& plane) {
  for (int i = 0; i < 4; ++i) {
    if (scratch.planes[i] == plane.data) scratch.plane_used[i] = false;
  }
}

// Separable blur, two rows at a time: columns into two padded rows, then along each row. No
// temporary plane; each input row is loaded once per output pair.
void Blur(const SiftKernels& kernels, ImageView<const float> src, ImageView<float> dst, const GaussianKernel& kernel,
          Scratch& scratch) {
  const int r = kernel.radius;
  const int w = src.width;
  float* padded[2] = {scratch.padded_row + kMaxKernelRadius,
                      scratch.padded_row + (w + 3 * kMaxKernelRadius) + kMaxKernelRadius};
  const auto pad = [&](float* row) {
    for (int i = 1; i <= r; ++i) {
      row[-i] = row[Reflect101(-i, w)];
      row[w - 1 + i] = row[Reflect101(w - 1 + i, w)];
    }
  };
  int y = 0;
  for (; y + 1 < src.height; y += 2) {
    for (int i = -r; i <= r + 1; ++i) scratch.row_pointers[i + r] = src.row(Reflect101(y + i, src.height));
    kernels.convolve_columns2(scratch.row_pointers, kernel.taps.data(), r, w, padded[0], padded[1]);
    for (int k = 0; k < 2; ++k) {
      pad(padded[k]);
      kernels.convolve_row(padded[k], kernel.taps.data(), r, w, dst.row(y + k));
    }
  }
  if (y < src.height) {
    for (int i = -r; i <= r; ++i) scratch.row_pointers[i + r] = src.row(Reflect101(y + i, src.height));
    kernels.convolve_columns(scratch.row_pointers, kernel.taps.data(), r, w, padded[0]);
    pad(padded[0]);
    kernels.convolve_row(padded[0], kernel.taps.data(), r, w, dst.row(y));
  }
}

// Doubles the image with sample (2x, 2y) = input (x, y), so coordinates map exactly by a factor 2.
void Upsample(ImageView<const float> src, ImageView<float> dst) {
  const int w = src.width;
  for (int y = 0; y < src.height; ++y) {
    const float* in = src.row(y);
    float* out = dst.row(2 * y);
    for (int x = 0; x + 1 < w; ++x) {
      out[2 * x] = in[x];
      out[2 * x + 1] = 0.5f * (in[x] + in[x + 1]);
    }
    out[2 * w - 2] = in[w - 1];
    out[2 * w - 1] = in[w - 1];
  }
  for (int y = 0; y < src.height; ++y) {
    const float* a = dst.row(2 * y);
    const float* b = dst.row(std::min(2 * y + 2, 2 * src.height - 2));
    float* out = dst.row(2 * y + 1);
    for (int x = 0; x < dst.width; ++x) out[x] = 0.5f * (a[x] + b[x]);
  }
}

void Downsample(ImageView<const float> src, ImageView<float> dst) {
  for (int y = 0; y < dst.height; ++y) {
    const float* in = src.row(2 * y);
    float* out = dst.row(y);
    for (int x = 0; x < dst.width; ++x) out[x] = in[2 * x];
  }
}

// The four Gaussian levels around DoG level d: g[0] = G(d-1) ... g[3] = G(d+2).
struct LevelWindow {
  ImageView<const float> g[4];
  float D(int level, int x, int y) const { return g[level + 1].at(x, y) - g[level].at(x, y); }
};

struct RefinedExtremum {
  float x, y;       // octave pixels
  float level;      // d + offset
  float response;   // |D| at the interpolated extremum
};

// Newton steps on the DoG (Lowe 2004 sec. 4, Brown & Lowe 2002); moves in x and y only, so the
// level window stays fixed. Returns false for unstable, low-contrast or edge-like extrema.
bool RefineExtremum(const LevelWindow& window, int d, int xi, int yi, const SiftOptions& options,
                    RefinedExtremum* out) {
  const int w = window.g[0].width;
  const int h = window.g[0].height;
  double offset[3] = {0, 0, 0};
  double gradient[3] = {0, 0, 0};
  double hxx = 0, hyy = 0, hxy = 0;
  bool converged = false;
  for (int step = 0; step < kMaxRefineSteps; ++step) {
    const double v2 = 2.0 * window.D(1, xi, yi);
    const double dx = 0.5 * (window.D(1, xi + 1, yi) - window.D(1, xi - 1, yi));
    const double dy = 0.5 * (window.D(1, xi, yi + 1) - window.D(1, xi, yi - 1));
    const double ds = 0.5 * (window.D(2, xi, yi) - window.D(0, xi, yi));
    hxx = window.D(1, xi + 1, yi) + window.D(1, xi - 1, yi) - v2;
    hyy = window.D(1, xi, yi + 1) + window.D(1, xi, yi - 1) - v2;
    const double hss = window.D(2, xi, yi) + window.D(0, xi, yi) - v2;
    hxy = 0.25 * (window.D(1, xi + 1, yi + 1) - window.D(1, xi - 1, yi + 1) - window.D(1, xi + 1, yi - 1) +
                  window.D(1, xi - 1, yi - 1));
    const double hxs = 0.25 * (window.D(2, xi + 1, yi) - window.D(2, xi - 1, yi) - window.D(0, xi + 1, yi) +
                               window.D(0, xi - 1, yi));
    const double hys = 0.25 * (window.D(2, xi, yi + 1) - window.D(2, xi, yi - 1) - window.D(0, xi, yi + 1) +
                               window.D(0, xi, yi - 1));
    // Solve H * offset = -gradient by the adjugate.
    const double c00 = hyy * hss - hys * hys, c01 = hxs * hys - hxy * hss, c02 = hxy * hys - hxs * hyy;
    const double c11 = hxx * hss - hxs * hxs, c12 = hxy * hxs - hxx * hys, c22 = hxx * hyy - hxy * hxy;
    const double det = hxx * c00 + hxy * c01 + hxs * c02;
    if (!(std::fabs(det) > 1e-20)) return false;
    gradient[0] = dx;
    gradient[1] = dy;
    gradient[2] = ds;
    offset[0] = -(c00 * dx + c01 * dy + c02 * ds) / det;
    offset[1] = -(c01 * dx + c11 * dy + c12 * ds) / det;
    offset[2] = -(c02 * dx + c12 * dy + c22 * ds) / det;
    if (std::fabs(offset[0]) <= 0.5 && std::fabs(offset[1]) <= 0.5) {
      converged = true;
      break;
    }
    if (std::fabs(offset[0]) > 3 || std::fabs(offset[1]) > 3) return false;
    xi += static_cast<int>(std::lround(offset[0]));
    yi += static_cast<int>(std::lround(offset[1]));
    if (xi < kBorder || xi >= w - kBorder || yi < kBorder || yi >= h - kBorder) return false;
  }
  if (!converged || std::fabs(offset[2]) >= 1.0) return false;
  const double contrast =
      window.D(1, xi, yi) + 0.5 * (gradient[0] * offset[0] + gradient[1] * offset[1] + gradient[2] * offset[2]);
  if (std::fabs(contrast) * options.levels_per_octave < options.contrast_threshold) return false;
  const double trace = hxx + hyy;
  const double det2 = hxx * hyy - hxy * hxy;
  const double r = options.edge_threshold;
  if (det2 <= 0 || trace * trace * r >= (r + 1) * (r + 1) * det2) return false;
  out->x = static_cast<float>(xi + offset[0]);
  out->y = static_cast<float>(yi + offset[1]);
  out->level = static_cast<float>(d + offset[2]);
  out->response = static_cast<float>(std::fabs(contrast));
  return true;
}

// Fills weights[i] = exp(-(centre_int + i - radius - centre)^2 / (2 sigma^2)) for i in [0, 2r].
void GaussianWeights(int centre_int, float centre, int radius, float sigma, float* weights) {
  const float scale = -0.5f / (sigma * sigma);
  for (int i = -radius; i <= radius; ++i) {
    const float d = static_cast<float>(centre_int + i) - centre;
    weights[i + radius] = std::exp(d * d * scale);
  }
}

// Dominant gradient orientations around a keypoint (Lowe 2004 sec. 5). Returns how many.
int ComputeOrientations(const SiftKernels& kernels, ImageView<const float> g, float x, float y, float sigma,
                        const SiftOptions& options, Scratch& scratch, float* orientations) {
  const float window_sigma = kOrientationSigmaFactor * sigma;
  const int radius = static_cast<int>(std::lround(kOrientationRadiusFactor * window_sigma));
  const int xi = static_cast<int>(std::lround(x));
  const int yi = static_cast<int>(std::lround(y));
  GaussianWeights(xi, x, radius, window_sigma, scratch.weights_x);
  GaussianWeights(yi, y, radius, window_sigma, scratch.weights_y);
  const int x_begin = std::max(xi - radius, 1);
  const int x_end = std::min(xi + radius + 1, g.width - 1);
  float hist[kOrientationBins] = {};
  constexpr float kBinsPerRadian = kOrientationBins / kTwoPi;
  for (int yy = std::max(yi - radius, 1); yy <= std::min(yi + radius, g.height - 2); ++yy) {
    kernels.gradient_row(g.row(yy - 1), g.row(yy), g.row(yy + 1), x_begin, x_end, scratch.magnitude_row,
                         scratch.angle_row);
    const float wy = scratch.weights_y[yy - yi + radius];
    for (int xx = x_begin; xx < x_end; ++xx) {
      const float weight = wy * scratch.weights_x[xx - xi + radius] * scratch.magnitude_row[xx - x_begin];
      const float bin = scratch.angle_row[xx - x_begin] * kBinsPerRadian;
      int b0 = static_cast<int>(bin);
      const float frac = bin - static_cast<float>(b0);
      if (b0 >= kOrientationBins) b0 -= kOrientationBins;
      const int b1 = b0 + 1 == kOrientationBins ? 0 : b0 + 1;
      hist[b0] += (1.0f - frac) * weight;
      hist[b1] += frac * weight;
    }
  }
  float smooth[kOrientationBins];
  for (int i = 0; i < kOrientationBins; ++i) {
    const auto at = [&](int k) { return hist[(k + kOrientationBins) % kOrientationBins]; };
    smooth[i] = (at(i - 2) + at(i + 2)) * (1.0f / 16) + (at(i - 1) + at(i + 1)) * (4.0f / 16) + at(i) * (6.0f / 16);
  }
  const float max_value = *std::max_element(smooth, smooth + kOrientationBins);
  if (!(max_value > 0)) return 0;
  int count = 0;
  for (int i = 0; i < kOrientationBins && count < options.max_orientations; ++i) {
    const float left = smooth[(i + kOrientationBins - 1) % kOrientationBins];
    const float right = smooth[(i + 1) % kOrientationBins];
    const float centre = smooth[i];
    if (centre > left && centre > right && centre >= kOrientationPeakRatio * max_value) {
      const float offset = 0.5f * (left - right) / (left - 2 * centre + right);
      float angle = (static_cast<float>(i) + offset) / kBinsPerRadian;
      if (angle < 0) angle += kTwoPi;
      if (angle >= kTwoPi) angle -= kTwoPi;
      orientations[count++] = angle;
    }
  }
  return count;
}

// Narrows [lo, hi] to the dx with |a*dx + b| < half_width; false when that set is empty.
bool IntersectSlab(float a, float b, float half_width, float* lo, float* hi) {
  if (std::fabs(a) < 1e-12f) return std::fabs(b) < half_width;
  const float t1 = (-half_width - b) / a;
  const float t2 = (half_width - b) / a;
  *lo = std::max(*lo, std::min(t1, t2));
  *hi = std::min(*hi, std::max(t1, t2));
  return *lo <= *hi;
}

// 4x4x8 descriptor with trilinear binning, normalise / clip 0.2 / renormalise (Lowe 2004 sec. 6).
void ComputeDescriptor(const SiftKernels& kernels, ImageView<const float> g, float x, float y, float sigma,
                       float orientation, Scratch& scratch, uint8_t* descriptor) {
  constexpr int d = kDescriptorWidth;
  constexpr int n = kDescriptorBins;
  const float cell = kDescriptorCellFactor * sigma;
  int radius = static_cast<int>(std::lround(cell * std::sqrt(2.0f) * (d + 1) * 0.5f));
  const int xi = static_cast<int>(std::lround(x));
  const int yi = static_cast<int>(std::lround(y));
  const float cos_t = std::cos(orientation) / cell;
  const float sin_t = std::sin(orientation) / cell;
  // Gaussian of sigma d/2 cells is separable in the unrotated offsets.
  GaussianWeights(xi, x, radius, 0.5f * d * cell, scratch.weights_x);
  GaussianWeights(yi, y, radius, 0.5f * d * cell, scratch.weights_y);
  // Neighbouring samples hit the same bins; two interleaved histograms halve the chains of
  // dependent read-modify-writes through memory. They are summed at the end.
  constexpr int kHistSize = (d + 2) * (d + 2) * n;
  float hists[2][kHistSize] = {};
  const int x_begin = std::max(xi - radius, 1);
  const int x_end = std::min(xi + radius + 1, g.width - 1);
  constexpr float kBinsPerRadian = n / kTwoPi;
  // Samples contribute only inside the rotated square |c_rot|, |r_rot| < d/2 + 1/2 (in cells).
  constexpr float kHalfExtent = 0.5f * d + 0.5f;
  for (int yy = std::max(yi - radius, 1); yy <= std::min(yi + radius, g.height - 2); ++yy) {
    const float dy = static_cast<float>(yy) - y;
    float lo = -1e30f, hi = 1e30f;
    if (!IntersectSlab(cos_t, dy * sin_t, kHalfExtent, &lo, &hi) ||
        !IntersectSlab(-sin_t, dy * cos_t, kHalfExtent, &lo, &hi)) {
      continue;
    }
    const int row_begin = std::max(x_begin, static_cast<int>(std::floor(x + lo)));
    const int row_end = std::min(x_end, static_cast<int>(std::ceil(x + hi)) + 1);
    if (row_begin >= row_end) continue;
    kernels.gradient_row(g.row(yy - 1), g.row(yy), g.row(yy + 1), row_begin, row_end, scratch.magnitude_row,
                         scratch.angle_row);
    const float wy = scratch.weights_y[yy - yi + radius];
    for (int xx = row_begin; xx < row_end; ++xx) {
      const float dx = static_cast<float>(xx) - x;
      const float c_rot = dx * cos_t + dy * sin_t;
      const float r_rot = -dx * sin_t + dy * cos_t;
      const float rbin = r_rot + 0.5f * d - 0.5f;
      const float cbin = c_rot + 0.5f * d - 0.5f;
      if (!(rbin > -1.0f && rbin < d && cbin > -1.0f && cbin < d)) continue;
      float obin = (scratch.angle_row[xx - row_begin] - orientation) * kBinsPerRadian;
      if (obin < 0) obin += n;
      if (obin >= n) obin -= n;
      const float value = scratch.magnitude_row[xx - row_begin] * wy * scratch.weights_x[xx - xi + radius];
      // rbin, cbin > -1, so truncating rbin + 1 is floor(rbin) + 1 without a libm call.
      const int r0 = static_cast<int>(rbin + 1.0f) - 1;
      const int c0 = static_cast<int>(cbin + 1.0f) - 1;
      int o0 = static_cast<int>(obin);
      const float fr = rbin - static_cast<float>(r0);
      const float fc = cbin - static_cast<float>(c0);
      const float fo = obin - static_cast<float>(o0);
      if (o0 >= n) o0 -= n;
      const int o1 = o0 + 1 == n ? 0 : o0 + 1;
      // Cells are offset by one so that r0 = -1 and c0 = -1 land in the padding row/column.
      for (int ir = 0; ir < 2; ++ir) {
        const float vr = ir == 0 ? value * (1 - fr) : value * fr;
        for (int ic = 0; ic < 2; ++ic) {
          const float vc = ic == 0 ? vr * (1 - fc) : vr * fc;
          float* bins = hists[xx & 1] + ((r0 + 1 + ir) * (d + 2) + (c0 + 1 + ic)) * n;
          bins[o0] += vc * (1 - fo);
          bins[o1] += vc * fo;
        }
      }
    }
  }
  float values[d * d * n];
  for (int r = 0; r < d; ++r) {
    for (int c = 0; c < d; ++c) {
      const int offset = ((r + 1) * (d + 2) + (c + 1)) * n;
      for (int k = 0; k < n; ++k) values[(r * d + c) * n + k] = hists[0][offset + k] + hists[1][offset + k];
    }
  }
  float norm2 = 0;
  for (float v : values) norm2 += v * v;
  const float clip = kDescriptorClip * std::sqrt(norm2);
  norm2 = 0;
  for (float& v : values) {
    v = std::min(v, clip);
    norm2 += v * v;
  }
  const float scale = norm2 > 0 ? kDescriptorQuantisation / std::sqrt(norm2) : 0.0f;
  for (int i = 0; i < d * d * n; ++i) {
    descriptor[i] = static_cast<uint8_t>(std::min(255.0f, std::round(values[i] * scale)));
  }
}

}  // namespace

Status SiftOptions::Check() const {
  if (first_octave != -1 && first_octave != 0) {
    return InvalidArgument("SIFT first octave must be -1 or 0, got " + std::to_string(first_octave));
  }
  if (levels_per_octave < 1 || levels_per_octave > 8) {
    return InvalidArgument("SIFT levels per octave must be in [1, 8], got " + std::to_string(levels_per_octave));
  }
  if (!(sigma > 0.5 && sigma < 5.0)) return InvalidArgument("SIFT sigma must be in (0.5, 5)");
  if (!(input_blur >= 0 && input_blur < sigma)) return InvalidArgument("SIFT input blur must be in [0, sigma)");
  if (!(contrast_threshold >= 0)) return InvalidArgument("SIFT contrast threshold must be >= 0");
  if (!(edge_threshold > 1)) return InvalidArgument("SIFT edge threshold must be > 1");
  if (max_orientations < 1) return InvalidArgument("SIFT max orientations must be >= 1");
  if (max_features < 0) return InvalidArgument("SIFT max features must be >= 0");
  return Status::Ok();
}

size_t SiftExtractor::RequiredArenaBytes(int width, int height, const SiftOptions& options) {
  const size_t w = static_cast<size_t>(FirstOctaveWidth(width, options.first_octave));
  const size_t h = static_cast<size_t>(FirstOctaveWidth(height, options.first_octave));
  const size_t window = 2 * static_cast<size_t>(MaxWindowRadius(options)) + 1;
  const size_t floats = 4 * w * h + 2 * (w + 3 * kMaxKernelRadius) + 9 * w + 2 * w + 2 * window;
  const size_t bytes = floats * sizeof(float) + w * sizeof(int32_t) +
                       (2 * kMaxKernelRadius + 2) * sizeof(float*);
  constexpr size_t kAllocations = 16;
  return bytes + kAllocations * Arena::kDefaultAlignment;
}

SiftExtractor::SiftExtractor(const SiftOptions& options) : options_(options), arena_(options.arena_bytes) {}

Result<SiftFeatures> SiftExtractor::Extract(ImageView<const float> gray, SiftReport* report) {
  RECONAR_RETURN_IF_ERROR(options_.Check());
  if (gray.empty() || gray.width < 16 || gray.height < 16) {
    return InvalidArgument("image of " + std::to_string(gray.width) + "x" + std::to_string(gray.height) +
                           " is too small for SIFT (at least 16x16)");
  }
  const size_t needed = RequiredArenaBytes(gray.width, gray.height, options_);
  if (needed > arena_.capacity()) {
    return ResourceExhausted("SIFT on a " + std::to_string(gray.width) + "x" + std::to_string(gray.height) +
                             " image at first octave " + std::to_string(options_.first_octave) + " needs " +
                             std::to_string(needed >> 20) + " MiB of working memory but the arena holds " +
                             std::to_string(arena_.capacity() >> 20) +
                             " MiB; raise the memory budget or use --first-octave 0");
  }
  SiftReport local_report;
  SiftReport& rep = report != nullptr ? *report : local_report;
  rep = SiftReport();
  const SiftKernels& kernels = ActiveSiftKernels();
  rep.kernels = kernels.name;

  Arena::Scope scope(arena_);
  const int base_w = FirstOctaveWidth(gray.width, options_.first_octave);
  const int base_h = FirstOctaveWidth(gray.height, options_.first_octave);
  const int window = 2 * MaxWindowRadius(options_) + 1;
  Scratch scratch;
  for (auto& plane : scratch.planes) plane = arena_.AllocateArray<float>(static_cast<size_t>(base_w) * base_h);
  scratch.padded_row = arena_.AllocateArray<float>(2 * (base_w + 3 * kMaxKernelRadius));
  scratch.row_pointers = arena_.AllocateArray<const float*>(2 * kMaxKernelRadius + 2);
  scratch.dog_rows = arena_.AllocateArray<float>(9 * static_cast<size_t>(base_w));
  scratch.candidates = arena_.AllocateArray<int32_t>(base_w);
  scratch.magnitude_row = arena_.AllocateArray<float>(base_w);
  scratch.angle_row = arena_.AllocateArray<float>(base_w);
  scratch.weights_x = arena_.AllocateArray<float>(window);
  scratch.weights_y = arena_.AllocateArray<float>(window);
  if (arena_.failed_allocations() > 0) return Internal("SIFT arena sizing is inconsistent with its use");

  const int S = options_.levels_per_octave;
  std::vector<GaussianKernel> increments(S + 3);
  for (int s = 1; s < S + 3; ++s) {
    const double previous = options_.sigma * std::pow(2.0, (s - 1.0) / S);
    const double current = options_.sigma * std::pow(2.0, static_cast<double>(s) / S);
    increments[s] = MakeGaussianKernel(std::sqrt(current * current - previous * previous));
  }
  const double blur_present = options_.input_blur * (options_.first_octave < 0 ? 2.0 : 1.0);
  const GaussianKernel initial =
      MakeGaussianKernel(std::sqrt(options_.sigma * options_.sigma - blur_present * blur_present));
  const float prefilter = static_cast<float>(0.5 * options_.contrast_threshold / S);

  SiftFeatures features;
  features.keypoints.reserve(8192);
  features.descriptors.reserve(8192 * 128);

  // Octave base.
  auto start = Clock::now();
  ImageView<float> base = AcquirePlane(scratch, base_w, base_h);
  if (options_.first_octave < 0) {
    ImageView<float> doubled = AcquirePlane(scratch, base_w, base_h);
    Upsample(gray, doubled);
    Blur(kernels, doubled, base, initial, scratch);
    ReleasePlane(scratch, doubled);
  } else {
    Blur(kernels, gray, base, initial, scratch);
  }
  rep.seconds_pyramid += SecondsSince(start);

  const int num_octaves = CountOctaves(gray.width, gray.height, options_);
  rep.num_octaves = num_octaves;
  std::vector<ImageView<float>> levels(S + 3);
  float orientations[8];
  for (int octave_index = 0; octave_index < num_octaves; ++octave_index) {
    const int octave = options_.first_octave + octave_index;
    const float to_input = std::ldexp(1.0f, octave);
    const int w = base.width;
    const int h = base.height;
    levels[0] = base;
    for (int s = 1; s < S + 3; ++s) {
      start = Clock::now();
      levels[s] = AcquirePlane(scratch, w, h);
      Blur(kernels, levels[s - 1], levels[s], increments[s], scratch);
      rep.seconds_pyramid += SecondsSince(start);
      if (s < 3) continue;
      const int d = s - 2;  // DoG level whose three neighbours now exist
      start = Clock::now();
      LevelWindow lw{{levels[d - 1], levels[d], levels[d + 1], levels[d + 2]}};
      // Rolling DoG rows: ring slot (y mod 3) of each of the three levels.
      auto dog_row = [&](int level, int y) { return scratch.dog_rows + (3 * level + (y % 3)) * static_cast<size_t>(w); };
      auto fill_dog_row = [&](int y) {
        const float* g[4] = {levels[d - 1].row(y), levels[d].row(y), levels[d + 1].row(y), levels[d + 2].row(y)};
        float* out[3] = {dog_row(0, y), dog_row(1, y), dog_row(2, y)};
        kernels.difference_of_gaussians(g, w, out);
      };
      fill_dog_row(kBorder - 1);
      fill_dog_row(kBorder);
      std::vector<RefinedExtremum> found;
      for (int y = kBorder; y < h - kBorder; ++y) {
        fill_dog_row(y + 1);
        const float* rows[9];
        for (int level = 0; level < 3; ++level) {
          for (int r = 0; r < 3; ++r) rows[3 * level + r] = dog_row(level, y - 1 + r);
        }
        const int count = kernels.find_extrema(rows, kBorder, w - kBorder, prefilter, scratch.candidates);
        rep.num_candidates += count;
        for (int i = 0; i < count; ++i) {
          RefinedExtremum extremum;
          if (RefineExtremum(lw, d, scratch.candidates[i], y, options_, &extremum)) found.push_back(extremum);
        }
      }
      rep.seconds_detection += SecondsSince(start);
      for (const RefinedExtremum& e : found) {
        const float sigma = static_cast<float>(options_.sigma * std::pow(2.0, e.level / S));
        start = Clock::now();
        const int num_orientations =
            ComputeOrientations(kernels, levels[d], e.x, e.y, sigma, options_, scratch, orientations);
        rep.seconds_orientation += SecondsSince(start);
        start = Clock::now();
        for (int k = 0; k < num_orientations; ++k) {
          SiftKeypoint kp;
          kp.x = e.x * to_input;
          kp.y = e.y * to_input;
          kp.scale = sigma * to_input;
          kp.orientation = orientations[k];
          kp.response = e.response;
          kp.octave = octave;
          features.keypoints.push_back(kp);
          features.descriptors.resize(features.descriptors.size() + 128);
          ComputeDescriptor(kernels, levels[d], e.x, e.y, sigma, orientations[k], scratch,
                            features.descriptors.data() + features.descriptors.size() - 128);
        }
        rep.seconds_descriptor += SecondsSince(start);
      }
      ReleasePlane(scratch, levels[d - 1]);
    }
    start = Clock::now();
    if (octave_index + 1 < num_octaves) {
      ImageView<float> next = AcquirePlane(scratch, w / 2, h / 2);
      Downsample(levels[S], next);
      base = next;
    }
    for (int s = S; s < S + 3; ++s) ReleasePlane(scratch, levels[s]);
    rep.seconds_pyramid += SecondsSince(start);
  }
  rep.arena_peak_bytes = arena_.peak_used();
  rep.num_keypoints_before_cap = static_cast<int>(features.keypoints.size());

  if (options_.max_features > 0 && features.keypoints.size() > static_cast<size_t>(options_.max_features)) {
    rep.truncated = true;
    std::vector<int> order(features.keypoints.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return features.keypoints[a].response > features.keypoints[b].response;
    });
    order.resize(options_.max_features);
    std::sort(order.begin(), order.end());
    SiftFeatures kept;
    kept.keypoints.reserve(order.size());
    kept.descriptors.reserve(order.size() * 128);
    for (int i : order) {
      kept.keypoints.push_back(features.keypoints[i]);
      kept.descriptors.insert(kept.descriptors.end(), features.descriptor(i), features.descriptor(i) + 128);
    }
    features = std::move(kept);
  }
  return features;
}

}  // namespace reconar
