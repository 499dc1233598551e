// VerifyTwoView on general, planar, rotation-only and too-small synthetic match sets.
#include <chrono>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "core/geometry/fundamental_eight_point.h"
#include "core/geometry/homography_four_point.h"
#include "core/geometry/two_view.h"
#include "tests/core/geometry/test_util.h"

namespace reconar {
namespace {

using geometry_test::CompareMasks;
using geometry_test::MakeScene;
using geometry_test::MaskQuality;
using Config = TwoViewGeometry::Config;
using Kind = SyntheticSceneOptions::Kind;

SyntheticSceneOptions Matches(Kind kind, int num_points, uint64_t seed) {
  SyntheticSceneOptions options;
  options.kind = kind;
  options.num_points = num_points;
  options.outlier_fraction = 0.5;
  options.noise_sigma = 0.5;
  options.seed = seed;
  return options;
}

Result<TwoViewGeometry> Verify(const SyntheticTwoViewScene& scene, const SyntheticSceneOptions& options,
                               const TwoViewOptions& two_view = TwoViewOptions()) {
  return VerifyTwoView(scene.points_a, scene.points_b, options.width, options.height, options.width, options.height,
                       two_view);
}

std::vector<char> MaskFromIndices(const std::vector<int>& indices, size_t size) {
  std::vector<char> mask(size, 0);
  for (int i : indices) mask[i] = 1;
  return mask;
}

TEST(VerifyTwoView, GeneralSceneIsVerified) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE(seed);
    // Outliers at least 2x the F threshold (6.1 px) from the true geometry, so every reported
    // false inlier is an estimation error rather than a random match lying on its epipolar line.
    SyntheticSceneOptions options = Matches(Kind::kGeneral, 1000, seed);
    options.min_outlier_distance = 12.5;
    const SyntheticTwoViewScene scene = MakeScene(options);
    const Result<TwoViewGeometry> geometry = Verify(scene, options);
    ASSERT_TRUE(geometry.ok()) << geometry.status().ToString();
    EXPECT_EQ(geometry->config, Config::kVerified) << geometry->reason;
    EXPECT_NEAR(geometry->f_threshold_px, 0.006 * 1024, 1e-12);
    EXPECT_NEAR(geometry->h_threshold_px, 0.004 * 1024, 1e-12);
    EXPECT_EQ(geometry->num_f_inliers, static_cast<int>(geometry->inliers.size()));
    EXPECT_LT(geometry->h_to_f_inlier_ratio, 0.8);
    const MaskQuality quality = CompareMasks(MaskFromIndices(geometry->inliers, scene.is_inlier.size()), scene.is_inlier);
    EXPECT_GE(quality.recall, 0.99);
    EXPECT_LT(quality.false_fraction, 0.01);
    // The estimated F explains the noise-free geometry far better than the 0.5 px noise.
    EXPECT_LT(geometry_test::RmsResidual<FundamentalEightPoint>(geometry_test::ExactInlierCorrespondences(scene), geometry->F),
              0.2);
  }
}

TEST(VerifyTwoView, PlanarSceneIsPlanarOrRotation) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE(seed);
    const SyntheticSceneOptions options = Matches(Kind::kPlanar, 1000, seed);
    const SyntheticTwoViewScene scene = MakeScene(options);
    const Result<TwoViewGeometry> geometry = Verify(scene, options);
    ASSERT_TRUE(geometry.ok()) << geometry.status().ToString();
    EXPECT_EQ(geometry->config, Config::kPlanarOrRotation) << geometry->reason;
    EXPECT_GE(geometry->h_to_f_inlier_ratio, 0.8);
    EXPECT_GE(geometry->num_f_inliers, 100);
    EXPECT_LT(geometry_test::RmsResidual<HomographyFourPoint>(geometry_test::ExactInlierCorrespondences(scene), geometry->H), 0.2);
  }
}

TEST(VerifyTwoView, PureRotationIsPlanarOrRotation) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE(seed);
    const SyntheticSceneOptions options = Matches(Kind::kPureRotation, 1000, seed);
    const SyntheticTwoViewScene scene = MakeScene(options);
    const Result<TwoViewGeometry> geometry = Verify(scene, options);
    ASSERT_TRUE(geometry.ok()) << geometry.status().ToString();
    EXPECT_EQ(geometry->config, Config::kPlanarOrRotation) << geometry->reason;
    EXPECT_GE(geometry->h_to_f_inlier_ratio, 0.8);
  }
}

