#include "core/mesh/triangle_bvh.h"

#include <algorithm>
#include <cmath>

namespace reconar {

TriangleBvh::TriangleBvh(const Mesh& mesh) {
  corners_.resize(mesh.triangles.size());
  std::vector<Eigen::Vector3f> centroids(mesh.triangles.size());
  order_.reserve(mesh.triangles.size());
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const std::array<uint32_t, 3>& t = mesh.triangles[i];
    if (t[0] >= mesh.positions.size() || t[1] >= mesh.positions.size() || t[2] >= mesh.positions.size()) continue;
    const std::array<Eigen::Vector3f, 3> c = {mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]};
    if (!c[0].allFinite() || !c[1].allFinite() || !c[2].allFinite()) continue;
    corners_[i] = c;
    centroids[i] = (c[0] + c[1] + c[2]) / 3.0f;
    order_.push_back(static_cast<int>(i));
  }
  nodes_.reserve(2 * (order_.size() / kLeafSize + 1));
  if (!order_.empty()) Build(0, static_cast<int>(order_.size()), &centroids);
  // The corners (and boxes) stored in leaf order: a leaf's triangles side by side in memory.
  std::vector<std::array<Eigen::Vector3f, 3>> by_triangle;
  by_triangle.swap(corners_);
  corners_.reserve(order_.size());
  boxes_.reserve(order_.size());
  position_of_.assign(mesh.triangles.size(), -1);
  for (size_t k = 0; k < order_.size(); ++k) {
    const std::array<Eigen::Vector3f, 3>& c = by_triangle[static_cast<size_t>(order_[k])];
    corners_.push_back(c);
    boxes_.push_back({c[0].cwiseMin(c[1]).cwiseMin(c[2]), c[0].cwiseMax(c[1]).cwiseMax(c[2])});
    position_of_[static_cast<size_t>(order_[k])] = static_cast<int>(k);
  }
}

int TriangleBvh::Build(int begin, int end, std::vector<Eigen::Vector3f>* centroids) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3f box_min = Eigen::Vector3f::Constant(INFINITY), box_max = -box_min;
  Eigen::Vector3f centre_min = box_min, centre_max = box_max;
  for (int k = begin; k < end; ++k) {
    const int t = order_[static_cast<size_t>(k)];
    for (const Eigen::Vector3f& c : corners_[static_cast<size_t>(t)]) {
      box_min = box_min.cwiseMin(c);
      box_max = box_max.cwiseMax(c);
    }
    centre_min = centre_min.cwiseMin((*centroids)[static_cast<size_t>(t)]);
    centre_max = centre_max.cwiseMax((*centroids)[static_cast<size_t>(t)]);
  }
  nodes_[static_cast<size_t>(index)].box_min = box_min;
  nodes_[static_cast<size_t>(index)].box_max = box_max;
  if (end - begin <= kLeafSize) {
    nodes_[static_cast<size_t>(index)].first = begin;
    nodes_[static_cast<size_t>(index)].count = end - begin;
    return index;
  }
  int axis = 0;
  (centre_max - centre_min).maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](int a, int b) {
                     return (*centroids)[static_cast<size_t>(a)][axis] < (*centroids)[static_cast<size_t>(b)][axis];
                   });
  Build(begin, middle, centroids);
  const int second = Build(middle, end, centroids);
  nodes_[static_cast<size_t>(index)].first = second;
  return index;
}

namespace {

// The entry distance of the ray into the box, or infinity when it misses it within (near, far).
double BoxEntry(const Eigen::Vector3f& box_min, const Eigen::Vector3f& box_max, const Eigen::Vector3d& origin,
                const Eigen::Vector3d& inverse_direction, double near, double far) {
  for (int a = 0; a < 3; ++a) {
    double t0 = (box_min[a] - origin[a]) * inverse_direction[a];
    double t1 = (box_max[a] - origin[a]) * inverse_direction[a];
    if (t0 > t1) std::swap(t0, t1);
    if (std::isnan(t0) || std::isnan(t1)) continue;  // a zero direction component with the origin on a face
    near = std::max(near, t0);
    far = std::min(far, t1);
    if (near > far) return INFINITY;
  }
  return near;
}

// Squared distance from the point to the box (0 inside), in single precision as the boxes are: a
// lower bound for pruning, compared with a margin for rounding.
float BoxDistanceSquared(const Eigen::Vector3f& box_min, const Eigen::Vector3f& box_max, const Eigen::Vector3f& p) {
  const Eigen::Vector3f outside = (box_min - p).cwiseMax(p - box_max).cwiseMax(0.0f);
  return outside.squaredNorm();
}

Eigen::Vector3d ClosestPointOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length_squared = ab.squaredNorm();
  if (length_squared <= 0.0) return a;
  return a + std::clamp((p - a).dot(ab) / length_squared, 0.0, 1.0) * ab;
}

