#include "core/mvs/merge_points.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/base/median.h"

namespace reconar {
namespace {

// Cell indices are clamped to +-2^30 (MergeOrientedPoints' cell_of): only absurdly far points
// share the boundary cells, and their distance tests stay exact.
struct CellKey {
  int32_t x, y, z;
  bool operator==(const CellKey& other) const { return x == other.x && y == other.y && z == other.z; }
};

// Cell -> the kept points in it, as a chain through `next` (open addressing, linear probing,
// grown at half load): no allocation per cell, unlike a map of vectors.
class CellChains {
 public:
  CellChains() { Rehash(1 << 12); }

  int32_t Head(const CellKey& key) const {
    for (size_t slot = Hash(key) & mask_;; slot = (slot + 1) & mask_) {
      if (heads_[slot] < 0) return -1;
      if (keys_[slot] == key) return heads_[slot];
    }
  }
  int32_t Next(int32_t point) const { return next_[static_cast<size_t>(point)]; }
  void ReservePoints(size_t points) { next_.reserve(points); }
  // Adds point `point` (the next index, 0, 1, 2, ...; see Skip) to the cell's chain.
  void Add(const CellKey& key, int32_t point) {
    if (2 * (used_ + 1) > heads_.size()) Rehash(2 * heads_.size());
    size_t slot = Hash(key) & mask_;
    while (heads_[slot] >= 0 && !(keys_[slot] == key)) slot = (slot + 1) & mask_;
    if (heads_[slot] < 0) {
      keys_[slot] = key;
      ++used_;
    }
    next_.push_back(heads_[slot]);
    heads_[slot] = point;
  }
  // The next point (by index) is in no cell.
  void Skip() { next_.push_back(-1); }

 private:
  static size_t Hash(const CellKey& key) {
    uint64_t h = static_cast<uint64_t>(key.x) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<uint64_t>(key.y) * 0xC2B2AE3D27D4EB4Full + (h >> 29);
    h ^= static_cast<uint64_t>(key.z) * 0x165667B19E3779F9ull + (h >> 32);
    return static_cast<size_t>(h ^ (h >> 31));
  }
  void Rehash(size_t capacity) {
    std::vector<CellKey> old_keys = std::move(keys_);
    std::vector<int32_t> old_heads = std::move(heads_);
    keys_.assign(capacity, CellKey{0, 0, 0});
    heads_.assign(capacity, -1);
    mask_ = capacity - 1;
    for (size_t i = 0; i < old_heads.size(); ++i) {
      if (old_heads[i] < 0) continue;
      size_t slot = Hash(old_keys[i]) & mask_;
      while (heads_[slot] >= 0) slot = (slot + 1) & mask_;
      keys_[slot] = old_keys[i];
      heads_[slot] = old_heads[i];
    }
  }

  std::vector<CellKey> keys_;
  std::vector<int32_t> heads_;  // -1: empty slot
  std::vector<int32_t> next_;   // per point: the next point of its cell, -1 at the end
  size_t mask_ = 0;
  size_t used_ = 0;
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

OrientedPoints MergeOrientedPoints(const std::vector<MergeInput>& parts, MergeReport* report,
                                   std::vector<float>* kept_footprints) {
  if (kept_footprints != nullptr) kept_footprints->clear();
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
    cell = MedianInPlace(footprints.data(), footprints.size());
  }
  std::vector<float>().swap(footprints);
  const auto cell_of = [cell](float v) {
    constexpr double kLimit = 1 << 30;
    return static_cast<int32_t>(std::clamp(std::floor(static_cast<double>(v) / cell), -kLimit, kLimit));
  };
  const auto position_of = [&parts](const Ref& ref) -> const Eigen::Vector3f& {
    return parts[ref.part].points.positions[ref.index];
  };
  const auto normal_of = [&parts](const Ref& ref) {
    const OrientedPoints& source = parts[ref.part].points;
    return ref.index < source.normals.size() ? source.normals[ref.index] : Eigen::Vector3f::Zero();
  };
  const auto footprint_of = [&parts](const Ref& ref) {
    return ref.index < parts[ref.part].footprints.size() ? parts[ref.part].footprints[ref.index] : 0.0f;
  };
  // Which points are kept, first; the output is built afterwards at its exact size, once the cell
  // table is gone (a merge of millions of points is the dense stage's memory peak). The table
  // chains the positions in `order` of the kept points.
  std::vector<uint8_t> kept(order.size(), 0);
  size_t kept_count = 0;
  {
    CellChains grid;
    grid.ReservePoints(order.size());
    for (size_t r = 0; r < order.size(); ++r) {
      const Eigen::Vector3f& position = position_of(order[r]);
      const Eigen::Vector3f normal = normal_of(order[r]);
      const float footprint = footprint_of(order[r]);
      bool duplicate = false;
      if (footprint > 0.0f && std::isfinite(footprint)) {
        // The cells the ball of radius `footprint` reaches (2 per axis when it is at most a cell); a
        // footprint many cells wide is capped to 9 cells per axis (rare outliers).
        int32_t low[3], high[3];
        for (int a = 0; a < 3; ++a) {
          const int32_t centre = cell_of(position[a]);
          low[a] = std::max(cell_of(position[a] - footprint), centre - 4);
          high[a] = std::min(cell_of(position[a] + footprint), centre + 4);
        }
        const float radius2 = footprint * footprint;
        for (int32_t z = low[2]; z <= high[2] && !duplicate; ++z) {
          for (int32_t y = low[1]; y <= high[1] && !duplicate; ++y) {
            for (int32_t x = low[0]; x <= high[0] && !duplicate; ++x) {
              for (int32_t k = grid.Head(CellKey{x, y, z}); k >= 0; k = grid.Next(k)) {
                const Ref& other = order[static_cast<size_t>(k)];
                if ((position_of(other) - position).squaredNorm() <= radius2 && normal_of(other).dot(normal) > 0.0f) {
                  duplicate = true;
                  break;
                }
              }
            }
          }
        }
      }
      // Every point enters the table's chain array (so that chain entries are order positions);
      // only the kept ones are linked into a cell.
      if (duplicate) {
        grid.Skip();
        continue;
      }
      grid.Add(CellKey{cell_of(position.x()), cell_of(position.y()), cell_of(position.z())}, static_cast<int32_t>(r));
      kept[r] = 1;
      ++kept_count;
    }
  }
  OrientedPoints merged;
  merged.positions.reserve(kept_count);
  merged.normals.reserve(kept_count);
  merged.colors.reserve(kept_count);
  merged.scores.reserve(kept_count);
  if (kept_footprints != nullptr) kept_footprints->reserve(kept_count);
  for (size_t r = 0; r < order.size(); ++r) {
    if (!kept[r]) continue;
    const Ref& ref = order[r];
    const OrientedPoints& source = parts[ref.part].points;
    merged.positions.push_back(position_of(ref));
    merged.normals.push_back(normal_of(ref));
    merged.colors.push_back(ref.index < source.colors.size() ? source.colors[ref.index] : std::array<uint8_t, 3>{0, 0, 0});
    merged.scores.push_back(ref.score);
    if (kept_footprints != nullptr) kept_footprints->push_back(footprint_of(ref));
  }
  if (report != nullptr) {
    report->input_points = order.size();
    report->duplicates_dropped = order.size() - kept_count;
  }
  return merged;
}

}  // namespace reconar