TEST(VerifyTwoView, TooFewMatches) {
  const SyntheticSceneOptions options = Matches(Kind::kGeneral, 60, 3);
  const SyntheticTwoViewScene scene = MakeScene(options);
  const Result<TwoViewGeometry> geometry = Verify(scene, options);
  ASSERT_TRUE(geometry.ok());
  EXPECT_EQ(geometry->config, Config::kTooFewInliers);
  EXPECT_EQ(geometry->reason, "60 putative matches, fewer than the 100 inliers required");
  EXPECT_TRUE(geometry->inliers.empty());
  EXPECT_STREQ(TwoViewConfigName(geometry->config), "too few inliers");
}

TEST(VerifyTwoView, TooFewInliersAmongManyMatches) {
  // 400 matches of which only 60 (15 %) are true: the best F cannot reach 100 inliers.
  SyntheticSceneOptions options = Matches(Kind::kGeneral, 400, 4);
  options.outlier_fraction = 0.85;
  options.min_outlier_distance = 12.5;
  const SyntheticTwoViewScene scene = MakeScene(options);
  const Result<TwoViewGeometry> geometry = Verify(scene, options);
  ASSERT_TRUE(geometry.ok());
  EXPECT_EQ(geometry->config, Config::kTooFewInliers);
  EXPECT_LT(geometry->num_f_inliers, 100);
  EXPECT_NE(geometry->reason.find("F-inliers of 400 putative matches, fewer than the 100 required"), std::string::npos)
      << geometry->reason;
}

TEST(VerifyTwoView, ThresholdsUseTheLargerImage) {
  const SyntheticSceneOptions options = Matches(Kind::kGeneral, 300, 5);
  const SyntheticTwoViewScene scene = MakeScene(options);
  const Result<TwoViewGeometry> geometry =
      VerifyTwoView(scene.points_a, scene.points_b, 1024, 768, 2000, 3000, TwoViewOptions());
  ASSERT_TRUE(geometry.ok());
  EXPECT_NEAR(geometry->f_threshold_px, 18.0, 1e-12);
  EXPECT_NEAR(geometry->h_threshold_px, 12.0, 1e-12);
}

TEST(VerifyTwoView, RejectsInvalidInput) {
  const std::vector<Eigen::Vector2d> a(200), b(199);
  EXPECT_EQ(VerifyTwoView(a, b, 640, 480, 640, 480, TwoViewOptions()).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(VerifyTwoView(a, a, 0, 480, 640, 480, TwoViewOptions()).status().code(), StatusCode::kInvalidArgument);
  TwoViewOptions options;
  options.min_inliers = 7;
  EXPECT_EQ(VerifyTwoView(a, a, 640, 480, 640, 480, options).status().code(), StatusCode::kInvalidArgument);
  options = TwoViewOptions();
  options.ransac.confidence = 2.0;
  const Status status = VerifyTwoView(a, a, 640, 480, 640, 480, options).status();
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("TwoViewOptions.ransac"), std::string::npos) << status.message();
}

TEST(VerifyTwoView, DeterministicAndTimedOn3000Matches) {
  const SyntheticSceneOptions options = Matches(Kind::kGeneral, 3000, 42);
  const SyntheticTwoViewScene scene = MakeScene(options);
  const auto start = std::chrono::steady_clock::now();
  const Result<TwoViewGeometry> first = Verify(scene, options);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const Result<TwoViewGeometry> second = Verify(scene, options);
  ASSERT_TRUE(first.ok() && second.ok());
  EXPECT_EQ(first->config, Config::kVerified) << first->reason;
  EXPECT_EQ(first->inliers, second->inliers);
  EXPECT_EQ(first->F, second->F);
  std::printf("VerifyTwoView: 3000 matches, 50%% outliers: %.1f ms (%d F-iterations, %d H-iterations, %s)\n", ms,
              first->f_iterations, first->h_iterations, first->reason.c_str());
}

}  // namespace
}  // namespace reconar
