#pragma once
// The bundle adjuster's view of the one camera model (RadialCamera, core/math/radial_camera.h)
// over a flat 12-double parameter block, with analytic Jacobians, cam_from_world pose:
//   P = R(w) X + t,  p = P.xy / P.z,  d = 1 + k1 |p|^2 + k2 |p|^4,
//   u = f d p.x + cx,  v = a f d p.y + cy.
// Parameters: w (3), t (3), f, k1, k2, cx, cy, a. The pixel and d pixel / d p are RadialCamera's
// (PixelFromNormalised, PixelFromNormalisedJacobian), chained with d p / d P and the rotation's
// Jacobians (bal_camera_model.h); the intrinsic columns are d pixel / d (f, k1, k2, cx, cy, a).
#include <Eigen/Core>

#include "core/math/radial_camera.h"
#include "core/optim/bal_camera_model.h"

namespace reconar {

// The RadialCamera of a 12-double parameter block.
inline RadialCamera RadialCameraOfBlock(const double* camera) {
  RadialCamera radial;
  radial.focal = camera[6];
  radial.k1 = camera[7];
  radial.k2 = camera[8];
  radial.cx = camera[9];
  radial.cy = camera[10];
  radial.aspect = camera[11];
  return radial;
}

// Projects `point` (3 doubles) with `camera` (12 doubles) into predicted[2] (pixels). Optional
// jac_camera (2x12, row-major) and jac_point (2x3, row-major). False when P.z == 0.
inline bool ProjectRadial(const double* camera, const double* point, double* predicted, double* jac_camera,
                          double* jac_point) {
  const Eigen::Map<const Eigen::Vector3d> w(camera);
  const Eigen::Map<const Eigen::Vector3d> t(camera + 3);
  const Eigen::Map<const Eigen::Vector3d> x(point);
  const AngleAxisRotation rotation(w, x);
  const Eigen::Vector3d P = rotation.rx + t;
  if (P.z() == 0.0) return false;
  const double inv_z = 1.0 / P.z();
  const Eigen::Vector2d p(P.x() * inv_z, P.y() * inv_z);
  const RadialCamera radial = RadialCameraOfBlock(camera);
  const Eigen::Vector2d pixel = radial.PixelFromNormalised(p);
  predicted[0] = pixel.x();
  predicted[1] = pixel.y();
  if (jac_camera == nullptr && jac_point == nullptr) return true;

  Eigen::Matrix<double, 2, 3> dp_dP;
  dp_dP << inv_z, 0.0, -p.x() * inv_z, 0.0, inv_z, -p.y() * inv_z;
  const Eigen::Matrix<double, 2, 3> du_dP = radial.PixelFromNormalisedJacobian(p) * dp_dP;
  if (jac_camera != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 12, Eigen::RowMajor>> jc(jac_camera);
    jc.block<2, 3>(0, 0) = du_dP * rotation.JacobianWrtAngleAxis();
    jc.block<2, 3>(0, 3) = du_dP;
    // u = f d p.x + cx, v = a f d p.y + cy with d = 1 + k1 r2 + k2 r2^2.
    const double r2 = p.squaredNorm();
    const Eigen::Vector2d dp = radial.Distortion(r2) * p;
    const double f = radial.focal, a = radial.aspect;
    jc(0, 6) = dp.x();
    jc(1, 6) = a * dp.y();
    jc(0, 7) = f * r2 * p.x();
    jc(1, 7) = a * f * r2 * p.y();
    jc(0, 8) = f * r2 * r2 * p.x();
    jc(1, 8) = a * f * r2 * r2 * p.y();
    jc(0, 9) = 1.0;
    jc(1, 9) = 0.0;
    jc(0, 10) = 0.0;
    jc(1, 10) = 1.0;
    jc(0, 11) = 0.0;
    jc(1, 11) = f * dp.y();
  }
  if (jac_point != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jp(jac_point);
    jp = du_dP * rotation.Matrix();
  }
  return true;
}

}  // namespace reconar
