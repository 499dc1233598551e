#pragma once
// DepthMap: PatchMatch's per-pixel planes of one reference view. A pixel (x, y) carries a depth
// z along the camera's z axis and a unit normal n in the camera frame, facing the camera
// (n . K^-1 (x, y, 1) < 0): the plane through z K^-1 (x, y, 1) with normal n. cost is the
// photometric cost of that plane (1 - NCC, in [0, 2]); kNoDepthCost marks a pixel without a
// meaningful plane (textureless window, or never scored).
#include <cstddef>
#include <vector>

namespace reconar {

inline constexpr float kNoDepthCost = 2.0f;

struct DepthMap {
  int width = 0;
  int height = 0;
  std::vector<float> depth;
  std::vector<float> normal;  // 3 per pixel
  std::vector<float> cost;

  bool empty() const { return width <= 0 || height <= 0; }
  size_t Index(int x, int y) const { return static_cast<size_t>(y) * static_cast<size_t>(width) + x; }
  void Reset(int w, int h) {
    width = w;
    height = h;
    const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
    depth.assign(n, 0.0f);
    normal.assign(3 * n, 0.0f);
    cost.assign(n, kNoDepthCost);
  }
  size_t SizeBytes() const { return (depth.size() + normal.size() + cost.size()) * sizeof(float); }
};

}  // namespace reconar
