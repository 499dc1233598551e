#pragma once
// DepthMap: PatchMatch's per-pixel planes of one reference view. A pixel (x, y) carries a depth
// z along the camera's z axis and a unit normal n in the camera frame, facing the camera
// (n . K^-1 (x, y, 1) < 0): the plane through z K^-1 (x, y, 1) with normal n. cost is the
// photometric cost of that plane (1 - NCC, in [0, 2]); kNoDepthCost marks a pixel without a
// meaningful plane (textureless window, or never scored). Normals are stored as 16-bit fixed point
// (steps of 1 / 32767, under 0.01 degrees): 14 bytes per pixel instead of 20.
#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace reconar {

inline constexpr float kNoDepthCost = 2.0f;

struct DepthMap {
  int width = 0;
  int height = 0;
  std::vector<float> depth;
  std::vector<int16_t> normal;  // 3 per pixel, times kNormalScale
  std::vector<float> cost;
  // Per pixel, a bit per source view: the sources that served its plane best (the candidates of
  // the next sweep are scored on them). Carried from a coarse level to the next finer one of the
  // same view, then released: not part of SizeBytes.
  std::vector<uint32_t> source_masks;

  bool empty() const { return width <= 0 || height <= 0; }
  static constexpr float kNormalScale = 32767.0f;

  Eigen::Vector3f Normal(size_t i) const {
    return Eigen::Vector3f(normal[3 * i], normal[3 * i + 1], normal[3 * i + 2]) * (1.0f / kNormalScale);
  }
  void SetNormal(size_t i, const Eigen::Vector3f& n) {
    for (int c = 0; c < 3; ++c) {
      normal[3 * i + static_cast<size_t>(c)] =
          static_cast<int16_t>(std::lround(std::fmax(-1.0f, std::fmin(1.0f, n[c])) * kNormalScale));
    }
  }
  size_t Index(int x, int y) const { return static_cast<size_t>(y) * static_cast<size_t>(width) + x; }
  void Reset(int w, int h) {
    width = w;
    height = h;
    const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
    depth.assign(n, 0.0f);
    normal.assign(3 * n, 0);
    cost.assign(n, kNoDepthCost);
  }
  size_t SizeBytes() const { return (depth.size() + cost.size()) * sizeof(float) + normal.size() * sizeof(int16_t); }
};

}  // namespace reconar
