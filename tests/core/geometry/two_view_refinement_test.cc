// The final refit of F must be robust: gross errors that happen to fall just under the inlier
// threshold must not pull F towards them (a plain least-squares refit does; seen on aarch64).
#include <gtest/gtest.h>

#include "core/geometry/fundamental_eight_point.h"
#include "core/geometry/two_view.h"
#include "test_util.h"

namespace reconar {
namespace {

TEST(TwoViewRefinement, NearThresholdGrossErrorsDoNotPullF) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    SCOPED_TRACE(seed);
    SyntheticSceneOptions options;
    options.num_points = 400;
    options.noise_sigma = 0.5;
    options.seed = seed;
    SyntheticTwoViewScene scene = geometry_test::MakeScene(options);
    const std::vector<Correspondence> exact = geometry_test::ExactInlierCorrespondences(scene);
    const double threshold = TwoViewOptions().f_threshold_fraction * std::max(options.width, options.height);
    // Move 5 % of the points in image b across their true epipolar line by 0.9 of the threshold:
    // about 11 noise sigmas, yet still inliers to any F close to the truth.
    for (int i = 0; i < options.num_points; i += 20) {
      const Eigen::Vector3d line = scene.F * scene.points_a[i].homogeneous();
      const Eigen::Vector2d normal = line.head<2>().normalized();
      scene.points_b[i] += 0.9 * threshold * normal;
    }
    auto geometry = VerifyTwoView(scene.points_a, scene.points_b, options.width, options.height, options.width,
                                  options.height, TwoViewOptions());
    ASSERT_TRUE(geometry.ok());
    ASSERT_EQ(geometry->config, TwoViewGeometry::Config::kVerified) << geometry->reason;
    const double rms = geometry_test::RmsResidual<FundamentalEightPoint>(exact, geometry->F);
    // The noise-free points fit the estimate far better than the 0.5 px noise.
    EXPECT_LT(rms, 0.2);
  }
}

}  // namespace
}  // namespace reconar
