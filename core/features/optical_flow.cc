#include "core/features/optical_flow.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace reconar {
namespace {

constexpr int kMinLevelSide = 8;
constexpr int kMaxPatchSide = 2 * (kMaxFlowWindowRadius + 1) + 1;

// Samples the (2 radius + 1)^2 window of `image` centred on (x, y), bilinear, row-major into `out`.
// Coordinates outside the image read the nearest border pixel.
void SampleWindow(const ImageView<const float>& image, float x, float y, int radius, float* out) {
  const float fx = std::floor(x), fy = std::floor(y);
  const int x0 = static_cast<int>(fx) - radius, y0 = static_cast<int>(fy) - radius;
  const float ax = x - fx, ay = y - fy;
  const float w00 = (1.0f - ax) * (1.0f - ay), w10 = ax * (1.0f - ay), w01 = (1.0f - ax) * ay, w11 = ax * ay;
  const int side = 2 * radius + 1;
  if (x0 >= 0 && y0 >= 0 && x0 + side < image.width && y0 + side < image.height) {
    for (int j = 0; j < side; ++j) {
      const float* r0 = image.row(y0 + j) + x0;
      const float* r1 = r0 + image.stride;
      float* o = out + j * side;
      for (int i = 0; i < side; ++i) o[i] = w00 * r0[i] + w10 * r0[i + 1] + w01 * r1[i] + w11 * r1[i + 1];
    }
    return;
  }
  const int max_x = image.width - 1, max_y = image.height - 1;
  for (int j = 0; j < side; ++j) {
    const int ya = std::clamp(y0 + j, 0, max_y), yb = std::clamp(y0 + j + 1, 0, max_y);
    const float* r0 = image.row(ya);
    const float* r1 = image.row(yb);
    float* o = out + j * side;
    for (int i = 0; i < side; ++i) {
      const int xa = std::clamp(x0 + i, 0, max_x), xb = std::clamp(x0 + i + 1, 0, max_x);
      o[i] = w00 * r0[xa] + w10 * r0[xb] + w01 * r1[xa] + w11 * r1[xb];
    }
  }
}

// Sampling is safe for any finite coordinate; far-away ones are pulled in so the int conversion
// stays defined (everything beyond the border reads the border anyway).
float ClampCoordinate(float v, int size) {
  return std::clamp(v, -2.0f * kMaxFlowWindowRadius - 2.0f, static_cast<float>(size) + 2.0f * kMaxFlowWindowRadius);
}

}  // namespace

