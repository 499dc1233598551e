#include "core/mesh/poisson/point_kdtree.h"

#include <algorithm>
#include <numeric>

namespace reconar::poisson {

PointKdTree::PointKdTree(const std::vector<Eigen::Vector3f>& points) : points_(points), order_(points.size()) {
  std::iota(order_.begin(), order_.end(), 0u);
  if (!order_.empty()) {
    nodes_.reserve(2 * (order_.size() / (kLeafSize / 2) + 1));
    Build(0, static_cast<uint32_t>(order_.size()));
  }
}

uint32_t PointKdTree::Build(uint32_t begin, uint32_t end) {
  const uint32_t id = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  if (end - begin <= kLeafSize) {
    nodes_[id].begin = begin;
    nodes_[id].end = end;
    return id;
  }
  Eigen::Vector3f lo = points_[order_[begin]], hi = lo;
  for (uint32_t i = begin + 1; i < end; ++i) {
    lo = lo.cwiseMin(points_[order_[i]]);
    hi = hi.cwiseMax(points_[order_[i]]);
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const uint32_t middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](uint32_t a, uint32_t b) { return points_[a][axis] < points_[b][axis]; });
  const float split = points_[order_[middle]][axis];
  const uint32_t left = Build(begin, middle);
  const uint32_t right = Build(middle, end);
  Node& node = nodes_[id];
  node.axis = axis;
  node.split = split;
  node.left = left;
  node.right = right;
  return id;
}

void PointKdTree::Search(uint32_t id, const Eigen::Vector3f& query, size_t k,
                         std::vector<std::pair<float, uint32_t>>* heap) const {
  const Node& node = nodes_[id];
  if (node.axis < 0) {
    for (uint32_t i = node.begin; i < node.end; ++i) {
      const uint32_t index = order_[i];
      const std::pair<float, uint32_t> candidate((points_[index] - query).squaredNorm(), index);
      if (heap->size() < k) {
        heap->push_back(candidate);
        std::push_heap(heap->begin(), heap->end());
      } else if (candidate < heap->front()) {
        std::pop_heap(heap->begin(), heap->end());
        heap->back() = candidate;
        std::push_heap(heap->begin(), heap->end());
      }
    }
    return;
  }
  // Points equal to the split value can lie on either side, hence <= / >= in the bound below.
  const float offset = query[node.axis] - node.split;
  const uint32_t near = offset < 0.0f ? node.left : node.right;
  const uint32_t far = offset < 0.0f ? node.right : node.left;
  Search(near, query, k, heap);
  if (heap->size() < k || offset * offset <= heap->front().first) Search(far, query, k, heap);
}

void PointKdTree::Nearest(const Eigen::Vector3f& query, int k, std::vector<std::pair<float, uint32_t>>* result) const {
  result->clear();
  if (nodes_.empty() || k <= 0) return;
  Search(0, query, static_cast<size_t>(k), result);
  std::sort_heap(result->begin(), result->end());
}

}  // namespace reconar::poisson