// The point of triangle abc nearest to p (Ericson, "Real-Time Collision Detection" 5.1.5: the
// Voronoi regions of the corners, then the edges, then the face, where *interior is set).
// Triangles of (numerically) zero area take the nearest of their edges: a point (p, p, p) is p.
Eigen::Vector3d ClosestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c, bool* interior) {
  *interior = false;
  const Eigen::Vector3d ab = b - a, ac = c - a;
  if (ab.cross(ac).squaredNorm() <= 1e-24 * ab.squaredNorm() * ac.squaredNorm()) {
    Eigen::Vector3d best = ClosestPointOnSegment(p, a, b);
    for (const Eigen::Vector3d& candidate : {ClosestPointOnSegment(p, a, c), ClosestPointOnSegment(p, b, c)}) {
      if ((candidate - p).squaredNorm() < (best - p).squaredNorm()) best = candidate;
    }
    return best;
  }
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  *interior = true;
  const double inverse = 1.0 / (va + vb + vc);
  return a + ab * (vb * inverse) + ac * (vc * inverse);
}

}  // namespace

void TriangleBvh::TryTriangle(int k, const Eigen::Vector3d& query, const Eigen::Vector3f& query_f,
                              NearestSearch* search) const {
  // The triangle's box bounds its distance from below: most triangles of a leaf end there.
  const std::array<Eigen::Vector3f, 2>& box = boxes_[static_cast<size_t>(k)];
  if (!(BoxDistanceSquared(box[0], box[1], query_f) <= search->prune2)) return;
  const std::array<Eigen::Vector3f, 3>& c = corners_[static_cast<size_t>(k)];
  bool interior = false;
  const Eigen::Vector3d point =
      ClosestOnTriangle(query, c[0].cast<double>(), c[1].cast<double>(), c[2].cast<double>(), &interior);
  const double d2 = (point - query).squaredNorm();
  if (d2 <= search->best2) {
    search->SetBest(d2);
    search->nearest = {order_[static_cast<size_t>(k)], std::sqrt(d2), point, interior};
  }
}

TriangleBvh::NearestSearch TriangleBvh::StartSearch(const Eigen::Vector3d& query, double max_distance,
                                                    int hint) const {
  NearestSearch search;
  search.SetBest(max_distance < 1e150 ? max_distance * max_distance : INFINITY);
  // A usable triangle near the query (the previous query's, for points in order) bounds the search.
  if (hint >= 0 && static_cast<size_t>(hint) < position_of_.size() && position_of_[static_cast<size_t>(hint)] >= 0) {
    TryTriangle(position_of_[static_cast<size_t>(hint)], query, query.cast<float>(), &search);
  }
  return search;
}

NearestSurfacePoint TriangleBvh::Nearest(const Eigen::Vector3d& query, double max_distance, int hint) const {
  if (nodes_.empty()) return NearestSurfacePoint();
  NearestSearch search = StartSearch(query, max_distance, hint);
  const Eigen::Vector3f query_f = query.cast<float>();
  struct Entry {
    int node;
    float distance2;  // from the query to the node's box
  };
  Entry stack[128];
  int top = 0;
  stack[top++] = {0, BoxDistanceSquared(nodes_[0].box_min, nodes_[0].box_max, query_f)};
  while (top > 0) {
    const Entry entry = stack[--top];
    if (!(entry.distance2 <= search.prune2)) continue;
    const Node& node = nodes_[static_cast<size_t>(entry.node)];
    if (node.count > 0) {
      for (int k = node.first; k < node.first + node.count; ++k) TryTriangle(k, query, query_f, &search);
      continue;
    }
    if (top + 2 > static_cast<int>(sizeof(stack) / sizeof(stack[0]))) continue;
    const int first = entry.node + 1, second = node.first;
    const Node& a = nodes_[static_cast<size_t>(first)];
    const Node& b = nodes_[static_cast<size_t>(second)];
    const float to_a = BoxDistanceSquared(a.box_min, a.box_max, query_f);
    const float to_b = BoxDistanceSquared(b.box_min, b.box_max, query_f);
    // The nearer child is searched first: pushed last.
    if (to_a <= to_b) {
      if (to_b <= search.prune2) stack[top++] = {second, to_b};
      if (to_a <= search.prune2) stack[top++] = {first, to_a};
    } else {
      if (to_a <= search.prune2) stack[top++] = {first, to_a};
      if (to_b <= search.prune2) stack[top++] = {second, to_b};
    }
  }
  return search.nearest;
}

