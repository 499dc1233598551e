#pragma once
// The bundle adjuster's view of the one camera model (RadialCamera, core/math/radial_camera.h)
// over a flat 12-double parameter block, with analytic Jacobians, cam_from_world pose:
//   P = R(w) X + t,  p = P.xy / P.z,  d = 1 + k1 |p|^2 + k2 |p|^4,
//   u = f d p.x + cx,  v = a f d p.y + cy.
// Parameters: w (3), t (3), f, k1, k2, cx, cy, a. It is the BAL model with the camera looking
// down +z instead of -z: p = -p_bal, so the Jacobians are the BAL ones negated (the v row scaled
// by a), plus the identity for c and d v / d a = f d p.y. Its pixels agree with
// RadialCamera::Project to rounding (tests/core/optim/radial_camera_model_test.cc); the BAL form
// is kept because the adjuster's results depend on its exact floating-point operations.
#include "core/optim/bal_camera_model.h"

namespace reconar {

// Projects `point` (3 doubles) with `camera` (12 doubles) into predicted[2] (pixels). Optional
// jac_camera (2x12, row-major) and jac_point (2x3, row-major). False when P.z == 0.
inline bool ProjectRadial(const double* camera, const double* point, double* predicted,
                          double* jac_camera, double* jac_point) {
  constexpr int kSize = 12;
  double jac_bal[2 * 9];
  if (!ProjectBal(camera, point, predicted, jac_camera != nullptr ? jac_bal : nullptr,
                  jac_point)) {
    return false;
  }
  const double aspect = camera[11];
  const double v_bal = predicted[1];
  predicted[0] = camera[9] - predicted[0];
  predicted[1] = camera[10] - aspect * v_bal;
  if (jac_camera != nullptr) {
    for (int row = 0; row < 2; ++row) {
      const double scale = row == 0 ? -1.0 : -aspect;
      for (int col = 0; col < 9; ++col) jac_camera[row * kSize + col] = scale * jac_bal[row * 9 + col];
      jac_camera[row * kSize + 9] = row == 0 ? 1.0 : 0.0;
      jac_camera[row * kSize + 10] = row == 1 ? 1.0 : 0.0;
      jac_camera[row * kSize + 11] = row == 1 ? -v_bal : 0.0;
    }
  }
  if (jac_point != nullptr) {
    for (int k = 0; k < 3; ++k) jac_point[k] = -jac_point[k];
    for (int k = 3; k < 6; ++k) jac_point[k] = -aspect * jac_point[k];
  }
  return true;
}

}  // namespace reconar
