// Linear triangulation, triangulation angles and relative pose from an essential matrix.
#include <cmath>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/geometry/essential_five_point.h"
#include "core/geometry/ransac.h"
#include "core/geometry/relative_pose.h"
#include "core/geometry/triangulation.h"
#include "tests/core/geometry/test_util.h"

namespace reconar {
namespace {

using geometry_test::MakeScene;

constexpr double kPi = 3.14159265358979323846;

Matrix34d Projection(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Matrix34d P;
  P << R, t;
  return K * P;
}

double RotationAngle(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  return Eigen::AngleAxisd(A.transpose() * B).angle();
}

TEST(Triangulation, RecoversExactPoints) {
  SyntheticSceneOptions options;
  options.num_points = 200;
  const SyntheticTwoViewScene scene = MakeScene(options);
  const Matrix34d P1 = Projection(scene.K, scene.R_a, scene.t_a);
  const Matrix34d P2 = Projection(scene.K, scene.R_b, scene.t_b);
  for (size_t i = 0; i < scene.points3d.size(); ++i) {
    Eigen::Vector3d X;
    ASSERT_TRUE(TriangulatePoint(P1, P2, scene.points_a[i], scene.points_b[i], &X));
    EXPECT_LT((X - scene.points3d[i]).norm(), 1e-9);
    EXPECT_GT(PointDepth(P1, X), 0.0);
    EXPECT_GT(PointDepth(P2, X), 0.0);
  }
}

TEST(Triangulation, NoisyPointsStayClose) {
  SyntheticSceneOptions options;
  options.num_points = 200;
  options.noise_sigma = 0.5;
  const SyntheticTwoViewScene scene = MakeScene(options);
  const Matrix34d P1 = Projection(scene.K, scene.R_a, scene.t_a);
  const Matrix34d P2 = Projection(scene.K, scene.R_b, scene.t_b);
  double sum = 0.0;
  for (size_t i = 0; i < scene.points3d.size(); ++i) {
    Eigen::Vector3d X;
    ASSERT_TRUE(TriangulatePoint(P1, P2, scene.points_a[i], scene.points_b[i], &X));
    sum += (X - scene.points3d[i]).norm();
  }
  EXPECT_LT(sum / scene.points3d.size(), 0.02);  // scene radius 1, distance 5
}

TEST(Triangulation, ParallelRaysAreRejected) {
  Matrix34d P1 = Matrix34d::Zero(), P2 = Matrix34d::Zero();
  P1.leftCols<3>().setIdentity();
  P2.leftCols<3>().setIdentity();
  P2(0, 3) = -1.0;  // camera 2 one unit to the right, same orientation
  Eigen::Vector3d X(7, 7, 7);
  EXPECT_FALSE(TriangulatePoint(P1, P2, Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(0.1, 0.2), &X));
  EXPECT_EQ(X, Eigen::Vector3d(7, 7, 7));
}

TEST(Triangulation, Angle) {
  const Eigen::Vector3d c1(-1, 0, 0), c2(1, 0, 0);
  EXPECT_NEAR(TriangulationAngle(c1, c2, Eigen::Vector3d(0, 0, 1)), kPi / 2, 1e-15);
  EXPECT_NEAR(TriangulationAngle(c1, c2, Eigen::Vector3d(0, 0, 1000)), 2.0 * std::atan(1e-3), 1e-15);
  EXPECT_EQ(TriangulationAngle(c1, c2, c1), 0.0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.5, -1, 2);
  EXPECT_LT((R * ProjectionCenter(R, t) + t).norm(), 1e-15);
}

TEST(RelativePose, DecomposesTheTrueEssentialMatrix) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE(seed);
    SyntheticSceneOptions options;
    options.num_points = 100;
    options.seed = seed;
    const SyntheticTwoViewScene scene = MakeScene(options);
    const std::vector<Correspondence> normalised = scene.Correspondences(true);
    std::array<Eigen::Matrix3d, 2> rotations;
    Eigen::Vector3d u3;
    DecomposeEssential(scene.E, &rotations, &u3);
    EXPECT_NEAR(rotations[0].determinant(), 1.0, 1e-12);
    EXPECT_NEAR(rotations[1].determinant(), 1.0, 1e-12);
    const Result<RelativePose> pose =
        RelativePoseFromEssential(scene.E, normalised.data(), static_cast<int>(normalised.size()));
    ASSERT_TRUE(pose.ok()) << pose.status().ToString();
    EXPECT_LT(RotationAngle(pose->R, scene.R), 1e-10);
    EXPECT_LT((pose->t - scene.t.normalized()).norm(), 1e-10);
    EXPECT_EQ(pose->num_in_front, 100);
    EXPECT_EQ(pose->in_front_mask, std::vector<char>(100, 1));
  }
}

TEST(RelativePose, FromFivePointRansacOnNoisyMatches) {
  SyntheticSceneOptions options;
  options.num_points = 500;
  options.noise_sigma = 0.5;
  options.outlier_fraction = 0.3;
  options.seed = 9;
  const SyntheticTwoViewScene scene = MakeScene(options);
  const std::vector<Correspondence> normalised = scene.Correspondences(true);
  RansacOptions ransac;
  ransac.max_residual = 2.0 / options.focal;
  const auto report = Ransac<EssentialFivePoint>::Run(normalised, ransac);
  ASSERT_TRUE(report.ok());
  ASSERT_EQ(report->status, RansacStatus::kSuccess);
  std::vector<Correspondence> inliers;
  for (size_t i = 0; i < normalised.size(); ++i) {
    if (report->inlier_mask[i]) inliers.push_back(normalised[i]);
  }
  const Result<RelativePose> pose =
      RelativePoseFromEssential(report->model, inliers.data(), static_cast<int>(inliers.size()));
  ASSERT_TRUE(pose.ok()) << pose.status().ToString();
  EXPECT_LT(RotationAngle(pose->R, scene.R), 0.2 * kPi / 180);
  EXPECT_LT(std::acos(std::min(1.0, pose->t.dot(scene.t.normalized()))), 2.0 * kPi / 180);
  EXPECT_GT(pose->num_in_front, static_cast<int>(0.98 * inliers.size()));
}

TEST(RelativePose, RejectsInvalidEssentialMatrices) {
  const std::vector<Correspondence> one(1, Correspondence{Eigen::Vector2d(0, 0), Eigen::Vector2d(0.1, 0)});
  Eigen::Matrix3d rank_one = Eigen::Matrix3d::Zero();
  rank_one(0, 0) = 1.0;
  EXPECT_EQ(RelativePoseFromEssential(rank_one, one.data(), 1).status().code(), StatusCode::kInvalidArgument);
  Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
  nan(1, 1) = std::nan("");
  EXPECT_EQ(RelativePoseFromEssential(nan, one.data(), 1).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(RelativePoseFromEssential(Eigen::Matrix3d::Identity(), one.data(), 0).status().code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace reconar