Status ImagePyramid::Build(ImageView<const uint8_t> gray, int num_levels) {
  if (gray.empty()) return InvalidArgument("ImagePyramid: empty image");
  if (num_levels < 1 || num_levels > kMaxPyramidLevels) {
    return InvalidArgument("ImagePyramid: num_levels must be in [1, " + std::to_string(kMaxPyramidLevels) + "]");
  }
  int levels = 0;
  size_t total = 0;
  int w = gray.width, h = gray.height;
  while (levels < num_levels && (levels == 0 || (w >= kMinLevelSide && h >= kMinLevelSide))) {
    widths_[levels] = w;
    heights_[levels] = h;
    offsets_[levels] = total;
    total += static_cast<size_t>(w) * static_cast<size_t>(h);
    ++levels;
    w = (w + 1) / 2;
    h = (h + 1) / 2;
  }
  num_levels_ = levels;
  if (storage_.size() < total) storage_.resize(total);
  if (scratch_.size() < static_cast<size_t>(gray.width)) scratch_.resize(static_cast<size_t>(gray.width));
  for (int y = 0; y < gray.height; ++y) {
    const uint8_t* in = gray.row(y);
    float* out = storage_.data() + offsets_[0] + static_cast<size_t>(y) * gray.width;
    for (int x = 0; x < gray.width; ++x) out[x] = in[x];
  }
  for (int l = 1; l < levels; ++l) {
    const int iw = widths_[l - 1], ih = heights_[l - 1], ow = widths_[l], oh = heights_[l];
    const float* in = storage_.data() + offsets_[l - 1];
    float* out = storage_.data() + offsets_[l];
    float* row = scratch_.data();
    for (int y = 0; y < oh; ++y) {
      const int cy = 2 * y;
      const float* r[5];
      for (int k = 0; k < 5; ++k) r[k] = in + static_cast<size_t>(std::clamp(cy + k - 2, 0, ih - 1)) * iw;
      for (int x = 0; x < iw; ++x) {
        row[x] = (r[0][x] + r[4][x]) * (1.0f / 16.0f) + (r[1][x] + r[3][x]) * (4.0f / 16.0f) + r[2][x] * (6.0f / 16.0f);
      }
      float* o = out + static_cast<size_t>(y) * ow;
      for (int x = 0; x < ow; ++x) {
        const int cx = 2 * x;
        const int xm2 = std::max(cx - 2, 0), xm1 = std::max(cx - 1, 0);
        const int xp1 = std::min(cx + 1, iw - 1), xp2 = std::min(cx + 2, iw - 1);
        o[x] =
            (row[xm2] + row[xp2]) * (1.0f / 16.0f) + (row[xm1] + row[xp1]) * (4.0f / 16.0f) + row[cx] * (6.0f / 16.0f);
      }
    }
  }
  return Status::Ok();
}

Status OpticalFlowOptions::Check() const {
  if (window_radius < 1 || window_radius > kMaxFlowWindowRadius) {
    return InvalidArgument("OpticalFlowOptions.window_radius must be in [1, " + std::to_string(kMaxFlowWindowRadius) +
                           "]");
  }
  if (num_levels < 1 || num_levels > kMaxPyramidLevels) {
    return InvalidArgument("OpticalFlowOptions.num_levels must be in [1, " + std::to_string(kMaxPyramidLevels) + "]");
  }
  if (max_iterations < 1) return InvalidArgument("OpticalFlowOptions.max_iterations must be >= 1");
  if (!(epsilon_px > 0.0)) return InvalidArgument("OpticalFlowOptions.epsilon_px must be > 0");
  if (!(min_eigenvalue >= 0.0) || !std::isfinite(min_eigenvalue)) {
    return InvalidArgument("OpticalFlowOptions.min_eigenvalue must be finite and >= 0");
  }
  if (!(max_mean_error > 0.0)) return InvalidArgument("OpticalFlowOptions.max_mean_error must be > 0");
  return Status::Ok();
}

const char* FlowStatusName(FlowStatus status) {
  switch (status) {
    case FlowStatus::kTracked:
      return "tracked";
    case FlowStatus::kOutOfBounds:
      return "out_of_bounds";
    case FlowStatus::kFlatWindow:
      return "flat_window";
    case FlowStatus::kLargeError:
      return "large_error";
  }
  return "unknown";
}

