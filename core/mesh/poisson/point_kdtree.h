#pragma once
// PointKdTree: exact k-nearest-neighbour search over 3D points (core/features/kdtree.h is an
// approximate forest over 128-byte descriptors and does not fit). Median splits on the widest
// axis of each node, leaves of up to kLeafSize points, depth-first search that visits the near
// child first and skips a far child whose splitting plane is farther than the current k-th
// neighbour. The tree borrows the caller's points, which must outlive it and stay unchanged.
#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

namespace reconar::poisson {

class PointKdTree {
 public:
  explicit PointKdTree(const std::vector<Eigen::Vector3f>& points);

  // The min(k, size) points nearest to `query` (the query point itself included when it is one
  // of the points), nearest first, as (squared distance, index) pairs in *result. Ties are broken
  // by index, so results are deterministic.
  void Nearest(const Eigen::Vector3f& query, int k, std::vector<std::pair<float, uint32_t>>* result) const;

 private:
  static constexpr int kLeafSize = 8;
  struct Node {
    // Inner node: split axis (0..2), split value, children; leaf: axis = -1 and the range
    // [begin, end) of order_.
    int axis = -1;
    float split = 0.0f;
    uint32_t left = 0, right = 0;
    uint32_t begin = 0, end = 0;
  };

  uint32_t Build(uint32_t begin, uint32_t end);
  void Search(uint32_t node, const Eigen::Vector3f& query, size_t k,
              std::vector<std::pair<float, uint32_t>>* heap) const;

  const std::vector<Eigen::Vector3f>& points_;
  std::vector<uint32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace reconar::poisson
