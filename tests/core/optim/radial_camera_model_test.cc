#include "core/optim/radial_camera_model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "core/math/radial_camera.h"
#include "core/math/rotation.h"
#include "core/optim/bundle_adjuster.h"

namespace reconar {
namespace {

TEST(RadialCameraModelTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    double camera[12] = {0.8 * u(rng), 0.8 * u(rng), 0.8 * u(rng), u(rng), u(rng), 6.0 + u(rng),
                         900.0 + 100.0 * u(rng), 0.1 * u(rng), 0.05 * u(rng),
                         640.0 + 20.0 * u(rng), 480.0 + 20.0 * u(rng), 1.0 + 0.01 * u(rng)};
    double point[3] = {u(rng), u(rng), u(rng)};
    double uv[2], jc[24], jp[6];
    ASSERT_TRUE(ProjectRadial(camera, point, uv, jc, jp));
    for (int k = 0; k < 15; ++k) {
      double* x = k < 12 ? &camera[k] : &point[k - 12];
      const double x0 = *x;
      const double h = 1e-6 * std::max(1.0, std::abs(x0));
      double up[2], um[2];
      *x = x0 + h;
      ProjectRadial(camera, point, up, nullptr, nullptr);
      *x = x0 - h;
      ProjectRadial(camera, point, um, nullptr, nullptr);
      *x = x0;
      for (int r = 0; r < 2; ++r) {
        const double fd = (up[r] - um[r]) / (2.0 * h);
        const double an = k < 12 ? jc[r * 12 + k] : jp[r * 3 + (k - 12)];
        EXPECT_NEAR(an, fd, 1e-6 * std::max(1.0, std::abs(fd))) << "trial " << trial << " param " << k;
      }
    }
  }
}

// The bundle adjuster's parameter-block projection is the one camera model (core/math/radial_camera.h).
TEST(RadialCameraModelTest, MatchesRadialCamera) {
  const Eigen::Vector3d w(0.1, -0.2, 0.05);
  const double camera[12] = {w.x(), w.y(), w.z(), 0.3, -0.1, 4.0, 1000.0, -0.05, 0.01, 320.0, 250.0, 1.002};
  RadialCamera radial;
  radial.focal = 1000.0;
  radial.k1 = -0.05;
  radial.k2 = 0.01;
  radial.cx = 320.0;
  radial.cy = 250.0;
  radial.aspect = 1.002;
  const Eigen::Vector3d X(0.4, -0.3, 1.2);
  const Eigen::Vector2d expected = radial.Project(RotationFromAngleAxis(w) * X + Eigen::Vector3d(0.3, -0.1, 4.0));
  double uv[2];
  ASSERT_TRUE(ProjectRadial(camera, X.data(), uv, nullptr, nullptr));
  EXPECT_NEAR(uv[0], expected.x(), 1e-9);
  EXPECT_NEAR(uv[1], expected.y(), 1e-9);
}

// Cameras on a ring around a point cloud; BA from perturbed parameters recovers a zero-residual
// solution, and parameters named constant stay bit-identical.
TEST(RadialBundleAdjustmentTest, ConvergesAndHoldsConstantParameters) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RadialProblem truth;
  const int num_cameras = 8, num_points = 300;
  for (int i = 0; i < num_cameras; ++i) {
    const double angle = 0.25 * i;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d center(6.0 * std::sin(angle), 0.2 * u(rng), -6.0 * std::cos(angle));
    const Eigen::Vector3d t = -R * center;
    const Eigen::AngleAxisd aa(R);
    const Eigen::Vector3d w = aa.angle() * aa.axis();
    const double cam[12] = {w.x(), w.y(), w.z(), t.x(), t.y(), t.z(), 1200.0, -0.08, 0.02, 640.0, 480.0, 1.0};
    truth.cameras.insert(truth.cameras.end(), cam, cam + 12);
  }
  for (int j = 0; j < num_points; ++j) {
    for (int d = 0; d < 3; ++d) truth.points.push_back(1.5 * u(rng));
  }
  for (int i = 0; i < num_cameras; ++i) {
    for (int j = 0; j < num_points; ++j) {
      double uv[2];
      ASSERT_TRUE(ProjectRadial(truth.camera(i), truth.point(j), uv, nullptr, nullptr));
      truth.observations.push_back({i, j, uv[0], uv[1]});
    }
  }
  RadialProblem problem = truth;
  for (int i = 1; i < num_cameras; ++i) {
    for (int d = 0; d < 6; ++d) problem.camera(i)[d] += 0.01 * u(rng);
    problem.camera(i)[6] *= 1.0 + 0.02 * u(rng);
    problem.camera(i)[9] += 5.0;
  }
  for (double& x : problem.points) x += 0.02 * u(rng);
  BundleAdjustmentOptions options;
  options.function_tolerance = 1e-12;
  options.max_iterations = 200;
  BundleAdjustmentConstancy constancy;
  constancy.constant_cameras.assign(num_cameras, 0);
  constancy.constant_cameras[0] = 1;
  constancy.constant_camera_parameters = {9, 10, 11};
  RadialProblem held = problem;
  auto summary = SolveBundleAdjustment(options, constancy, &held);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  for (int i = 0; i < num_cameras; ++i) {
    EXPECT_EQ(held.camera(i)[9], problem.camera(i)[9]);
    EXPECT_EQ(held.camera(i)[10], problem.camera(i)[10]);
  }
  // With the principal point free, the exact solution is reachable (one fixed camera and the
  // shared scale of the ring fix the gauge well enough for the cost to reach ~0).
  constancy.constant_camera_parameters = {11};
  summary = SolveBundleAdjustment(options, constancy, &problem);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_LT(summary->final_cost, 1e-8 * summary->initial_cost);
  EXPECT_LT(summary->final_cost / static_cast<double>(problem.observations.size()), 1e-10);
  for (int i = 1; i < num_cameras; ++i) {
    EXPECT_NEAR(problem.camera(i)[6], 1200.0, 0.5);
    EXPECT_NEAR(problem.camera(i)[9], 640.0, 1.0);
  }
}

