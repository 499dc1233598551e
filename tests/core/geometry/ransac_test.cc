// The RANSAC template on synthetic scenes with outliers: accuracy, determinism, edge cases.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "core/geometry/essential_five_point.h"
#include "core/geometry/fundamental_eight_point.h"
#include "core/geometry/fundamental_seven_point.h"
#include "core/geometry/homography_four_point.h"
#include "core/geometry/ransac.h"
#include "tests/core/geometry/test_util.h"

namespace reconar {
namespace {

using geometry_test::CompareMasks;
using geometry_test::MakeScene;
using geometry_test::MaskQuality;
using geometry_test::ExactInlierCorrespondences;
using geometry_test::RmsResidual;

// 1000 matches, half of them outliers, 0.5 px noise. Outliers are at least 4 px (twice the
// threshold below) from the true geometry: a uniformly random match that happens to lie on its
// epipolar line (~1 % of them at 2 px) is geometrically an inlier and no estimator could reject it.
SyntheticSceneOptions NoisyScene(uint64_t seed, SyntheticSceneOptions::Kind kind = SyntheticSceneOptions::Kind::kGeneral) {
  SyntheticSceneOptions options;
  options.kind = kind;
  options.num_points = 1000;
  options.outlier_fraction = 0.5;
  options.noise_sigma = 0.5;
  options.min_outlier_distance = 4.0;
  options.seed = seed;
  return options;
}

// 4 sigma: the squared Sampson / transfer residuals of inliers are ~ sigma^2 chi^2 distributed.
RansacOptions TwoPixelOptions() {
  RansacOptions options;
  options.max_residual = 2.0;
  return options;
}

// Finds >= 95 % of the true inliers with < 1 % false ones, and a model whose RMS residual on the
// noise-free inliers is below max_rms (a fraction of the 0.5 px noise; MSAC picks among models of
// near-equal cost, so this is looser than the least-squares fit on the true inliers, ~0.06 px).
template <typename Estimator, typename Local = Estimator>
void ExpectFindsInliers(const SyntheticTwoViewScene& scene, bool normalised, const RansacOptions& options,
                        double max_rms) {
  const std::vector<Correspondence> samples = scene.Correspondences(normalised);
  Result<RansacReport<Eigen::Matrix3d>> report = Ransac<Estimator, Local>::Run(samples, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_EQ(report->status, RansacStatus::kSuccess);
  const MaskQuality quality = CompareMasks(report->inlier_mask, scene.is_inlier);
  EXPECT_GE(quality.recall, 0.95);
  EXPECT_LT(quality.false_fraction, 0.01);
  EXPECT_LT(RmsResidual<Estimator>(ExactInlierCorrespondences(scene, normalised), report->model), max_rms);
  EXPECT_EQ(report->num_inliers,
            static_cast<int>(std::count(report->inlier_mask.begin(), report->inlier_mask.end(), 1)));
  EXPECT_GT(report->iterations, 0);
  EXPECT_LE(report->iterations, options.max_iterations);
}

TEST(Ransac, FundamentalEightPointWithHalfOutliers) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE(seed);
    const SyntheticTwoViewScene scene = MakeScene(NoisyScene(seed));
    ExpectFindsInliers<FundamentalEightPoint>(scene, false, TwoPixelOptions(), 0.3);
  }
}

TEST(Ransac, FundamentalSevenPointWithEightPointLocalOptimisation) {
  const SyntheticTwoViewScene scene = MakeScene(NoisyScene(11));
  ExpectFindsInliers<FundamentalSevenPoint, FundamentalEightPoint>(scene, false, TwoPixelOptions(), 0.3);
}

TEST(Ransac, EssentialFivePointWithHalfOutliers) {
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE(seed);
    SyntheticSceneOptions scene_options = NoisyScene(seed);
    const SyntheticTwoViewScene scene = MakeScene(scene_options);
    RansacOptions options;
    options.max_residual = 2.0 / scene_options.focal;  // normalised coordinates
    ExpectFindsInliers<EssentialFivePoint>(scene, /*normalised=*/true, options, 0.3 / scene_options.focal);
  }
}

TEST(Ransac, HomographyWithHalfOutliers) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE(seed);
    const SyntheticTwoViewScene scene = MakeScene(NoisyScene(seed, SyntheticSceneOptions::Kind::kPlanar));
    ExpectFindsInliers<HomographyFourPoint>(scene, false, TwoPixelOptions(), 0.3);
  }
}