void TriangleBvh::NearestBatch(const Eigen::Vector3d* queries, size_t count, double max_distance,
                               NearestSurfacePoint* nearest, std::vector<int>* candidates) const {
  constexpr size_t kGroup = 16;
  int hint = -1;
  std::array<NearestSearch, kGroup> searches;
  for (size_t begin = 0; begin < count; begin += kGroup) {
    const size_t end = std::min(count, begin + kGroup);
    // The group's first query searched alone: its triangle bounds the others' distances, and every
    // triangle that can beat those bounds lies within the largest of them of the group's box.
    nearest[begin] = Nearest(queries[begin], max_distance, hint);
    if (nearest[begin].triangle >= 0) hint = nearest[begin].triangle;
    Eigen::Vector3f group_min = Eigen::Vector3f::Constant(INFINITY), group_max = -group_min;
    double reach2 = 0.0;
    for (size_t i = begin + 1; i < end; ++i) {
      searches[i - begin] = StartSearch(queries[i], max_distance, hint);
      reach2 = std::max(reach2, searches[i - begin].best2);
      const Eigen::Vector3f query_f = queries[i].cast<float>();
      group_min = group_min.cwiseMin(query_f);
      group_max = group_max.cwiseMax(query_f);
    }
    if (end - begin < 2) continue;
    if (!(reach2 < INFINITY) || !group_min.allFinite() || !group_max.allFinite()) {
      for (size_t i = begin + 1; i < end; ++i) nearest[i] = Nearest(queries[i], max_distance, hint);
      continue;
    }
    const float reach2_f = static_cast<float>(reach2 * (1.0 + 1e-5) + 1e-12);
    const auto box_to_group = [&](const Eigen::Vector3f& box_min, const Eigen::Vector3f& box_max) {
      return (box_min - group_max).cwiseMax(group_min - box_max).cwiseMax(0.0f).squaredNorm();
    };
    // A group spread wide (or far from the surface) has too many candidates to share: its queries
    // are searched one by one.
    constexpr size_t kMaxCandidates = 32;
    candidates->clear();
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    bool shared = true;
    while (top > 0 && shared) {
      const Node& node = nodes_[static_cast<size_t>(stack[--top])];
      if (!(box_to_group(node.box_min, node.box_max) <= reach2_f)) continue;
      if (node.count > 0) {
        for (int k = node.first; k < node.first + node.count; ++k) {
          const std::array<Eigen::Vector3f, 2>& box = boxes_[static_cast<size_t>(k)];
          if (box_to_group(box[0], box[1]) <= reach2_f) candidates->push_back(k);
        }
        shared = candidates->size() <= kMaxCandidates;
        continue;
      }
      if (top + 2 > static_cast<int>(sizeof(stack) / sizeof(stack[0]))) {
        shared = false;
        continue;
      }
      stack[top++] = node.first;
      stack[top++] = static_cast<int>(&node - nodes_.data()) + 1;
    }
    if (!shared) {
      for (size_t i = begin + 1; i < end; ++i) {
        nearest[i] = Nearest(queries[i], max_distance, hint);
        if (nearest[i].triangle >= 0) hint = nearest[i].triangle;
      }
      continue;
    }
    for (size_t i = begin + 1; i < end; ++i) {
      NearestSearch& search = searches[i - begin];
      const Eigen::Vector3f query_f = queries[i].cast<float>();
      for (const int k : *candidates) TryTriangle(k, queries[i], query_f, &search);
      nearest[i] = search.nearest;
    }
  }
}

RayHit TriangleBvh::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double min_distance,
                              double max_distance) const {
  RayHit hit;
  if (nodes_.empty()) return hit;
  const Eigen::Vector3d inverse = direction.cwiseInverse();
  double best = max_distance;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[static_cast<size_t>(stack[--top])];
    if (!(BoxEntry(node.box_min, node.box_max, origin, inverse, min_distance, best) < INFINITY)) continue;
    if (node.count > 0) {
      for (int k = node.first; k < node.first + node.count; ++k) {
        const std::array<Eigen::Vector3f, 3>& c = corners_[static_cast<size_t>(k)];
        const Eigen::Vector3d a = c[0].cast<double>();
        const Eigen::Vector3d e1 = c[1].cast<double>() - a, e2 = c[2].cast<double>() - a;
        const Eigen::Vector3d p = direction.cross(e2);
        const double determinant = e1.dot(p);
        if (std::abs(determinant) < 1e-300) continue;
        const Eigen::Vector3d s = origin - a;
        const double u = s.dot(p) / determinant;
        if (u < 0.0 || u > 1.0) continue;
        const Eigen::Vector3d q = s.cross(e1);
        const double v = direction.dot(q) / determinant;
        if (v < 0.0 || u + v > 1.0) continue;
        const double distance = e2.dot(q) / determinant;
        if (distance > min_distance && distance < best) {
          best = distance;
          hit.triangle = order_[static_cast<size_t>(k)];
          hit.distance = distance;
        }
      }
      continue;
    }
    // Depth is at most about log2(triangles / kLeafSize) + a few: the median split halves each node.
    if (top + 2 > static_cast<int>(sizeof(stack) / sizeof(stack[0]))) continue;
    stack[top++] = node.first;
    stack[top++] = static_cast<int>(&node - nodes_.data()) + 1;
  }
  if (hit.triangle >= 0) hit.point = origin + hit.distance * direction;
  return hit;
}

}  // namespace reconar
