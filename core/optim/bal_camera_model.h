#pragma once
// The BAL / Bundler camera model with analytic Jacobians.
//   P = R(w) X + t,  p = -P.xy / P.z,  d = 1 + k1 |p|^2 + k2 |p|^4,  u = f d p.
// R(w) is the Rodrigues rotation of the angle-axis vector w. Its derivative uses the closed form
// d(R(w) v)/dw = -[R(w) v]x J_l(w), with the left Jacobian of SO(3)
// J_l(w) = I + (1 - cos t)/t^2 [w]x + (t - sin t)/t^3 [w]x^2, t = |w|
// (e.g. Gallego & Yezzi, "A compact formula for the derivative of a 3-D rotation in exponential
// coordinates", JMIV 2015; Barfoot, "State Estimation for Robotics", 2017, sec. 7.1.3).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "core/math/rotation.h"

namespace reconar {

// Rodrigues coefficients a = sin t / t, b = (1 - cos t) / t^2, c = (t - sin t) / t^3, using
// their Taylor series near t = 0 where the closed forms lose precision.
inline void RodriguesCoefficients(double theta2, double* a, double* b, double* c) {
  if (theta2 < 1e-6) {
    const double t4 = theta2 * theta2;
    *a = 1.0 - theta2 / 6.0 + t4 / 120.0;
    *b = 0.5 - theta2 / 24.0 + t4 / 720.0;
    *c = 1.0 / 6.0 - theta2 / 120.0 + t4 / 5040.0;
  } else {
    const double theta = std::sqrt(theta2);
    const double s = std::sin(theta);
    *a = s / theta;
    *b = (1.0 - std::cos(theta)) / theta2;
    *c = (theta - s) / (theta2 * theta);
  }
}

// X rotated by the angle-axis vector w (Rodrigues' formula, R(w) X = X + a w x X + b w x (w x X)),
// with the coefficients its Jacobians need; shared by the BAL and the radial parameter blocks.
struct AngleAxisRotation {
  AngleAxisRotation(const Eigen::Vector3d& angle_axis, const Eigen::Vector3d& x) : w(angle_axis) {
    RodriguesCoefficients(w.squaredNorm(), &a, &b, &c);
    const Eigen::Vector3d wx = w.cross(x);
    rx = x + a * wx + b * w.cross(wx);
  }

  // d(R(w) X) / dw = -[R(w) X]x J_l(w).
  Eigen::Matrix3d JacobianWrtAngleAxis() const {
    const Eigen::Matrix3d wxm = Skew(w);
    const Eigen::Matrix3d jl = Eigen::Matrix3d::Identity() + b * wxm + c * wxm * wxm;
    return -Skew(rx) * jl;
  }

  // d(R(w) X) / dX = R(w).
  Eigen::Matrix3d Matrix() const { return Eigen::Matrix3d::Identity() + a * Skew(w) + b * Skew(w) * Skew(w); }

  Eigen::Vector3d w;
  double a = 0.0, b = 0.0, c = 0.0;  // RodriguesCoefficients of |w|^2
  Eigen::Vector3d rx;                // R(w) X
};

// Projects `point` (3 doubles) with `camera` (9 doubles) into predicted[2]. When jac_camera
// (2x9, row-major) or jac_point (2x3, row-major) are non-null, fills d predicted / d params.
// Returns false when the point lies on the camera plane (P.z == 0); outputs are then undefined.
inline bool ProjectBal(const double* camera, const double* point, double* predicted,
                       double* jac_camera, double* jac_point) {
  const Eigen::Map<const Eigen::Vector3d> w(camera);
  const Eigen::Map<const Eigen::Vector3d> t(camera + 3);
  const double f = camera[6], k1 = camera[7], k2 = camera[8];
  const Eigen::Map<const Eigen::Vector3d> x(point);

  const AngleAxisRotation rotation(w, x);
  const Eigen::Vector3d p3 = rotation.rx + t;
  if (p3.z() == 0.0) return false;
  const double inv_z = 1.0 / p3.z();
  const double px = -p3.x() * inv_z, py = -p3.y() * inv_z;
  const double r2 = px * px + py * py;
  const double d = 1.0 + r2 * (k1 + k2 * r2);
  predicted[0] = f * d * px;
  predicted[1] = f * d * py;
  if (jac_camera == nullptr && jac_point == nullptr) return true;

  // du/dp = f (d I + (2 k1 + 4 k2 r2) p p^T); dp/dP = [-1/z 0 x/z^2; 0 -1/z y/z^2].
  const double e = 2.0 * k1 + 4.0 * k2 * r2;
  Eigen::Matrix2d du_dp;
  du_dp << f * (d + e * px * px), f * e * px * py, f * e * px * py, f * (d + e * py * py);
  Eigen::Matrix<double, 2, 3> dp_dP;
  dp_dP << -inv_z, 0.0, -px * inv_z, 0.0, -inv_z, -py * inv_z;  // x/z^2 = -px/z
  const Eigen::Matrix<double, 2, 3> du_dP = du_dp * dp_dP;

  if (jac_camera != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 9, Eigen::RowMajor>> jc(jac_camera);
    jc.block<2, 3>(0, 0) = du_dP * rotation.JacobianWrtAngleAxis();
    jc.block<2, 3>(0, 3) = du_dP;
    jc(0, 6) = d * px;
    jc(1, 6) = d * py;
    jc(0, 7) = f * r2 * px;
    jc(1, 7) = f * r2 * py;
    jc(0, 8) = f * r2 * r2 * px;
    jc(1, 8) = f * r2 * r2 * py;
  }
  if (jac_point != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jp(jac_point);
    jp = du_dP * rotation.Matrix();
  }
  return true;
}

}  // namespace reconar