namespace {

// The inverse-compositional template of the window of `image` at (x, y): its samples, gradients
// (central differences of a window one pixel wider) and the summed structure tensor h = (h00, h01,
// h11). Returns whether the window has texture in two directions (min_eigenvalue per pixel) and
// an invertible tensor.
bool PrepareTemplate(const ImageView<const float>& image, float x, float y, int radius, double min_eigenvalue,
                     float* values, float* gx, float* gy, float h[3]) {
  const int side = 2 * radius + 1, wide = side + 2, n = side * side;
  float templ_wide[kMaxPatchSide * kMaxPatchSide];
  SampleWindow(image, x, y, radius + 1, templ_wide);
  float h00 = 0.0f, h01 = 0.0f, h11 = 0.0f;
  for (int j = 0; j < side; ++j) {
    const float* c = templ_wide + (j + 1) * wide + 1;
    for (int i = 0; i < side; ++i) {
      const int k = j * side + i;
      values[k] = c[i];
      gx[k] = 0.5f * (c[i + 1] - c[i - 1]);
      gy[k] = 0.5f * (c[i + wide] - c[i - wide]);
      h00 += gx[k] * gx[k];
      h01 += gx[k] * gy[k];
      h11 += gy[k] * gy[k];
    }
  }
  h[0] = h00;
  h[1] = h01;
  h[2] = h11;
  const float trace_half = 0.5f * (h00 + h11);
  const float det = h00 * h11 - h01 * h01;
  const float min_eigen = trace_half - std::sqrt(std::max(0.0f, trace_half * trace_half - det));
  return min_eigen / static_cast<float>(n) >= static_cast<float>(min_eigenvalue) && det > 0.0f;
}

// Inverse-compositional Gauss-Newton on the translation (qx, qy) in `image` (Baker & Matthews
// 2004, sec. 3.2). Returns false when a step is not finite.
bool AlignWindow(const ImageView<const float>& image, const float* values, const float* gx, const float* gy,
                 const float h[3], int radius, int max_iterations, float epsilon2, float* qx, float* qy) {
  const int side = 2 * radius + 1, n = side * side;
  float sample[kMaxPatchSide * kMaxPatchSide];
  const float inv_det = 1.0f / (h[0] * h[2] - h[1] * h[1]);
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    SampleWindow(image, *qx, *qy, radius, sample);
    float b0 = 0.0f, b1 = 0.0f;
    for (int k = 0; k < n; ++k) {
      const float e = sample[k] - values[k];
      b0 += gx[k] * e;
      b1 += gy[k] * e;
    }
    const float dx = inv_det * (h[2] * b0 - h[1] * b1);
    const float dy = inv_det * (h[0] * b1 - h[1] * b0);
    if (!std::isfinite(dx) || !std::isfinite(dy)) return false;
    *qx = ClampCoordinate(*qx - dx, image.width);
    *qy = ClampCoordinate(*qy - dy, image.height);
    if (!(dx * dx + dy * dy >= epsilon2)) break;
  }
  return true;
}

// The result at (qx, qy) of level 0: bounds, then the mean absolute difference to the template.
FlowResult Finish(const ImageView<const float>& image, const float* values, int radius, float qx, float qy,
                  double max_mean_error) {
  FlowResult result;
  result.point = Eigen::Vector2f(qx, qy);
  if (!result.point.allFinite() || qx < 0.0f || qy < 0.0f || qx > static_cast<float>(image.width - 1) ||
      qy > static_cast<float>(image.height - 1)) {
    result.status = FlowStatus::kOutOfBounds;
    return result;
  }
  const int side = 2 * radius + 1, n = side * side;
  float sample[kMaxPatchSide * kMaxPatchSide];
  SampleWindow(image, qx, qy, radius, sample);
  float error = 0.0f;
  for (int k = 0; k < n; ++k) error += std::abs(sample[k] - values[k]);
  result.mean_error = error / static_cast<float>(n);
  result.status =
      result.mean_error <= static_cast<float>(max_mean_error) ? FlowStatus::kTracked : FlowStatus::kLargeError;
  return result;
}

}  // namespace