// One camera shared by all images: starting from a common wrong focal, distortion and principal
// point, the shared parameters converge to the truth and stay identical across the blocks.
TEST(RadialBundleAdjustmentTest, SharedIntrinsicsConvergeAndStayEqual) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RadialProblem problem;
  const int num_cameras = 6, num_points = 200;
  for (int i = 0; i < num_cameras; ++i) {
    const double angle = 0.3 * i;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d center(6.0 * std::sin(angle), 0.3 * u(rng), -6.0 * std::cos(angle));
    const Eigen::Vector3d t = -R * center;
    const Eigen::AngleAxisd aa(R);
    const Eigen::Vector3d w = aa.angle() * aa.axis();
    const double cam[12] = {w.x(), w.y(), w.z(), t.x(), t.y(), t.z(), 1000.0, -0.1, 0.03, 600.0, 420.0, 1.003};
    problem.cameras.insert(problem.cameras.end(), cam, cam + 12);
  }
  for (int j = 0; j < num_points; ++j) {
    for (int d = 0; d < 3; ++d) problem.points.push_back(1.5 * u(rng));
  }
  for (int i = 0; i < num_cameras; ++i) {
    for (int j = 0; j < num_points; ++j) {
      double uv[2];
      ASSERT_TRUE(ProjectRadial(problem.camera(i), problem.point(j), uv, nullptr, nullptr));
      problem.observations.push_back({i, j, uv[0], uv[1]});
    }
  }
  for (int i = 1; i < num_cameras; ++i) {
    double* c = problem.camera(i);
    for (int d = 0; d < 6; ++d) c[d] += 0.005 * u(rng);
    c[6] = 1040.0;
    c[7] = 0.0;
    c[8] = 0.0;
    c[9] = 590.0;
    c[10] = 430.0;
    c[11] = 1.0;
  }
  BundleAdjustmentOptions options;
  options.function_tolerance = 1e-14;
  options.max_iterations = 300;
  BundleAdjustmentConstancy constancy;
  constancy.constant_cameras.assign(num_cameras, 0);
  constancy.constant_cameras[0] = 1;  // fixes the gauge; a constant camera keeps its own intrinsics
  constancy.intrinsics_group.assign(num_cameras, 0);
  RadialProblem sparse = problem;
  auto summary = SolveBundleAdjustment(options, constancy, &problem);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_LT(summary->final_cost, 1e-10 * summary->initial_cost);
  for (int i = 2; i < num_cameras; ++i) {
    for (int k = 6; k < 12; ++k) EXPECT_EQ(problem.camera(i)[k], problem.camera(1)[k]);
  }
  EXPECT_NEAR(problem.camera(1)[6], 1000.0, 0.1);
  EXPECT_NEAR(problem.camera(1)[7], -0.1, 1e-3);
  EXPECT_NEAR(problem.camera(1)[9], 600.0, 0.1);
  EXPECT_NEAR(problem.camera(1)[11], 1.003, 1e-5);
  // The sparse solver takes the same steps (shared_intrinsics_test.cc compares them closely).
  options.linear_solver = BundleAdjustmentOptions::LinearSolver::kSparseCholesky;
  const auto sparse_summary = SolveBundleAdjustment(options, constancy, &sparse);
  ASSERT_TRUE(sparse_summary.ok()) << sparse_summary.status().message();
  EXPECT_EQ(sparse_summary->iterations, summary->iterations);
  for (size_t k = 0; k < problem.cameras.size(); ++k) {
    EXPECT_NEAR(sparse.cameras[k], problem.cameras[k], 1e-9 * std::max(1.0, std::abs(problem.cameras[k])));
  }
}

}  // namespace
}  // namespace reconar
