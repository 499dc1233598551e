// The synthetic scene generator: determinism and consistency of the ground truth it reports.
#include <cmath>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/geometry/residuals.h"
#include "core/geometry/synthetic_scene.h"
#include "tests/core/geometry/test_util.h"

namespace reconar {
namespace {

using geometry_test::MakeScene;
using Kind = SyntheticSceneOptions::Kind;

TEST(SyntheticScene, SameSeedSameScene) {
  SyntheticSceneOptions options;
  options.outlier_fraction = 0.3;
  options.noise_sigma = 1.0;
  const SyntheticTwoViewScene a = MakeScene(options);
  const SyntheticTwoViewScene b = MakeScene(options);
  EXPECT_EQ(a.points_a, b.points_a);
  EXPECT_EQ(a.points_b, b.points_b);
  EXPECT_EQ(a.is_inlier, b.is_inlier);
  options.seed = 2;
  EXPECT_NE(MakeScene(options).points_a, a.points_a);
}

TEST(SyntheticScene, GroundTruthIsConsistent) {
  for (Kind kind : {Kind::kGeneral, Kind::kPlanar, Kind::kPureRotation}) {
    SyntheticSceneOptions options;
    options.kind = kind;
    options.num_points = 400;
    options.outlier_fraction = 0.25;
    options.min_outlier_distance = 10.0;
    const SyntheticTwoViewScene scene = MakeScene(options);
    EXPECT_EQ(scene.num_inliers(), 300);
    EXPECT_NEAR(scene.R.determinant(), 1.0, 1e-12);
    for (size_t i = 0; i < scene.points_a.size(); ++i) {
      const Eigen::Vector2d& a = scene.points_a[i];
      const Eigen::Vector2d& b = scene.points_b[i];
      EXPECT_TRUE(a.x() >= 0 && a.x() < options.width && a.y() >= 0 && a.y() < options.height);
      if (kind == Kind::kGeneral) {
        const double sampson = SquaredSampsonError(scene.F, a, b);
        if (scene.is_inlier[i]) {
          EXPECT_LT(sampson, 1e-16);
          // The relative pose maps the point from camera a to camera b.
          const Eigen::Vector3d X = scene.points3d[i];
          EXPECT_LT((scene.R * (scene.R_a * X + scene.t_a) + scene.t - (scene.R_b * X + scene.t_b)).norm(), 1e-12);
        } else {
          EXPECT_GE(sampson, 100.0);
        }
      } else {
        const double transfer = SquaredTransferError(scene.H, a, b);
        EXPECT_TRUE(scene.is_inlier[i] ? transfer < 1e-16 : transfer >= 100.0) << transfer;
      }
    }
    if (kind == Kind::kPureRotation) {
      EXPECT_LT(scene.t.norm(), 1e-12);
    } else {
      EXPECT_NEAR(geometry_test::ProjectiveDistance(scene.E, CrossProductMatrix(scene.t) * scene.R), 0.0, 1e-12);
    }
  }
}

TEST(SyntheticScene, RejectsInvalidOptions) {
  SyntheticSceneOptions options;
  options.outlier_fraction = 1.0;
  EXPECT_EQ(MakeSyntheticTwoViewScene(options).status().code(), StatusCode::kInvalidArgument);
  options = SyntheticSceneOptions();
  options.num_points = 0;
  EXPECT_EQ(MakeSyntheticTwoViewScene(options).status().code(), StatusCode::kInvalidArgument);
  options = SyntheticSceneOptions();
  options.noise_sigma = -1.0;
  EXPECT_EQ(MakeSyntheticTwoViewScene(options).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace reconar
