#include "core/mvs/pmvs/nelder_mead.h"

#include <gtest/gtest.h>

#include <cmath>

namespace reconar {
namespace {

TEST(NelderMeadTest, FindsMinimumOfAnisotropicQuadratic) {
  const Eigen::Vector3d minimum(0.3, -1.2, 2.0);
  auto cost = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d d = x - minimum;
    return 1.0 + d[0] * d[0] + 10.0 * d[1] * d[1] + 0.1 * d[2] * d[2] + 0.5 * d[0] * d[1];
  };
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  NelderMeadOptions options;
  options.max_evaluations = 2000;
  options.x_tolerance = 1e-6;
  options.f_tolerance = 1e-12;
  const NelderMeadSummary summary = NelderMeadMinimize<3>(cost, Eigen::Vector3d(0.5, 0.5, 0.5), options, &x);
  EXPECT_EQ(summary.termination, NelderMeadSummary::Termination::kConverged);
  EXPECT_LT((x - minimum).norm(), 1e-4);
  EXPECT_NEAR(summary.final_cost, 1.0, 1e-9);
  EXPECT_LE(summary.final_cost, summary.initial_cost);
}

TEST(NelderMeadTest, RosenbrockValleyIn2d) {
  auto cost = [](const Eigen::Vector2d& x) {
    return 100.0 * std::pow(x[1] - x[0] * x[0], 2) + std::pow(1.0 - x[0], 2);
  };
  Eigen::Vector2d x(-1.2, 1.0);
  NelderMeadOptions options;
  options.max_evaluations = 5000;
  options.x_tolerance = 1e-8;
  options.f_tolerance = 1e-14;
  NelderMeadMinimize<2>(cost, Eigen::Vector2d(0.1, 0.1), options, &x);
  EXPECT_NEAR(x[0], 1.0, 1e-4);
  EXPECT_NEAR(x[1], 1.0, 1e-4);
}

TEST(NelderMeadTest, StopsAtEvaluationBudget) {
  auto cost = [](const Eigen::Vector2d& x) { return x.squaredNorm(); };
  Eigen::Vector2d x(5.0, 5.0);
  NelderMeadOptions options;
  options.max_evaluations = 10;
  options.x_tolerance = 0.0;
  options.f_tolerance = 0.0;
  const NelderMeadSummary summary = NelderMeadMinimize<2>(cost, Eigen::Vector2d(1.0, 1.0), options, &x);
  EXPECT_EQ(summary.termination, NelderMeadSummary::Termination::kMaxEvaluations);
  EXPECT_LE(summary.evaluations, 10 + 3);  // a shrink may finish the last iteration
  EXPECT_LT(x.squaredNorm(), 50.0);
}

}  // namespace
}  // namespace reconar
