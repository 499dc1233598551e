#include "core/mvs/merge_points.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <unordered_map>

namespace reconar {
namespace {

struct CellKey {
  int64_t x, y, z;
  bool operator==(const CellKey& other) const { return x == other.x && y == other.y && z == other.z; }
};

struct CellHash {
  size_t operator()(const CellKey& key) const {
    return static_cast<size_t>(key.x * 73856093) ^ static_cast<size_t>(key.y * 19349663) ^
           static_cast<size_t>(key.z * 83492791);
  }
};

}  // namespace

float PixelFootprint(const std::vector<const DenseView*>& views, const Eigen::Vector3f& position) {
  const Eigen::Vector3d point = position.cast<double>();
  double best = 0.0;
  for (const DenseView* view : views) {
    const double depth = view->Depth(point);
    if (!(depth > 0.0)) continue;
    const Eigen::Vector2d pixel = view->Project(point);
    if (pixel.x() < -0.5 || pixel.y() < -0.5 || pixel.x() > view->width() - 0.5 || pixel.y() > view->height() - 0.5) {
      continue;
    }
    const double footprint = depth / view->fx;
    if (best == 0.0 || footprint < best) best = footprint;
  }
  return static_cast<float>(best);
}

OrientedPoints MergeOrientedPoints(const std::vector<MergeInput>& parts, MergeReport* report) {
  struct Ref {
    float score;
    uint32_t part, index;
  };
  std::vector<Ref> order;
  std::vector<float> footprints;
  for (size_t p = 0; p < parts.size(); ++p) {
    for (size_t i = 0; i < parts[p].points.size(); ++i) {
      const float score = i < parts[p].points.scores.size() ? parts[p].points.scores[i] : 0.0f;
      order.push_back({score, static_cast<uint32_t>(p), static_cast<uint32_t>(i)});
      const float footprint = i < parts[p].footprints.size() ? parts[p].footprints[i] : 0.0f;
      if (footprint > 0.0f && std::isfinite(footprint)) footprints.push_back(footprint);
    }
  }
  std::stable_sort(order.begin(), order.end(), [](const Ref& a, const Ref& b) { return a.score > b.score; });
  float cell = 1.0f;
  if (!footprints.empty()) {
    std::nth_element(footprints.begin(), footprints.begin() + footprints.size() / 2, footprints.end());
    cell = footprints[footprints.size() / 2];
  }
  const auto key_of = [cell](const Eigen::Vector3f& x) {
    return CellKey{static_cast<int64_t>(std::floor(x.x() / cell)), static_cast<int64_t>(std::floor(x.y() / cell)),
                   static_cast<int64_t>(std::floor(x.z() / cell))};
  };
  std::unordered_map<CellKey, std::vector<uint32_t>, CellHash> grid;  // cell -> indices into `merged`
  OrientedPoints merged;
  size_t dropped = 0;
  for (const Ref& ref : order) {
    const OrientedPoints& source = parts[ref.part].points;
    const Eigen::Vector3f& position = source.positions[ref.index];
    const Eigen::Vector3f normal =
        ref.index < source.normals.size() ? source.normals[ref.index] : Eigen::Vector3f::Zero();
    const float footprint = ref.index < parts[ref.part].footprints.size() ? parts[ref.part].footprints[ref.index] : 0.0f;
    const CellKey key = key_of(position);
    bool duplicate = false;
    if (footprint > 0.0f && std::isfinite(footprint)) {
      // Search the cells within one footprint; a footprint many cells wide is capped (rare outliers).
      const int64_t reach = std::min<int64_t>(4, static_cast<int64_t>(std::ceil(footprint / cell)));
      const float radius2 = footprint * footprint;
      for (int64_t dz = -reach; dz <= reach && !duplicate; ++dz) {
        for (int64_t dy = -reach; dy <= reach && !duplicate; ++dy) {
          for (int64_t dx = -reach; dx <= reach && !duplicate; ++dx) {
            const auto it = grid.find(CellKey{key.x + dx, key.y + dy, key.z + dz});
            if (it == grid.end()) continue;
            for (uint32_t k : it->second) {
              if ((merged.positions[k] - position).squaredNorm() <= radius2 && merged.normals[k].dot(normal) > 0.0f) {
                duplicate = true;
                break;
              }
            }
          }
        }
      }
    }
    if (duplicate) {
      ++dropped;
      continue;
    }
    grid[key].push_back(static_cast<uint32_t>(merged.positions.size()));
    merged.positions.push_back(position);
    merged.normals.push_back(normal);
    merged.colors.push_back(ref.index < source.colors.size() ? source.colors[ref.index] : std::array<uint8_t, 3>{0, 0, 0});
    merged.scores.push_back(ref.score);
  }
  if (report != nullptr) {
    report->input_points = order.size();
    report->duplicates_dropped = dropped;
  }
  return merged;
}

}  // namespace reconar
