#include "core/math/radial_camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

#include "core/math/camera_intrinsics.h"

namespace reconar {
namespace {

RadialCamera TestCamera(double k1, double k2, double aspect = 1.0) {
  RadialCamera camera;
  camera.focal = 900.0;
  camera.cx = 500.0;
  camera.cy = 400.0;
  camera.k1 = k1;
  camera.k2 = k2;
  camera.aspect = aspect;
  return camera;
}

TEST(RadialCamera, ProjectIsTheRadialFormula) {
  const RadialCamera camera = TestCamera(-0.15, 0.04, 1.01);
  const Eigen::Vector3d X(0.3, -0.2, 1.5);
  const Eigen::Vector2d p = X.head<2>() / X.z();
  const double d = 1.0 - 0.15 * p.squaredNorm() + 0.04 * p.squaredNorm() * p.squaredNorm();
  const Eigen::Vector2d pixel = camera.Project(X);
  EXPECT_NEAR(pixel.x(), 900.0 * d * p.x() + 500.0, 1e-9);
  EXPECT_NEAR(pixel.y(), 1.01 * 900.0 * d * p.y() + 400.0, 1e-9);
  EXPECT_DOUBLE_EQ(camera.fy(), 909.0);
}

TEST(RadialCamera, UndistortInvertsProject) {
  for (double aspect : {1.0, 0.98}) {
    const RadialCamera camera = TestCamera(-0.15, 0.04, aspect);
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> x(-0.7, 0.7), y(-0.5, 0.5);
    for (int i = 0; i < 1000; ++i) {
      const Eigen::Vector2d p(x(rng), y(rng));
      Eigen::Vector2d back;
      ASSERT_TRUE(camera.Undistort(camera.PixelFromNormalised(p), &back));
      EXPECT_LT((back - p).norm(), 1e-12);
    }
  }
  // Far outside the monotonic range of r d(r^2) there is no inverse.
  const RadialCamera strong = TestCamera(-0.5, 0.0);
  Eigen::Vector2d p;
  EXPECT_FALSE(strong.Undistort(Eigen::Vector2d(500.0 + 900.0 * 2.0, 400.0), &p));
  EXPECT_FALSE(strong.Undistort(Eigen::Vector2d(std::nan(""), 400.0), &p));
  // Without distortion the pixel maps straight back.
  ASSERT_TRUE(TestCamera(0.0, 0.0).Undistort(Eigen::Vector2d(590.0, 310.0), &p));
  EXPECT_EQ(p, Eigen::Vector2d(0.1, -0.1));
}

// Before the one camera model, tag registration and the tracker inverted the distortion by 20
// fixed-point iterations p <- q / d(|p|^2) while pose estimation and the mapper used Newton's
// method on |p|. This measures what choosing Newton changed, over the whole image of a camera with
// moderate distortion: the largest difference in pixels (printed; asserted below 1e-9 px).
TEST(RadialCamera, NewtonAgreesWithTheFormerFixedPointIteration) {
  const std::array<std::array<double, 2>, 2> distortions = {{{-0.15, 0.04}, {0.05, -0.01}}};
  for (const std::array<double, 2>& k1k2 : distortions) {
    const RadialCamera camera = TestCamera(k1k2[0], k1k2[1]);
    double largest_px = 0.0;
    for (int v = 0; v <= 800; v += 8) {
      for (int u = 0; u <= 1000; u += 8) {
        const Eigen::Vector2d q((u - camera.cx) / camera.focal, (v - camera.cy) / camera.focal);
        Eigen::Vector2d fixed_point = q;
        for (int i = 0; i < 20; ++i) fixed_point = q / camera.Distortion(fixed_point.squaredNorm());
        Eigen::Vector2d newton;
        ASSERT_TRUE(camera.Undistort(Eigen::Vector2d(u, v), &newton)) << u << " " << v;
        largest_px = std::max(largest_px, camera.focal * (newton - fixed_point).norm());
      }
    }
    std::printf("k1 %g k2 %g: largest |Newton - fixed point| = %.3g px\n", k1k2[0], k1k2[1], largest_px);
    EXPECT_LT(largest_px, 1e-9);
  }
}

TEST(RadialCamera, JacobianMatchesCentralDifferences) {
  const RadialCamera camera = TestCamera(-0.15, 0.04, 1.02);
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-0.5, 0.4), Eigen::Vector2d(0.0, 0.0)}) {
    const Eigen::Matrix2d analytic = camera.PixelFromNormalisedJacobian(p);
    for (int k = 0; k < 2; ++k) {
      const double h = 1e-6;
      const Eigen::Vector2d step = h * Eigen::Vector2d::Unit(k);
      const Eigen::Vector2d numeric =
          (camera.PixelFromNormalised(p + step) - camera.PixelFromNormalised(p - step)) / (2.0 * h);
      EXPECT_LT((analytic.col(k) - numeric).norm(), 1e-5) << p.transpose() << " column " << k;
    }
  }
}

