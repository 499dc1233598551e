#pragma once
// Rotation helpers, written once: the skew matrix, angle-axis <-> matrix (the exponential map of
// SO(3), Rodrigues' formula via Eigen::AngleAxis) and the nearest rotation to a 3x3 matrix.
// A rotation vector w has angle |w| (radians) about the axis w / |w|.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace reconar {

// [v]x, so that [v]x a = v x a.
inline Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

// exp([w]x): the identity for w = 0, I + [w]x below 1e-12 rad (exact to double precision there),
// Rodrigues' formula otherwise.
inline Eigen::Matrix3d RotationFromAngleAxis(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity() + Skew(w);
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// log(R): the rotation vector of R (angle in [0, pi]).
inline Eigen::Vector3d AngleAxisFromRotation(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// The rotation nearest to m in the Frobenius norm: U diag(1, 1, det(U V^T)) V^T of m = U S V^T.
inline Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

// Angle of the rotation between a and b, in radians; accurate for small angles too.
inline double RotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(Eigen::Quaterniond(a.transpose() * b).normalized()).angle();
}

}  // namespace reconar