TEST(Ransac, SameSeedGivesIdenticalResults) {
  const SyntheticTwoViewScene scene = MakeScene(NoisyScene(21));
  const std::vector<Correspondence> samples = scene.Correspondences();
  RansacOptions options = TwoPixelOptions();
  options.seed = 1234;
  const auto first = Ransac<FundamentalEightPoint>::Run(samples, options);
  const auto second = Ransac<FundamentalEightPoint>::Run(samples, options);
  ASSERT_TRUE(first.ok() && second.ok());
  EXPECT_EQ(first->inlier_mask, second->inlier_mask);
  EXPECT_EQ(first->iterations, second->iterations);
  EXPECT_EQ(first->model, second->model);  // bit-identical
  options.seed = 5678;
  const auto other = Ransac<FundamentalEightPoint>::Run(samples, options);
  ASSERT_TRUE(other.ok());
  EXPECT_EQ(other->status, RansacStatus::kSuccess);
}

TEST(Ransac, LocalOptimisationRunsAndDoesNotHurt) {
  const SyntheticTwoViewScene scene = MakeScene(NoisyScene(31));
  const std::vector<Correspondence> samples = scene.Correspondences();
  RansacOptions options = TwoPixelOptions();
  const auto with_lo = Ransac<FundamentalEightPoint>::Run(samples, options);
  options.local_optimisation = false;
  const auto without_lo = Ransac<FundamentalEightPoint>::Run(samples, options);
  ASSERT_TRUE(with_lo.ok() && without_lo.ok());
  EXPECT_GT(with_lo->local_optimisations, 0);
  EXPECT_EQ(without_lo->local_optimisations, 0);
  EXPECT_LE(with_lo->cost, without_lo->cost * 1.02);
  // LO's least-squares models reach the all-inlier cost faster, so fewer iterations are needed.
  EXPECT_LE(with_lo->iterations, without_lo->iterations);
}

TEST(Ransac, TooFewSamples) {
  const SyntheticTwoViewScene scene = MakeScene(NoisyScene(1));
  std::vector<Correspondence> samples = scene.Correspondences();
  samples.resize(7);
  const auto report = Ransac<FundamentalEightPoint>::Run(samples, RansacOptions());
  ASSERT_TRUE(report.ok());
  EXPECT_EQ(report->status, RansacStatus::kTooFewSamples);
  EXPECT_EQ(report->iterations, 0);
  EXPECT_TRUE(report->inlier_mask.empty());
}

TEST(Ransac, AllSamplesDegenerateGivesNoModel) {
  const std::vector<Correspondence> samples(50, Correspondence{Eigen::Vector2d(3, 4), Eigen::Vector2d(5, 6)});
  RansacOptions options;
  options.max_iterations = 200;
  const auto report = Ransac<FundamentalEightPoint>::Run(samples, options);
  ASSERT_TRUE(report.ok());
  EXPECT_EQ(report->status, RansacStatus::kNoModel);
  EXPECT_EQ(report->iterations, 200);
  EXPECT_STREQ(RansacStatusName(report->status), "no model");
}

TEST(Ransac, RejectsInvalidOptions) {
  const std::vector<Correspondence> samples(10);
  RansacOptions options;
  options.max_residual = 0.0;
  EXPECT_EQ(Ransac<HomographyFourPoint>::Run(samples, options).status().code(), StatusCode::kInvalidArgument);
  options = RansacOptions();
  options.confidence = 1.0;
  EXPECT_EQ(Ransac<HomographyFourPoint>::Run(samples, options).status().code(), StatusCode::kInvalidArgument);
  options = RansacOptions();
  options.min_iterations = options.max_iterations + 1;
  EXPECT_EQ(Ransac<HomographyFourPoint>::Run(samples, options).status().code(), StatusCode::kInvalidArgument);
  options = RansacOptions();
  options.local_inner_samples = -1;
  EXPECT_EQ(Ransac<HomographyFourPoint>::Run(samples, options).status().code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(RansacOptions().Check().ok());
}

TEST(Ransac, RequiredIterationsFollowsTheFormula) {
  using ransac_internal::RequiredIterations;
  // w = 0.5, s = 8, p = 0.999: log(0.001) / log(1 - 1/256) = 1765.0...
  EXPECT_EQ(RequiredIterations(500, 1000, 8, 0.999, 100000), 1765);
  EXPECT_EQ(RequiredIterations(1000, 1000, 8, 0.999, 100000), 0);
  EXPECT_EQ(RequiredIterations(0, 1000, 8, 0.999, 1234), 1234);
  EXPECT_EQ(RequiredIterations(1, 100000, 8, 0.999, 1234), 1234);  // w^s underflows the budget
}

}  // namespace
}  // namespace reconar
