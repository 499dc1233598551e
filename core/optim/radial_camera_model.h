#pragma once
// COLMAP's RADIAL camera (Bundler's radial model with a principal point), cam_from_world pose:
//   P = R(w) X + t,  p = P.xy / P.z,  d = 1 + k1 |p|^2 + k2 |p|^4,  u = f d p + c.
// Parameters: w (3), t (3), f, k1, k2, cx, cy. It is the BAL model with the camera looking down
// +z instead of -z: p = -p_bal, so u - c = -u_bal and the Jacobians are the BAL ones negated,
// plus the identity for c.
#include "core/optim/bal_camera_model.h"

namespace reconar {

// Projects `point` (3 doubles) with `camera` (11 doubles) into predicted[2] (pixels). Optional
// jac_camera (2x11, row-major) and jac_point (2x3, row-major). False when P.z == 0.
inline bool ProjectRadial(const double* camera, const double* point, double* predicted,
                          double* jac_camera, double* jac_point) {
  double jac_bal[2 * 9];
  if (!ProjectBal(camera, point, predicted, jac_camera != nullptr ? jac_bal : nullptr,
                  jac_point)) {
    return false;
  }
  predicted[0] = camera[9] - predicted[0];
  predicted[1] = camera[10] - predicted[1];
  if (jac_camera != nullptr) {
    for (int row = 0; row < 2; ++row) {
      for (int col = 0; col < 9; ++col) jac_camera[row * 11 + col] = -jac_bal[row * 9 + col];
      jac_camera[row * 11 + 9] = row == 0 ? 1.0 : 0.0;
      jac_camera[row * 11 + 10] = row == 1 ? 1.0 : 0.0;
    }
  }
  if (jac_point != nullptr) {
    for (int k = 0; k < 6; ++k) jac_point[k] = -jac_point[k];
  }
  return true;
}

}  // namespace reconar
