#include "core/mesh/poisson/point_outliers.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "core/base/median.h"
#include "core/base/thread_pool.h"
#include "core/base/union_find.h"
#include "core/mesh/poisson/point_kdtree.h"

namespace reconar {
namespace {

enum Verdict : uint8_t { kInlier = 0, kIsolated = 1, kSmallPiece = 2 };

// The two tests on pairwise distinct points (a zero distance would make every neighbour of a
// duplicated point look isolated): one Verdict per point. Sets report->pieces, pieces_kept and
// median_spacing.
std::vector<uint8_t> ClassifyDistinctPoints(const std::vector<Eigen::Vector3f>& positions,
                                            const OutlierFilterOptions& options, OutlierFilterReport* report) {
  const size_t n = positions.size();
  const size_t k = static_cast<size_t>(options.neighbors);
  std::vector<uint8_t> verdict(n, kInlier);
  if (n <= k) {
    report->pieces = report->pieces_kept = n > 0 ? 1 : 0;
    return verdict;
  }

  // The k nearest neighbours of every point (itself excluded) and log d_i, d_i their mean distance.
  const poisson::PointKdTree tree(positions);
  std::vector<uint32_t> knn(n * k);
  std::vector<float> knn_distance(n * k);
  std::vector<double> log_spacing(n);
  ThreadPool pool(options.num_threads);
  std::vector<std::vector<std::pair<float, uint32_t>>> scratch(static_cast<size_t>(pool.num_threads()));
  constexpr size_t kChunk = 4096;
  const size_t chunks = (n + kChunk - 1) / kChunk;
  pool.ParallelFor(0, chunks, [&](size_t chunk, int worker) {
    std::vector<std::pair<float, uint32_t>>& nearest = scratch[static_cast<size_t>(worker)];
    for (size_t i = chunk * kChunk; i < std::min(n, (chunk + 1) * kChunk); ++i) {
      tree.Nearest(positions[i], static_cast<int>(k + 1), &nearest);
      double sum = 0.0;
      size_t j = 0;
      for (const auto& [squared, index] : nearest) {
        if (index == i || j == k) continue;
        knn[i * k + j] = index;
        knn_distance[i * k + j] = std::sqrt(squared);
        sum += knn_distance[i * k + j];
        ++j;
      }
      log_spacing[i] = std::log(sum / static_cast<double>(k));
    }
  });

  // Isolated points: log(d_i / median of the neighbours' d_j), against a robust z-score bound.
  std::vector<double> log_ratio(n);
  pool.ParallelFor(0, chunks, [&](size_t chunk, int) {
    std::vector<double> around(k);
    for (size_t i = chunk * kChunk; i < std::min(n, (chunk + 1) * kChunk); ++i) {
      for (size_t j = 0; j < k; ++j) around[j] = log_spacing[knn[i * k + j]];
      log_ratio[i] = log_spacing[i] - MedianInPlace(around.data(), k);
    }
  });
  const double median = Median(log_ratio);
  std::vector<double> deviation(n);
  for (size_t i = 0; i < n; ++i) deviation[i] = std::abs(log_ratio[i] - median);
  const double sigma = 1.4826 * Median(deviation);
  const double limit = median + std::max(options.max_robust_sigmas * sigma, std::log(options.min_isolation_ratio));
  size_t survivors = 0;
  for (size_t i = 0; i < n; ++i) {
    verdict[i] = log_ratio[i] > limit ? kIsolated : kInlier;
    survivors += verdict[i] == kInlier ? 1 : 0;
  }
  report->median_spacing = std::exp(Median(log_spacing));

  // Small pieces among the survivors. An edge must be short for both ends, so that an outlier's
  // long reach does not tie it to a surface.
  UnionFind pieces(n);
  for (size_t i = 0; i < n; ++i) {
    if (verdict[i] != kInlier) continue;
    for (size_t j = 0; j < k; ++j) {
      const uint32_t other = knn[i * k + j];
      const double reach = options.link_factor * std::exp(std::min(log_spacing[i], log_spacing[other]));
      if (verdict[other] == kInlier && knn_distance[i * k + j] <= reach) pieces.Union(static_cast<uint32_t>(i), other);
    }
  }
  std::unordered_map<uint32_t, size_t> piece_size;
  for (size_t i = 0; i < n; ++i) {
    if (verdict[i] == kInlier) ++piece_size[pieces.Find(static_cast<uint32_t>(i))];
  }
  const double min_size = options.min_component_fraction * static_cast<double>(survivors);
  report->pieces = static_cast<int>(piece_size.size());
  for (const auto& [root, size] : piece_size) report->pieces_kept += static_cast<double>(size) >= min_size ? 1 : 0;
  for (size_t i = 0; i < n; ++i) {
    if (verdict[i] == kInlier && static_cast<double>(piece_size[pieces.Find(static_cast<uint32_t>(i))]) < min_size) {
      verdict[i] = kSmallPiece;
    }
  }
  return verdict;
}

}  // namespace

Status OutlierFilterOptions::Check() const {
  if (neighbors < 1)
    return InvalidArgument("OutlierFilterOptions.neighbors must be >= 1, got " + std::to_string(neighbors));
  if (!(max_robust_sigmas > 0.0)) return InvalidArgument("OutlierFilterOptions.max_robust_sigmas must be > 0");
  if (!(min_isolation_ratio >= 1.0)) return InvalidArgument("OutlierFilterOptions.min_isolation_ratio must be >= 1");
  if (!(link_factor > 0.0)) return InvalidArgument("OutlierFilterOptions.link_factor must be > 0");
  if (!(min_component_fraction >= 0.0 && min_component_fraction < 1.0)) {
    return InvalidArgument("OutlierFilterOptions.min_component_fraction must be in [0, 1)");
  }
  return Status::Ok();
}

Result<std::vector<uint8_t>> FindInlierPoints(const std::vector<Eigen::Vector3f>& positions,
                                              const OutlierFilterOptions& options, OutlierFilterReport* report) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  const size_t n = positions.size();
  for (size_t i = 0; i < n; ++i) {
    if (!positions[i].allFinite()) return InvalidArgument("point " + std::to_string(i) + " has a non-finite position");
  }
  // Coincident points share one verdict.
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  const auto less = [&](uint32_t a, uint32_t b) {
    const Eigen::Vector3f& p = positions[a];
    const Eigen::Vector3f& q = positions[b];
    return std::tie(p.x(), p.y(), p.z()) < std::tie(q.x(), q.y(), q.z());
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<uint32_t> distinct_of(n);
  std::vector<Eigen::Vector3f> distinct;
  distinct.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    if (i == 0 || less(order[i - 1], order[i])) distinct.push_back(positions[order[i]]);
    distinct_of[order[i]] = static_cast<uint32_t>(distinct.size() - 1);
  }

  OutlierFilterReport local;
  OutlierFilterReport& r = report != nullptr ? *report : local;
  r = OutlierFilterReport();
  r.input_points = n;
  const std::vector<uint8_t> verdict = ClassifyDistinctPoints(distinct, options, &r);
  std::vector<uint8_t> keep(n);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t v = verdict[distinct_of[i]];
    keep[i] = v == kInlier ? 1 : 0;
    r.isolated_removed += v == kIsolated ? 1 : 0;
    r.small_piece_removed += v == kSmallPiece ? 1 : 0;
  }
  return keep;
}

}  // namespace reconar