Status TrackPoints(const ImagePyramid& previous, const ImagePyramid& next, const OpticalFlowOptions& options,
                   const Eigen::Vector2f* points, const Eigen::Vector2f* guesses, int count, FlowResult* results) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (previous.num_levels() == 0 || previous.num_levels() != next.num_levels() || previous.width() != next.width() ||
      previous.height() != next.height()) {
    return InvalidArgument("TrackPoints: the two pyramids differ in size or levels (or are empty)");
  }
  const int levels = std::min(options.num_levels, previous.num_levels());
  const int radius = options.window_radius;
  const float width = static_cast<float>(previous.width()), height = static_cast<float>(previous.height());
  const float epsilon2 = static_cast<float>(options.epsilon_px * options.epsilon_px);
  float values[kMaxPatchSide * kMaxPatchSide], gx[kMaxPatchSide * kMaxPatchSide], gy[kMaxPatchSide * kMaxPatchSide];
  float h[3];
  for (int p = 0; p < count; ++p) {
    FlowResult& result = results[p];
    result = FlowResult();
    const Eigen::Vector2f start = points[p];
    const Eigen::Vector2f guess = guesses != nullptr ? guesses[p] : start;
    if (!start.allFinite() || !guess.allFinite() || start.x() < 0.0f || start.y() < 0.0f || start.x() > width - 1.0f ||
        start.y() > height - 1.0f) {
      continue;  // kOutOfBounds
    }
    float qx = ClampCoordinate(guess.x(), previous.width()) / static_cast<float>(1 << (levels - 1));
    float qy = ClampCoordinate(guess.y(), previous.height()) / static_cast<float>(1 << (levels - 1));
    bool flat = false, diverged = false;
    for (int l = levels - 1; l >= 0 && !flat && !diverged; --l) {
      const float scale = 1.0f / static_cast<float>(1 << l);
      // A window flat at a coarse level only keeps the estimate of the level above; at level 0 the
      // point is refused.
      const bool textured = PrepareTemplate(previous.level(l), start.x() * scale, start.y() * scale, radius,
                                            options.min_eigenvalue, values, gx, gy, h);
      if (!textured) {
        flat = l == 0;
      } else {
        diverged = !AlignWindow(next.level(l), values, gx, gy, h, radius, options.max_iterations, epsilon2, &qx, &qy);
      }
      if (l > 0) {
        qx *= 2.0f;
        qy *= 2.0f;
      }
    }
    if (flat) {
      result.status = FlowStatus::kFlatWindow;
      continue;
    }
    if (diverged) continue;  // kOutOfBounds
    result = Finish(next.level(0), values, radius, qx, qy, options.max_mean_error);
  }
  return Status::Ok();
}

int FlowTemplateFloats(int window_radius) {
  const int side = 2 * window_radius + 1;
  return 3 + 3 * side * side;
}

bool MakeFlowTemplate(const ImagePyramid& pyramid, const Eigen::Vector2f& point, const OpticalFlowOptions& options,
                      float* storage) {
  if (pyramid.num_levels() == 0 || !options.Check().ok() || !point.allFinite() || point.x() < 0.0f ||
      point.y() < 0.0f || point.x() > static_cast<float>(pyramid.width() - 1) ||
      point.y() > static_cast<float>(pyramid.height() - 1)) {
    return false;
  }
  const int radius = options.window_radius, n = (2 * radius + 1) * (2 * radius + 1);
  return PrepareTemplate(pyramid.level(0), point.x(), point.y(), radius, options.min_eigenvalue, storage + 3,
                         storage + 3 + n, storage + 3 + 2 * n, storage);
}

FlowResult AlignFlowTemplate(const ImagePyramid& next, const float* storage, const Eigen::Vector2f& guess,
                             const OpticalFlowOptions& options) {
  FlowResult result;
  if (next.num_levels() == 0 || !guess.allFinite()) return result;
  const int radius = options.window_radius, n = (2 * radius + 1) * (2 * radius + 1);
  const ImageView<const float> image = next.level(0);
  float qx = ClampCoordinate(guess.x(), image.width), qy = ClampCoordinate(guess.y(), image.height);
  const float epsilon2 = static_cast<float>(options.epsilon_px * options.epsilon_px);
  if (!AlignWindow(image, storage + 3, storage + 3 + n, storage + 3 + 2 * n, storage, radius, options.max_iterations,
                   epsilon2, &qx, &qy)) {
    return result;
  }
  return Finish(image, storage + 3, radius, qx, qy, options.max_mean_error);
}

}  // namespace reconar