TEST(RadialCamera, FoldRadiusIsWherePixelRadiusStopsGrowing) {
  for (const auto& [k1, k2] : {std::pair(-0.5, 0.0), std::pair(0.1, -0.05), std::pair(-0.3, 0.02), std::pair(0.0, -0.1), std::pair(0.2, -1e-9)}) {
    const double fold_r2 = TestCamera(k1, k2).FoldRadiusSquared();
    ASSERT_TRUE(std::isfinite(fold_r2)) << k1 << " " << k2;
    const double growth = 1.0 + 3.0 * k1 * fold_r2 + 5.0 * k2 * fold_r2 * fold_r2;
    EXPECT_NEAR(growth / (1.0 + std::abs(3.0 * k1 * fold_r2)), 0.0, 1e-12) << k1 << " " << k2;
  }
  EXPECT_EQ(TestCamera(0.0, 0.0).FoldRadiusSquared(), INFINITY);
  EXPECT_EQ(TestCamera(0.1, 0.0).FoldRadiusSquared(), INFINITY);
  EXPECT_EQ(TestCamera(-0.15, 0.04).FoldRadiusSquared(), INFINITY);
}

TEST(RadialCamera, MaxValidRadiusRefusesWhatTheDistortionFoldsBackIntoTheFrame) {
  constexpr int kWidth = 1000, kHeight = 800;
  const auto in_frame = [](const Eigen::Vector2d& pixel) {
    return pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() < kWidth - 0.5 && pixel.y() < kHeight - 0.5;
  };
  // r d(r^2) = r - 0.5 r^3 turns back at r^2 = 2/3, inside the frame's corners.
  const RadialCamera strong = TestCamera(-0.5, 0.0);
  const double max_r2 = strong.MaxValidRadiusSquared(kWidth, kHeight);
  EXPECT_NEAR(max_r2, 2.0 / 3.0, 1e-12);
  const Eigen::Vector3d far_off_axis(1.3, 0.0, 1.0);
  ASSERT_TRUE(in_frame(strong.Project(far_off_axis)));
  EXPECT_GT(far_off_axis.head<2>().squaredNorm(), max_r2);
  const Eigen::Vector3d ordinary(0.3, -0.2, 1.0);
  ASSERT_TRUE(in_frame(strong.Project(ordinary)));
  EXPECT_LE(ordinary.head<2>().squaredNorm(), max_r2);
  // Where nothing folds the frame's farthest corner sets the bound.
  const RadialCamera mild = TestCamera(-0.15, 0.04);
  Eigen::Vector2d farthest_corner;
  ASSERT_TRUE(mild.Undistort(Eigen::Vector2d(-0.5, -0.5), &farthest_corner));
  EXPECT_DOUBLE_EQ(mild.MaxValidRadiusSquared(kWidth, kHeight), farthest_corner.squaredNorm());
}

TEST(RadialCamera, IsValidNeedsPositiveFocalAndAspect) {
  EXPECT_TRUE(TestCamera(0.1, 0.0).IsValid());
  EXPECT_FALSE(RadialCamera().IsValid());  // focal 0: not set
  EXPECT_FALSE(TestCamera(0.1, 0.0, 0.0).IsValid());
  EXPECT_FALSE(TestCamera(std::nan(""), 0.0).IsValid());
}

// CameraIntrinsics (fx, fy) is a record of the same model.
TEST(CameraIntrinsics, ProjectsAndUnprojectsThroughRadialCamera) {
  CameraIntrinsics intrinsics{/*width=*/0,  /*height=*/0, /*fx=*/800.0, /*fy=*/808.0,
                              /*cx=*/320.0, /*cy=*/240.0, /*k1=*/-0.1,  /*k2=*/0.02};
  const RadialCamera camera = intrinsics.Camera();
  EXPECT_EQ(camera.focal, 800.0);
  EXPECT_DOUBLE_EQ(camera.fy(), 808.0);
  const Eigen::Vector3d X(0.2, 0.1, 1.0);
  EXPECT_EQ(intrinsics.Project(X), camera.Project(X));
  const Eigen::Vector2d pixel = intrinsics.Project(X);
  const double d = 1.0 + 0.05 * (-0.1 + 0.02 * 0.05);
  EXPECT_NEAR(pixel.y(), 808.0 * d * 0.1 + 240.0, 1e-9);
  EXPECT_LT((intrinsics.Unproject(pixel) - Eigen::Vector2d(0.2, 0.1)).norm(), 1e-12);
  // Beyond the invertible region Unproject says so with NaN.
  intrinsics.k1 = -0.5;
  intrinsics.k2 = 0.0;
  EXPECT_FALSE(intrinsics.Unproject(Eigen::Vector2d(320.0 + 800.0 * 2.0, 240.0)).allFinite());
}

}  // namespace
}  // namespace reconar
