// Minimal and least-squares behaviour of the two-view estimators on exact synthetic data.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/geometry/essential_five_point.h"
#include "core/geometry/fundamental_eight_point.h"
#include "core/geometry/fundamental_seven_point.h"
#include "core/geometry/homography_four_point.h"
#include "core/geometry/polynomial.h"
#include "core/geometry/residuals.h"
#include "tests/core/geometry/test_util.h"

namespace reconar {
namespace {

using geometry_test::FirstInliers;
using geometry_test::MakeScene;
using geometry_test::ProjectiveDistance;

constexpr int kNumSeeds = 25;

SyntheticSceneOptions ExactScene(uint64_t seed, SyntheticSceneOptions::Kind kind = SyntheticSceneOptions::Kind::kGeneral) {
  SyntheticSceneOptions options;
  options.kind = kind;
  options.num_points = 100;
  options.seed = seed;
  return options;
}

template <typename Estimator>
double MaxResidual(const std::vector<Correspondence>& samples, const Eigen::Matrix3d& model) {
  std::vector<double> residuals(samples.size());
  Estimator::Residuals(samples.data(), static_cast<int>(samples.size()), model, residuals.data());
  double worst = 0.0;
  for (double r : residuals) worst = std::max(worst, r);
  return worst;
}

TEST(FundamentalEightPoint, RecoversTrueModelFromMinimalSample) {
  for (uint64_t seed = 1; seed <= kNumSeeds; ++seed) {
    const SyntheticTwoViewScene scene = MakeScene(ExactScene(seed));
    const std::vector<Correspondence> all = scene.Correspondences();
    const std::vector<Correspondence> sample = FirstInliers(scene, FundamentalEightPoint::kMinSamples);
    std::array<Eigen::Matrix3d, 1> models;
    ASSERT_EQ(FundamentalEightPoint::Estimate(sample.data(), 8, &models), 1) << "seed " << seed;
    EXPECT_LT(ProjectiveDistance(models[0], scene.F), 1e-7) << "seed " << seed;
    EXPECT_LT(MaxResidual<FundamentalEightPoint>(all, models[0]), 1e-12) << "seed " << seed;
    EXPECT_NEAR(models[0].norm(), 1.0, 1e-12);
    EXPECT_LT(std::abs(models[0].determinant()), 1e-12);
  }
}

TEST(FundamentalEightPoint, LeastSquaresFitsNoisyPoints) {
  SyntheticSceneOptions options = ExactScene(7);
  options.num_points = 300;
  options.noise_sigma = 0.5;
  const SyntheticTwoViewScene scene = MakeScene(options);
  const std::vector<Correspondence> all = scene.Correspondences();
  std::array<Eigen::Matrix3d, 1> models;
  ASSERT_EQ(FundamentalEightPoint::Estimate(all.data(), static_cast<int>(all.size()), &models), 1);
  std::vector<double> residuals(all.size());
  FundamentalEightPoint::Residuals(all.data(), static_cast<int>(all.size()), models[0], residuals.data());
  double mean = 0.0;
  for (double r : residuals) mean += r / residuals.size();
  // The squared Sampson distance of noisy points is ~ sigma^2 chi^2_1: mean ~ 0.25 px^2.
  EXPECT_LT(mean, 0.4);
  EXPECT_LT(std::abs(models[0].determinant()), 1e-12);
}

TEST(FundamentalEightPoint, RejectsCoincidentPoints) {
  std::vector<Correspondence> sample(8, Correspondence{Eigen::Vector2d(10, 20), Eigen::Vector2d(30, 40)});
  std::array<Eigen::Matrix3d, 1> models;
  EXPECT_EQ(FundamentalEightPoint::Estimate(sample.data(), 8, &models), 0);
  EXPECT_EQ(FundamentalEightPoint::Estimate(sample.data(), 7, &models), 0);
}

TEST(FundamentalSevenPoint, OneModelIsTheTrueModel) {
  for (uint64_t seed = 1; seed <= kNumSeeds; ++seed) {
    const SyntheticTwoViewScene scene = MakeScene(ExactScene(seed));
    const std::vector<Correspondence> all = scene.Correspondences();
    const std::vector<Correspondence> sample = FirstInliers(scene, FundamentalSevenPoint::kMinSamples);
    std::array<Eigen::Matrix3d, 3> models;
    const int n = FundamentalSevenPoint::Estimate(sample.data(), 7, &models);
    ASSERT_GE(n, 1) << "seed " << seed;
    double best = 1e9;
    int best_index = 0;
    for (int i = 0; i < n; ++i) {
      // Every candidate is rank 2 and satisfies the seven constraints.
      EXPECT_LT(std::abs(models[i].determinant()), 1e-10) << "seed " << seed;
      EXPECT_LT(MaxResidual<FundamentalSevenPoint>(sample, models[i]), 1e-10) << "seed " << seed;
      const double distance = ProjectiveDistance(models[i], scene.F);
      if (distance < best) {
        best = distance;
        best_index = i;
      }
    }
    EXPECT_LT(best, 1e-7) << "seed " << seed;
    EXPECT_LT(MaxResidual<FundamentalSevenPoint>(all, models[best_index]), 1e-10) << "seed " << seed;
  }
}

TEST(EssentialFivePoint, OneModelIsTheTrueModel) {
  int found = 0;
  for (uint64_t seed = 1; seed <= 4 * kNumSeeds; ++seed) {
    const SyntheticTwoViewScene scene = MakeScene(ExactScene(seed));
    const std::vector<Correspondence> all = scene.Correspondences(/*normalised=*/true);
    const std::vector<Correspondence> sample = FirstInliers(scene, EssentialFivePoint::kMinSamples, true);
    std::array<Eigen::Matrix3d, 10> models;
    const int n = EssentialFivePoint::Estimate(sample.data(), 5, &models);
    ASSERT_GE(n, 1) << "seed " << seed;
    ASSERT_LE(n, 10);
    double best = 1e9;
    int best_index = 0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Matrix3d& E = models[i];
      // Every solution is an essential matrix: det E = 0 and 2 E E^T E - tr(E E^T) E = 0.
      EXPECT_LT(std::abs(E.determinant()), 1e-8) << "seed " << seed;
      EXPECT_LT((2.0 * E * E.transpose() * E - (E * E.transpose()).trace() * E).norm(), 1e-7) << "seed " << seed;
      EXPECT_LT(MaxResidual<EssentialFivePoint>(sample, E), 1e-14) << "seed " << seed;
      const double distance = ProjectiveDistance(E, scene.E);
      if (distance < best) {
        best = distance;
        best_index = i;
      }
    }
    if (best < 1e-6 && MaxResidual<EssentialFivePoint>(all, models[best_index]) < 1e-14) ++found;
  }
  EXPECT_EQ(found, 4 * kNumSeeds);
}

TEST(EssentialFivePoint, LeastSquaresWithMoreSamples) {
  const SyntheticTwoViewScene scene = MakeScene(ExactScene(3));
  const std::vector<Correspondence> sample = FirstInliers(scene, 12, true);
  std::array<Eigen::Matrix3d, 10> models;
  const int n = EssentialFivePoint::Estimate(sample.data(), 12, &models);
  ASSERT_GE(n, 1);
  double best = 1e9;
  for (int i = 0; i < n; ++i) best = std::min(best, ProjectiveDistance(models[i], scene.E));
  EXPECT_LT(best, 1e-6);
}

TEST(HomographyFourPoint, RecoversPlanarAndRotationHomographies) {
  for (auto kind : {SyntheticSceneOptions::Kind::kPlanar, SyntheticSceneOptions::Kind::kPureRotation}) {
    for (uint64_t seed = 1; seed <= kNumSeeds; ++seed) {
      const SyntheticTwoViewScene scene = MakeScene(ExactScene(seed, kind));
      const std::vector<Correspondence> all = scene.Correspondences();
      const std::vector<Correspondence> sample = FirstInliers(scene, HomographyFourPoint::kMinSamples);
      std::array<Eigen::Matrix3d, 1> models;
      ASSERT_EQ(HomographyFourPoint::Estimate(sample.data(), 4, &models), 1) << "seed " << seed;
      EXPECT_LT(ProjectiveDistance(models[0], scene.H), 1e-8) << "seed " << seed;
      EXPECT_LT(MaxResidual<HomographyFourPoint>(all, models[0]), 1e-12) << "seed " << seed;
      // Least squares on all points gives the same homography.
      ASSERT_EQ(HomographyFourPoint::Estimate(all.data(), static_cast<int>(all.size()), &models), 1);
      EXPECT_LT(ProjectiveDistance(models[0], scene.H), 1e-8) << "seed " << seed;
    }
  }
}

TEST(Residuals, SampsonAndTransferErrorsMatchGeometry) {
  // F of a pure horizontal translation: epipolar lines are rows, so the Sampson distance of a
  // vertical offset d split over both images is d^2 / 2.
  Eigen::Matrix3d F;
  F << 0, 0, 0, 0, 0, -1, 0, 1, 0;
  EXPECT_NEAR(SquaredSampsonError(F, Eigen::Vector2d(5, 10), Eigen::Vector2d(40, 12)), 2.0, 1e-12);
  EXPECT_NEAR(SquaredSampsonError(F, Eigen::Vector2d(5, 10), Eigen::Vector2d(-3, 10)), 0.0, 1e-12);
  const Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  EXPECT_NEAR(SquaredTransferError(H, Eigen::Vector2d(1, 1), Eigen::Vector2d(4, 5)), 25.0, 1e-12);
  Eigen::Matrix3d H_infinity = Eigen::Matrix3d::Identity();
  H_infinity(2, 2) = 0.0;
  EXPECT_GT(SquaredTransferError(H_infinity, Eigen::Vector2d(0, 0), Eigen::Vector2d(0, 0)), 1e300);
}

TEST(Polynomial, CubicRoots) {
  double roots[3];
  // (x - 1)(x - 2)(x + 3) = x^3 - 7x + 6
  ASSERT_EQ(SolveCubicReal(1, 0, -7, 6, roots), 3);
  std::sort(roots, roots + 3);
  EXPECT_NEAR(roots[0], -3.0, 1e-12);
  EXPECT_NEAR(roots[1], 1.0, 1e-12);
  EXPECT_NEAR(roots[2], 2.0, 1e-12);
  // x^3 + x + 1 has one real root near -0.6823278.
  ASSERT_EQ(SolveCubicReal(2, 0, 2, 2, roots), 1);
  EXPECT_NEAR(roots[0], -0.6823278038280193, 1e-12);
  // Degenerates to the quadratic 2x^2 - 8 = 0.
  ASSERT_EQ(SolveCubicReal(0, 2, 0, -8, roots), 2);
  EXPECT_NEAR(std::abs(roots[0]), 2.0, 1e-12);
  EXPECT_NEAR(roots[0] + roots[1], 0.0, 1e-12);
  EXPECT_EQ(SolveCubicReal(0, 0, 0, 0, roots), 0);
  double quadratic[2];
  EXPECT_EQ(SolveQuadraticReal(1, 0, 1, quadratic), 0);
}

}  // namespace
}  // namespace reconar
