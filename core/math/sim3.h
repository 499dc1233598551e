#pragma once
// Sim3: a similarity joining two named frames, X_a = scale * R X_b + t for a_from_b (the metric
// registration of a reconstruction, the alignment of an estimate to ground truth).
// AlignSimilarity: the least-squares similarity between paired points (Umeyama, "Least-squares
// estimation of transformation parameters between two point patterns", PAMI 1991).
#include <Eigen/Core>
#include <Eigen/SVD>
#include <algorithm>
#include <optional>
#include <vector>

#include "core/base/status.h"

namespace reconar {

struct Sim3 {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d Apply(const Eigen::Vector3d& from) const { return scale * rotation * from + translation; }
};

// The Sim3 with to_i ~ Apply(from_i) in the least-squares sense; with `fixed_scale` only the
// rotation and translation are estimated. Needs at least 3 pairs and a `from` set that is not a
// single point, to rounding (InvalidArgument otherwise).
inline Result<Sim3> AlignSimilarity(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to,
                                    std::optional<double> fixed_scale = std::nullopt) {
  if (from.size() != to.size()) return InvalidArgument("AlignSimilarity: point sets differ in size");
  if (from.size() < 3) return InvalidArgument("AlignSimilarity: needs at least 3 point pairs");
  const double n = static_cast<double>(from.size());
  Eigen::Vector3d mean_from = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_to = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    mean_from += from[i] / n;
    mean_to += to[i] / n;
  }
  // Covariance Sigma = 1/n sum (to - mean_to)(from - mean_from)^T and variance of `from` (eq. 36-38).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double variance_from = 0.0;
  for (size_t i = 0; i < from.size(); ++i) {
    covariance += (to[i] - mean_to) * (from[i] - mean_from).transpose() / n;
    variance_from += (from[i] - mean_from).squaredNorm() / n;
  }
  // Points that differ only by rounding (cameras turning on one spot) give no rotation either.
  double largest_from = 0.0;
  for (const Eigen::Vector3d& point : from) largest_from = std::max(largest_from, point.norm());
  if (!(variance_from > 1e-18 * largest_from * largest_from)) {
    return InvalidArgument("AlignSimilarity: all source points coincide");
  }

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d s = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) s.z() = -1.0;  // a reflection otherwise
  Sim3 similarity;
  similarity.rotation = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  similarity.scale = fixed_scale ? *fixed_scale : svd.singularValues().dot(s) / variance_from;
  similarity.translation = mean_to - similarity.scale * similarity.rotation * mean_from;
  return similarity;
}

}  // namespace reconar
