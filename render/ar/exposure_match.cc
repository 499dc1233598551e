#include "render/ar/exposure_match.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>
#include <vector>

#include "core/base/image_sampling.h"
#include "core/mesh/simplify.h"

namespace reconar {
namespace {

constexpr int kClipLow = 8, kClipHigh = 247;

struct PositionHash {
  size_t operator()(const Eigen::Vector3f& p) const {
    uint32_t bits[3];
    std::memcpy(bits, p.data(), sizeof(bits));
    return (size_t{bits[0]} * 73856093u) ^ (size_t{bits[1]} * 19349663u) ^ (size_t{bits[2]} * 83492791u);
  }
};

}  // namespace

Result<Mesh> ExposureProxy(const Mesh& textured, const std::vector<TexturePage>& texture, size_t max_faces) {
  RECONAR_RETURN_IF_ERROR(ValidateMesh(textured));
  if (textured.texcoords.empty()) return InvalidArgument("ExposureProxy: the mesh has no texcoords");
  RECONAR_RETURN_IF_ERROR(ValidateTexturePages(texture, textured.triangles.size()));
  const size_t n = textured.positions.size();
  std::vector<Eigen::Vector3f> colour(n, Eigen::Vector3f::Zero());
  std::vector<uint8_t> sampled(n, 0);
  for (size_t page = 0; page < texture.size(); ++page) {
    const Image<uint8_t>& image = texture[page].image;
    for (size_t t = texture[page].first_triangle; t < PageTrianglesEnd(texture, page, textured.triangles.size()); ++t) {
      for (const uint32_t v : textured.triangles[t]) {
        if (sampled[v]) continue;
        float rgb[3] = {0.0f, 0.0f, 0.0f};
        const Eigen::Vector2f& uv = textured.texcoords[v];
        SampleBilinear(image, uv.x() * image.width() - 0.5, uv.y() * image.height() - 0.5, rgb);
        colour[v] = Eigen::Vector3f(rgb[0], rgb[1], rgb[2]);
        if (!textured.colors.empty()) {
          for (int c = 0; c < 3; ++c) colour[v][c] *= textured.colors[v][static_cast<size_t>(c)] / 255.0f;
        }
        sampled[v] = 1;
      }
    }
  }
  Mesh proxy;
  std::vector<uint32_t> welded(n);
  std::vector<Eigen::Vector3f> sum;
  std::vector<int> count;
  std::unordered_map<Eigen::Vector3f, uint32_t, PositionHash> index_of;
  index_of.reserve(n);
  for (size_t v = 0; v < n; ++v) {
    const auto inserted = index_of.emplace(textured.positions[v], static_cast<uint32_t>(proxy.positions.size()));
    if (inserted.second) {
      proxy.positions.push_back(textured.positions[v]);
      sum.push_back(Eigen::Vector3f::Zero());
      count.push_back(0);
    }
    welded[v] = inserted.first->second;
    if (sampled[v]) {
      sum[welded[v]] += colour[v];
      ++count[welded[v]];
    }
  }
  for (size_t k = 0; k < proxy.positions.size(); ++k) {
    const Eigen::Vector3f mean = count[k] > 0 ? Eigen::Vector3f(sum[k] / static_cast<float>(count[k]))
                                              : Eigen::Vector3f::Zero();
    proxy.colors.push_back({static_cast<uint8_t>(std::lround(mean.x())), static_cast<uint8_t>(std::lround(mean.y())),
                            static_cast<uint8_t>(std::lround(mean.z())), 255});
  }
  for (const auto& t : textured.triangles) {
    const std::array<uint32_t, 3> corners = {welded[t[0]], welded[t[1]], welded[t[2]]};
    if (corners[0] == corners[1] || corners[1] == corners[2] || corners[0] == corners[2]) continue;
    proxy.triangles.push_back(corners);
  }
  RECONAR_RETURN_IF_ERROR(SimplifyToFaceBudget(max_faces, &proxy).status());
  return proxy;
}

void BoxReduce(ImageView<const uint8_t> frame_rgb, int frame_width, int frame_height, Image<uint8_t>* reduced) {
  const int width = reduced->width(), height = reduced->height();
  for (int y = 0; y < height; ++y) {
    const int y0 = y * frame_height / height, y1 = std::max(y0 + 1, (y + 1) * frame_height / height);
    for (int x = 0; x < width; ++x) {
      const int x0 = x * frame_width / width, x1 = std::max(x0 + 1, (x + 1) * frame_width / width);
      uint32_t sum[3] = {0, 0, 0};
      for (int v = y0; v < y1; ++v) {
        const uint8_t* row = frame_rgb.row(v);
        for (int u = x0; u < x1; ++u) {
          for (int c = 0; c < 3; ++c) sum[c] += row[3 * u + c];
        }
      }
      const uint32_t count = static_cast<uint32_t>((x1 - x0) * (y1 - y0));
      for (int c = 0; c < 3; ++c) reduced->row(y)[3 * x + c] = static_cast<uint8_t>((sum[c] + count / 2) / count);
    }
  }
}

std::optional<std::array<float, 3>> ExposureMatcher::Estimate(const Image<uint8_t>& model, const Image<uint8_t>& frame,
                                                             const std::array<uint8_t, 3>& background) {
  if (model.width() != frame.width() || model.height() != frame.height()) return std::nullopt;
  std::array<std::vector<float>, 3>& ratios = ratios_;
  for (std::vector<float>& values : ratios) values.clear();
  for (int y = 0; y < model.height(); ++y) {
    const uint8_t* drawn = model.row(y);
    const uint8_t* seen = frame.row(y);
    for (int x = 0; x < model.width(); ++x) {
      const uint8_t* m = drawn + 3 * x;
      if (m[0] == background[0] && m[1] == background[1] && m[2] == background[2]) continue;
      for (int c = 0; c < 3; ++c) {
        const int a = m[c], b = seen[3 * x + c];
        if (a < kClipLow || a > kClipHigh || b < kClipLow || b > kClipHigh) continue;
        ratios[static_cast<size_t>(c)].push_back(static_cast<float>(b) / static_cast<float>(a));
      }
    }
  }
  std::array<float, 3> gain;
  for (size_t c = 0; c < 3; ++c) {
    std::vector<float>& values = ratios[c];
    if (values.size() < static_cast<size_t>(options_.min_pixels)) return std::nullopt;
    std::nth_element(values.begin(), values.begin() + static_cast<ptrdiff_t>(values.size() / 2), values.end());
    gain[c] = values[values.size() / 2];
  }
  return gain;
}

void ExposureMatcher::Update(const std::optional<std::array<float, 3>>& estimate) {
  if (!estimate) return;
  std::array<double, 3> target;
  bool jump = !has_estimate_;
  for (size_t c = 0; c < 3; ++c) {
    target[c] = std::clamp(static_cast<double>((*estimate)[c]), options_.min_gain, options_.max_gain);
    jump = jump || std::abs(std::log(target[c] / gain_[c])) > std::log(options_.jump_ratio);
  }
  for (size_t c = 0; c < 3; ++c) {
    const double weight = jump ? 1.0 : options_.smoothing;
    gain_[c] = static_cast<float>(std::exp((1.0 - weight) * std::log(gain_[c]) + weight * std::log(target[c])));
  }
  has_estimate_ = true;
}

}  // namespace reconar
