#include "core/optim/bal_camera_model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

namespace reconar {
namespace {

// Central differences with step h relative to the parameter magnitude.
void CheckJacobians(const double camera_in[9], const double point_in[3]) {
  double camera[9], point[3];
  std::copy(camera_in, camera_in + 9, camera);
  std::copy(point_in, point_in + 3, point);
  double uv[2] = {0.0, 0.0}, jc[18], jp[6];
  ASSERT_TRUE(ProjectBal(camera, point, uv, jc, jp));
  for (int k = 0; k < 12; ++k) {
    double* x = k < 9 ? &camera[k] : &point[k - 9];
    const double x0 = *x;
    const double h = 1e-6 * std::max(1.0, std::abs(x0));
    double up[2] = {0.0, 0.0}, um[2] = {0.0, 0.0};
    *x = x0 + h;
    ProjectBal(camera, point, up, nullptr, nullptr);
    *x = x0 - h;
    ProjectBal(camera, point, um, nullptr, nullptr);
    *x = x0;
    for (int r = 0; r < 2; ++r) {
      const double fd = (up[r] - um[r]) / (2.0 * h);
      const double an = k < 9 ? jc[r * 9 + k] : jp[r * 3 + (k - 9)];
      EXPECT_NEAR(an, fd, 1e-6 * std::max(1.0, std::abs(fd))) << "row " << r << " param " << k;
    }
  }
}

TEST(BalCameraModelTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    double camera[9], point[3];
    // Rotations from ~1e-5 rad (series branch) to ~2.5 rad.
    const double rot_scale = trial % 4 == 0 ? 1e-5 : (trial % 4 == 1 ? 1e-3 : 1.5);
    for (int d = 0; d < 3; ++d) camera[d] = rot_scale * u(rng);
    camera[3] = u(rng);
    camera[4] = u(rng);
    camera[5] = -5.0 + u(rng);
    camera[6] = 300.0 + 100.0 * u(rng);
    camera[7] = 0.1 * u(rng);
    camera[8] = 0.05 * u(rng);
    // Point in front of the camera: P = R X + t with P.z < 0.
    for (int d = 0; d < 3; ++d) point[d] = u(rng);
    SCOPED_TRACE(trial);
    CheckJacobians(camera, point);
  }
}

TEST(BalCameraModelTest, ZeroRotationAndKnownProjection) {
  const double camera[9] = {0, 0, 0, 0, 0, -4, 100, 0.1, 0.01};
  const double point[3] = {1, 2, 0};
  double uv[2] = {0.0, 0.0};
  ASSERT_TRUE(ProjectBal(camera, point, uv, nullptr, nullptr));
  // P = (1, 2, -4), p = (0.25, 0.5), r2 = 0.3125, d = 1 + 0.03125 + 0.0009765625.
  const double d = 1.0 + 0.1 * 0.3125 + 0.01 * 0.3125 * 0.3125;
  EXPECT_NEAR(uv[0], 100 * d * 0.25, 1e-12);
  EXPECT_NEAR(uv[1], 100 * d * 0.5, 1e-12);
  CheckJacobians(camera, point);
}

TEST(BalCameraModelTest, RotationMatchesRodriguesMatrix) {
  const double w[3] = {0.3, -0.4, 1.2};
  Eigen::Vector3d axis(w[0], w[1], w[2]);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(axis.norm(), axis.normalized()).toRotationMatrix();
  const double camera[9] = {w[0], w[1], w[2], 0, 0, 0, 1, 0, 0};
  const double point[3] = {0.5, -1.0, 2.0};
  double uv[2] = {0.0, 0.0};
  ASSERT_TRUE(ProjectBal(camera, point, uv, nullptr, nullptr));
  const Eigen::Vector3d p = r * Eigen::Vector3d(point[0], point[1], point[2]);
  EXPECT_NEAR(uv[0], -p.x() / p.z(), 1e-12);
  EXPECT_NEAR(uv[1], -p.y() / p.z(), 1e-12);
}

}  // namespace
}  // namespace reconar
