// AdjustmentCovariance against Monte Carlo: the same synthetic scene adjusted from observations
// with fresh noise again and again; the spread of a function the similarity does not change (a
// ratio of distances between points) must be what the covariance of one adjustment predicts.
#include "core/optim/adjustment_covariance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "tests/core/optim/synthetic_bal.h"

namespace reconar {
namespace {

struct Ratio {
  double value = 0.0;
  std::vector<PointGradient> gradients;
};

// |P0 - P1| / |P2 - P3| and its gradient.
Ratio DistanceRatio(const RadialProblem& problem) {
  const auto point = [&](int j) { return Eigen::Map<const Eigen::Vector3d>(problem.point(j)); };
  const Eigen::Vector3d a = point(0) - point(1), b = point(2) - point(3);
  Ratio ratio;
  ratio.value = a.norm() / b.norm();
  const Eigen::Vector3d da = a / (a.norm() * b.norm());
  const Eigen::Vector3d db = -ratio.value * b / b.squaredNorm();
  ratio.gradients = {{0, da}, {1, -da}, {2, db}, {3, -db}};
  return ratio;
}

TEST(AdjustmentCovarianceTest, PredictsTheSpreadOfARatioOfDistancesOverNoiseDraws) {
  const std::vector<int> groups(8, 0);
  const RadialProblem truth = testing::MakeSyntheticRadial(groups, 80, 0.0, 3);
  BundleAdjustmentConstancy constancy;
  constancy.intrinsics_group = groups;
  constancy.constant_camera_parameters = {9, 10, 11};  // principal point and aspect held, f, k1, k2 free
  BundleAdjustmentOptions options;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  constexpr double kNoisePx = 0.5;
  constexpr int kTrials = 100;
  std::mt19937 random(11);
  std::normal_distribution<double> noise(0.0, kNoisePx);
  std::vector<double> ratios;
  double predicted_sigma = 0.0, variance_factor = 0.0;
  for (int trial = 0; trial < kTrials; ++trial) {
    RadialProblem problem = truth;
    for (BalObservation& o : problem.observations) {
      o.x += noise(random);
      o.y += noise(random);
    }
    auto summary = SolveBundleAdjustment(options, constancy, &problem);
    ASSERT_TRUE(summary.ok()) << summary.status().ToString();
    const Ratio ratio = DistanceRatio(problem);
    ratios.push_back(ratio.value);
    if (trial < 10) {  // the prediction of a few single adjustments, averaged
      auto covariance = AdjustmentCovariance::Compute(problem, constancy);
      ASSERT_TRUE(covariance.ok()) << covariance.status().ToString();
      predicted_sigma += std::sqrt(covariance->Variance(ratio.gradients)) / 10;
      variance_factor += covariance->variance_factor() / 10;
    }
  }
  double mean = 0.0, squares = 0.0;
  for (double r : ratios) mean += r / kTrials;
  for (double r : ratios) squares += (r - mean) * (r - mean);
  const double measured_sigma = std::sqrt(squares / (kTrials - 1));
  std::printf("ratio %.6f (truth %.6f): spread over %d noise draws %.3g, predicted %.3g (%.2fx); sigma0 %.3f px "
              "(noise %.2f)\n", mean, DistanceRatio(truth).value, kTrials, measured_sigma, predicted_sigma,
              predicted_sigma / measured_sigma, std::sqrt(variance_factor), kNoisePx);
  // The sample spread of 100 draws is within about 15 % of the true one (2 standard errors).
  EXPECT_GT(predicted_sigma, 0.8 * measured_sigma);
  EXPECT_LT(predicted_sigma, 1.25 * measured_sigma);
  EXPECT_NEAR(std::sqrt(variance_factor), kNoisePx, 0.1 * kNoisePx);
  EXPECT_LT(std::abs(mean - DistanceRatio(truth).value), 3 * measured_sigma / std::sqrt(kTrials) + 1e-12);
}

TEST(AdjustmentCovarianceTest, AConstantPointAddsNothingAndAMismatchedConstancyIsRefused) {
  const std::vector<int> groups(6, 0);
  RadialProblem problem = testing::MakeSyntheticRadial(groups, 40, 0.3, 5);
  BundleAdjustmentConstancy constancy;
  constancy.intrinsics_group = groups;
  constancy.constant_points.assign(40, 0);
  constancy.constant_points[0] = 1;
  auto covariance = AdjustmentCovariance::Compute(problem, constancy);
  ASSERT_TRUE(covariance.ok()) << covariance.status().ToString();
  EXPECT_EQ(covariance->Variance({{0, Eigen::Vector3d(1, 0, 0)}}), 0.0);
  EXPECT_GT(covariance->Variance({{1, Eigen::Vector3d(1, 0, 0)}}), 0.0);
  constancy.intrinsics_group.pop_back();
  EXPECT_EQ(AdjustmentCovariance::Compute(problem, constancy).status().code(), StatusCode::kInvalidArgument);
}

// A point added after the fact (a pick in the photos) has the variance it would have had in the
// adjustment, up to what its own observations would have told about the cameras.
TEST(AdjustmentCovarianceTest, AnAddedPointHasTheVarianceItWouldHaveHadInTheAdjustment) {
  const std::vector<int> groups(8, 0);
  RadialProblem problem = testing::MakeSyntheticRadial(groups, 80, 0.0, 3);
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0.0, 0.5);
  for (BalObservation& o : problem.observations) {
    o.x += noise(random);
    o.y += noise(random);
  }
  BundleAdjustmentConstancy constancy;
  constancy.intrinsics_group = groups;
  constancy.constant_camera_parameters = {9, 10, 11};
  ASSERT_TRUE(SolveBundleAdjustment(BundleAdjustmentOptions(), constancy, &problem).ok());
  auto with_all = AdjustmentCovariance::Compute(problem, constancy);
  ASSERT_TRUE(with_all.ok()) << with_all.status().ToString();

