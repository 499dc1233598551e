#include "core/mesh/poisson/point_normals.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <functional>
#include <numeric>
#include <queue>
#include <string>
#include <tuple>
#include <vector>

#include "core/mesh/poisson/point_kdtree.h"

namespace reconar {
namespace {

// Symmetric k-NN graph in compressed rows: the neighbours of i are adjacency[offsets[i] .. offsets[i+1]).
struct Graph {
  std::vector<uint32_t> offsets;
  std::vector<uint32_t> adjacency;
};

Graph SymmetricGraph(const std::vector<uint32_t>& knn, size_t n, size_t k) {
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  edges.reserve(2 * knn.size());
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < k; ++j) {
      const uint32_t other = knn[i * k + j];
      if (other == i) continue;
      edges.emplace_back(static_cast<uint32_t>(i), other);
      edges.emplace_back(other, static_cast<uint32_t>(i));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  Graph graph;
  graph.offsets.assign(n + 1, 0);
  for (const auto& e : edges) ++graph.offsets[e.first + 1];
  std::partial_sum(graph.offsets.begin(), graph.offsets.end(), graph.offsets.begin());
  graph.adjacency.resize(edges.size());
  for (size_t e = 0; e < edges.size(); ++e) graph.adjacency[e] = edges[e].second;
  return graph;
}

}  // namespace

Status NormalEstimationOptions::Check() const {
  if (neighbors < 3) {
    return InvalidArgument("NormalEstimationOptions.neighbors must be >= 3, got " + std::to_string(neighbors));
  }
  return Status::Ok();
}

Status EstimateNormals(Mesh* points, const NormalEstimationOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  const std::vector<Eigen::Vector3f>& positions = points->positions;
  const size_t n = positions.size();
  if (n < 3) return InvalidArgument("normal estimation needs at least 3 points, got " + std::to_string(n));
  for (size_t i = 0; i < n; ++i) {
    if (!positions[i].allFinite()) return InvalidArgument("point " + std::to_string(i) + " has a non-finite position");
  }
  const size_t k = std::min(static_cast<size_t>(options.neighbors), n);

  // Unoriented normals by PCA of each k-neighbourhood.
  const poisson::PointKdTree tree(positions);
  std::vector<uint32_t> knn(n * k);
  std::vector<Eigen::Vector3f> normals(n, Eigen::Vector3f::Zero());
  std::vector<uint8_t> degenerate(n, 0);
  std::vector<std::pair<float, uint32_t>> nearest;
  for (size_t i = 0; i < n; ++i) {
    tree.Nearest(positions[i], static_cast<int>(k), &nearest);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (size_t j = 0; j < k; ++j) {
      knn[i * k + j] = nearest[j].second;
      mean += (positions[nearest[j].second] - positions[i]).cast<double>();
    }
    mean /= static_cast<double>(k);
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (size_t j = 0; j < k; ++j) {
      const Eigen::Vector3d d = (positions[nearest[j].second] - positions[i]).cast<double>() - mean;
      covariance += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance);
    if (!(solver.eigenvalues()(2) > 0.0)) {
      degenerate[i] = 1;
      continue;
    }
    normals[i] = solver.eigenvectors().col(0).cast<float>().normalized();
  }

  // Orientation: Prim's minimum spanning tree per component, seeded at the highest point.
  const Graph graph = SymmetricGraph(knn, n, k);
  std::vector<uint32_t> by_height(n);
  std::iota(by_height.begin(), by_height.end(), 0u);
  std::stable_sort(by_height.begin(), by_height.end(),
                   [&](uint32_t a, uint32_t b) { return positions[a].z() > positions[b].z(); });
  std::vector<uint8_t> oriented(n, 0);
  using Candidate = std::tuple<float, uint32_t, uint32_t>;  // cost, point, tree parent
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> queue;
  auto push_edges = [&](uint32_t from) {
    for (uint32_t e = graph.offsets[from]; e < graph.offsets[from + 1]; ++e) {
      const uint32_t to = graph.adjacency[e];
      if (!oriented[to]) queue.emplace(1.0f - std::abs(normals[from].dot(normals[to])), to, from);
    }
  };
  for (const uint32_t seed : by_height) {
    if (oriented[seed]) continue;
    if (degenerate[seed]) normals[seed] = Eigen::Vector3f::UnitZ();
    if (normals[seed].z() < 0.0f) normals[seed] = -normals[seed];
    oriented[seed] = 1;
    push_edges(seed);
    while (!queue.empty()) {
      const auto [cost, point, parent] = queue.top();
      queue.pop();
      if (oriented[point]) continue;
      if (degenerate[point]) {
        normals[point] = normals[parent];
      } else if (normals[point].dot(normals[parent]) < 0.0f) {
        normals[point] = -normals[point];
      }
      oriented[point] = 1;
      push_edges(point);
    }
  }
  points->normals = std::move(normals);
  return Status::Ok();
}

}  // namespace reconar
