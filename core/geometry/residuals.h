#pragma once
// Per-correspondence residuals shared by the estimators. Inline because RANSAC evaluates them
// for every putative match of every hypothesis.
#include <limits>

#include <Eigen/Core>

namespace reconar {

// Squared Sampson distance of (x1, x2) to the epipolar geometry x2^T F x1 = 0: the first-order
// approximation of the squared geometric (reprojection) error, (x2^T F x1)^2 /
// ((F x1)_1^2 + (F x1)_2^2 + (F^T x2)_1^2 + (F^T x2)_2^2) (Hartley & Zisserman, eq. 11.9).
// Same units as the points squared; returns the largest double when the denominator vanishes.
// Algebraic residual x2^T F x1 and the squared norm of its gradient in (x1, x2), whose ratio
// e^2 / denominator is the squared Sampson distance.
struct SampsonTerms {
  double e;
  double denominator;
};
inline SampsonTerms SampsonParts(const Eigen::Matrix3d& F, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) {
  const double l0 = F(0, 0) * x1.x() + F(0, 1) * x1.y() + F(0, 2);  // F x1 (line in image b)
  const double l1 = F(1, 0) * x1.x() + F(1, 1) * x1.y() + F(1, 2);
  const double l2 = F(2, 0) * x1.x() + F(2, 1) * x1.y() + F(2, 2);
  const double m0 = F(0, 0) * x2.x() + F(1, 0) * x2.y() + F(2, 0);  // F^T x2 (line in image a)
  const double m1 = F(0, 1) * x2.x() + F(1, 1) * x2.y() + F(2, 1);
  return {x2.x() * l0 + x2.y() * l1 + l2, l0 * l0 + l1 * l1 + m0 * m0 + m1 * m1};
}

inline double SquaredSampsonError(const Eigen::Matrix3d& F, const Eigen::Vector2d& x1,
                                  const Eigen::Vector2d& x2) {
  const SampsonTerms t = SampsonParts(F, x1, x2);
  if (!(t.denominator > 0.0)) return std::numeric_limits<double>::max();
  return t.e * t.e / t.denominator;
}

// Squared one-sided transfer error ||x2 - pi(H x1)||^2 (Hartley & Zisserman, eq. 4.6); the
// largest double when H x1 lies at infinity.
inline double SquaredTransferError(const Eigen::Matrix3d& H, const Eigen::Vector2d& x1,
                                   const Eigen::Vector2d& x2) {
  const double w = H(2, 0) * x1.x() + H(2, 1) * x1.y() + H(2, 2);
  if (!(w != 0.0)) return std::numeric_limits<double>::max();
  const double inv_w = 1.0 / w;
  const double u = (H(0, 0) * x1.x() + H(0, 1) * x1.y() + H(0, 2)) * inv_w - x2.x();
  const double v = (H(1, 0) * x1.x() + H(1, 1) * x1.y() + H(1, 2)) * inv_w - x2.y();
  const double squared = u * u + v * v;
  return squared >= 0.0 ? squared : std::numeric_limits<double>::max();  // NaN -> largest
}

}  // namespace reconar
