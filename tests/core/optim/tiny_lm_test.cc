// TinyLmSolve on small problems, with Eigen's heap guard armed: this TU defines
// EIGEN_RUNTIME_NO_MALLOC (see CMakeLists.txt) and asserts are on, so any heap allocation by
// Eigen inside the solve aborts the test.
#include "core/optim/tiny_lm.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/optim/bal_camera_model.h"

namespace reconar {
namespace {

// Rosenbrock as least squares: r = (10 (x1 - x0^2), 1 - x0); minimum 0 at (1, 1).
struct Rosenbrock {
  bool operator()(const Eigen::Vector2d& x, Eigen::Vector2d* r, Eigen::Matrix2d* j) const {
    (*r) << 10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0];
    if (j != nullptr) *j << -20.0 * x[0], 10.0, -1.0, 0.0;
    return true;
  }
};

// y = a exp(b t) + c sampled at 12 points.
struct ExpFit {
  Eigen::Matrix<double, 12, 1> t, y;
  bool operator()(const Eigen::Vector3d& p, Eigen::Matrix<double, 12, 1>* r,
                  Eigen::Matrix<double, 12, 3>* j) const {
    for (int k = 0; k < 12; ++k) {
      const double e = std::exp(p[1] * t[k]);
      (*r)[k] = p[0] * e + p[2] - y[k];
      if (j != nullptr) (*j).row(k) << e, p[0] * t[k] * e, 1.0;
    }
    return true;
  }
};

// Resection of one BAL camera's pose (angle-axis, t) from 8 exact observations.
struct BalPose {
  double intrinsics[3] = {400.0, 0.02, 0.001};
  double points[8][3];
  double observed[8][2];
  bool operator()(const Eigen::Matrix<double, 6, 1>& pose, Eigen::Matrix<double, 16, 1>* r,
                  Eigen::Matrix<double, 16, 6>* j) const {
    double camera[9];
    for (int d = 0; d < 6; ++d) camera[d] = pose[d];
    for (int d = 0; d < 3; ++d) camera[6 + d] = intrinsics[d];
    for (int k = 0; k < 8; ++k) {
      double uv[2] = {0.0, 0.0}, jc[18];
      if (!ProjectBal(camera, points[k], uv, j != nullptr ? jc : nullptr, nullptr)) return false;
      (*r)[2 * k] = uv[0] - observed[k][0];
      (*r)[2 * k + 1] = uv[1] - observed[k][1];
      if (j != nullptr) {
        for (int d = 0; d < 6; ++d) {
          (*j)(2 * k, d) = jc[d];
          (*j)(2 * k + 1, d) = jc[9 + d];
        }
      }
    }
    return true;
  }
};

class NoMallocScope {
 public:
  NoMallocScope() { Eigen::internal::set_is_malloc_allowed(false); }
  ~NoMallocScope() { Eigen::internal::set_is_malloc_allowed(true); }
};

TEST(TinyLmTest, GuardIsArmed) {
#ifndef EIGEN_RUNTIME_NO_MALLOC
  FAIL() << "EIGEN_RUNTIME_NO_MALLOC must be defined for this test";
#endif
  EXPECT_DEATH(
      {
        NoMallocScope guard;
        Eigen::VectorXd v(100);
        v.setZero();
      },
      "");
}

TEST(TinyLmTest, Rosenbrock) {
  Eigen::Vector2d x(-1.2, 1.0);
  TinyLmSummary s;
  {
    NoMallocScope guard;
    s = TinyLmSolve<2, 2>(Rosenbrock(), TinyLmOptions(), &x);
  }
  EXPECT_TRUE(s.converged());
  EXPECT_LT(s.final_cost, 1e-20);
  EXPECT_NEAR(x[0], 1.0, 1e-9);
  EXPECT_NEAR(x[1], 1.0, 1e-9);
}

TEST(TinyLmTest, ExponentialFit) {
  ExpFit f;
  for (int k = 0; k < 12; ++k) {
    f.t[k] = 0.25 * k;
    f.y[k] = 2.0 * std::exp(-0.7 * f.t[k]) + 0.5;
  }
  Eigen::Vector3d p(1.0, 0.0, 0.0);
  TinyLmSummary s;
  {
    NoMallocScope guard;
    s = TinyLmSolve<3, 12>(f, TinyLmOptions(), &p);
  }
  EXPECT_TRUE(s.converged());
  EXPECT_NEAR(p[0], 2.0, 1e-7);
  EXPECT_NEAR(p[1], -0.7, 1e-7);
  EXPECT_NEAR(p[2], 0.5, 1e-7);
}

TEST(TinyLmTest, BalPoseResection) {
  BalPose f;
  const double truth[6] = {0.1, -0.2, 0.05, 0.3, -0.1, -5.0};
  double camera[9];
  for (int d = 0; d < 6; ++d) camera[d] = truth[d];
  for (int d = 0; d < 3; ++d) camera[6 + d] = f.intrinsics[d];
  for (int k = 0; k < 8; ++k) {
    f.points[k][0] = (k % 2 ? 1.0 : -1.0) * (0.5 + 0.1 * k);
    f.points[k][1] = (k % 3 ? 0.7 : -0.8) - 0.05 * k;
    f.points[k][2] = (k % 4 < 2 ? 0.6 : -0.5);
    ProjectBal(camera, f.points[k], f.observed[k], nullptr, nullptr);
  }
  Eigen::Matrix<double, 6, 1> pose;
  pose << 0.15, -0.15, 0.0, 0.2, 0.0, -4.5;
  TinyLmSummary s;
  {
    NoMallocScope guard;
    s = TinyLmSolve<6, 16>(f, TinyLmOptions(), &pose);
  }
  EXPECT_TRUE(s.converged());
  EXPECT_LT(s.final_cost, 1e-16);
  for (int d = 0; d < 6; ++d) EXPECT_NEAR(pose[d], truth[d], 1e-8) << d;
}

TEST(TinyLmTest, FunctorFailureAtStartIsNumericFailure) {
  auto failing = [](const Eigen::Vector2d&, Eigen::Vector2d*, Eigen::Matrix2d*) { return false; };
  Eigen::Vector2d x(0.0, 0.0);
  const TinyLmSummary s = TinyLmSolve<2, 2>(failing, TinyLmOptions(), &x);
  EXPECT_EQ(s.termination, TinyLmSummary::Termination::kNumericFailure);
  EXPECT_EQ(s.iterations, 0);
}

}  // namespace
}  // namespace reconar
