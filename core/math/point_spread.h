#pragma once
// How points spread about their mean: the eigen-decomposition of their scatter matrix
// sum (p - mean) (p - mean)^T. The axis of the smallest eigenvalue is the normal of the plane they
// lie nearest; a second eigenvalue near zero says they lie on a line.
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace reconar {

struct PointSpread {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();  // of the scatter matrix, ascending
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();     // column k: the unit axis of eigenvalues[k]

  Eigen::Vector3d ThinnestAxis() const { return axes.col(0); }
};

// All zero (the axes the identity) for no points.
inline PointSpread SpreadOfPoints(const std::vector<Eigen::Vector3d>& points) {
  PointSpread spread;
  if (points.empty()) return spread;
  for (const Eigen::Vector3d& p : points) spread.mean += p / static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) scatter += (p - spread.mean) * (p - spread.mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  spread.eigenvalues = eigen.eigenvalues();
  spread.axes = eigen.eigenvectors();
  return spread;
}

}  // namespace reconar