  // The same problem without point 0; then point 0 added with its observations.
  RadialProblem without = problem;
  without.points.erase(without.points.begin(), without.points.begin() + 3);
  without.observations.clear();
  std::vector<BalObservation> of_point_0;
  for (BalObservation o : problem.observations) {
    if (o.point == 0) {
      of_point_0.push_back(o);
      continue;
    }
    --o.point;
    without.observations.push_back(o);
  }
  ASSERT_GE(of_point_0.size(), 2u);
  auto with_added = AdjustmentCovariance::Compute(without, constancy);
  ASSERT_TRUE(with_added.ok()) << with_added.status().ToString();
  auto added = with_added->AddPoint(Eigen::Map<const Eigen::Vector3d>(problem.point(0)), of_point_0);
  ASSERT_TRUE(added.ok()) << added.status().ToString();
  EXPECT_EQ(*added, without.num_points());

  // |P0 - P1| / |P2 - P3| in both numberings.
  const auto point = [&](int j) { return Eigen::Map<const Eigen::Vector3d>(problem.point(j)); };
  const Eigen::Vector3d a = point(0) - point(1), b = point(2) - point(3);
  const double ratio = a.norm() / b.norm();
  const Eigen::Vector3d da = a / (a.norm() * b.norm()), db = -ratio * b / b.squaredNorm();
  const double variance_all = with_all->Variance({{0, da}, {1, -da}, {2, db}, {3, -db}});
  const double variance_added = with_added->Variance({{*added, da}, {0, -da}, {1, db}, {2, -db}});
  std::printf("sigma with the point adjusted %.4g, added afterwards %.4g\n", std::sqrt(variance_all),
              std::sqrt(variance_added));
  EXPECT_GT(variance_all, 0.0);
  EXPECT_NEAR(std::sqrt(variance_added), std::sqrt(variance_all), 0.05 * std::sqrt(variance_all));

  // An observation of a camera the problem does not have is refused; one view does not fix a point.
  std::vector<BalObservation> bad = of_point_0;
  bad[0].camera = 99;
  EXPECT_EQ(with_added->AddPoint(point(0), bad).status().code(), StatusCode::kInvalidArgument);
  auto once = with_added->AddPoint(point(0), {of_point_0[0]});
  ASSERT_TRUE(once.ok());
  EXPECT_TRUE(std::isinf(with_added->Variance({{*once, Eigen::Vector3d(1, 0, 0)}})));
}

}  // namespace
}  // namespace reconar
