// Undistortion against the camera model itself: content seen through SfmCamera::Project (with
// radial distortion) must reappear at DenseView::Project (pinhole) in the undistorted image.
#include "core/mvs/undistort.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace reconar {
namespace {

SfmCamera DistortedCamera() {
  SfmCamera camera;
  camera.width = 640;
  camera.height = 480;
  camera.focal = 520.0;
  camera.cx = 326.3;
  camera.cy = 233.7;
  camera.k1 = -0.21;
  camera.k2 = 0.06;
  camera.aspect = 1.015;
  return camera;
}

Rigid3 SomePose() {
  Rigid3 pose;
  pose.rotation =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, -0.1).normalized()).toRotationMatrix();
  pose.translation = Eigen::Vector3d(0.1, -0.2, 4.0);
  return pose;
}

// A smooth colour pattern of the distorted pixel position (low frequency, so that averaging
// down two levels changes it little).
std::array<double, 3> Pattern(double u, double v) {
  return {127.5 + 100.0 * std::sin(u / 23.0) * std::cos(v / 31.0), 127.5 + 100.0 * std::cos((u + v) / 41.0),
          127.5 + 100.0 * std::sin((u - 0.5 * v) / 37.0)};
}

Image<uint8_t> PatternImage(int width, int height) {
  Image<uint8_t> image(width, height, 3);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const auto rgb = Pattern(u, v);
      for (int c = 0; c < 3; ++c) image.row(v)[3 * u + c] = static_cast<uint8_t>(std::lround(rgb[c]));
    }
  }
  return image;
}

std::array<double, 3> SampleBilinear(const Image<uint8_t>& image, const Eigen::Vector2d& p) {
  const int x0 = static_cast<int>(std::floor(p.x())), y0 = static_cast<int>(std::floor(p.y()));
  const double ax = p.x() - x0, ay = p.y() - y0;
  std::array<double, 3> out{};
  for (int c = 0; c < 3; ++c) {
    const double a = image.row(y0)[3 * x0 + c], b = image.row(y0)[3 * (x0 + 1) + c];
    const double d = image.row(y0 + 1)[3 * x0 + c], e = image.row(y0 + 1)[3 * (x0 + 1) + c];
    out[c] = (1 - ay) * ((1 - ax) * a + ax * b) + ay * ((1 - ax) * d + ax * e);
  }
  return out;
}

TEST(Undistort, CameraAtLevelFollowsThePixelCentreConvention) {
  const SfmCamera camera = DistortedCamera();
  for (int level = 0; level <= 2; ++level) {
    const SfmCamera scaled = CameraAtLevel(camera, level);
    const double s = 1 << level;
    EXPECT_EQ(scaled.width, 640 >> level);
    EXPECT_DOUBLE_EQ(scaled.focal, camera.focal / s);
    const Eigen::Vector3d x(0.3, -0.2, 1.7);
    const Eigen::Vector2d p0 = camera.Project(x), pl = scaled.Project(x);
    EXPECT_NEAR(pl.x(), (p0.x() + 0.5) / s - 0.5, 1e-9);
    EXPECT_NEAR(pl.y(), (p0.y() + 0.5) / s - 0.5, 1e-9);
  }
}

TEST(Undistort, AreaAverageDownIsTheBlockMean) {
  Image<uint8_t> image(5, 4, 1);
  for (int v = 0; v < 4; ++v) {
    for (int u = 0; u < 5; ++u) image.row(v)[u] = static_cast<uint8_t>(10 * v + u);
  }
  const Image<uint8_t> half = AreaAverageDown(image, 1);
  ASSERT_EQ(half.width(), 2);
  ASSERT_EQ(half.height(), 2);
  EXPECT_EQ(half.row(0)[0], 6);   // (0 + 1 + 10 + 11) / 4 = 5.5 -> 6
  EXPECT_EQ(half.row(1)[1], 28);  // (22 + 23 + 32 + 33) / 4 = 27.5 -> 28
  const Image<uint8_t> quarter = AreaAverageDown(image, 2);
  ASSERT_EQ(quarter.width(), 1);
  EXPECT_EQ(quarter.row(0)[0], 17);  // mean of columns 0..3, rows 0..3 = 1.5 + 15 = 16.5 -> 17
}

TEST(Undistort, PointsLandOnTheSameContent) {
  const SfmCamera camera = DistortedCamera();
  const Rigid3 pose = SomePose();
  const Image<uint8_t> photo = PatternImage(camera.width, camera.height);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int level = 0; level <= 2; ++level) {
    auto view = UndistortView(photo, camera, pose, level);
    ASSERT_TRUE(view.ok()) << view.status().ToString();
    EXPECT_EQ(view->width(), 640 >> level);
    EXPECT_EQ(view->gray.width(), view->rgb.width());
    double error_sum = 0.0, error_max = 0.0;
    int n = 0;
    while (n < 300) {
      // A world point whose distorted projection lies well inside the photo.
      const Eigen::Vector3d cam(1.2 * uniform(random), 0.9 * uniform(random), 4.0 + uniform(random));
      const Eigen::Vector3d world = pose.rotation.transpose() * (cam - pose.translation);
      const Eigen::Vector2d distorted = camera.Project(pose * world);
      if (distorted.x() < 8 || distorted.y() < 8 || distorted.x() > 631 || distorted.y() > 471) continue;
      const Eigen::Vector2d undistorted = view->Project(world);
      ASSERT_GT(undistorted.x(), 0.0);
      ASSERT_GT(undistorted.y(), 0.0);
      ASSERT_LT(undistorted.x(), view->width() - 1.0);
      ASSERT_LT(undistorted.y(), view->height() - 1.0);
      const auto expected = Pattern(distorted.x(), distorted.y());
      const auto actual = SampleBilinear(view->rgb, undistorted);
      for (int c = 0; c < 3; ++c) {
        const double error = std::abs(actual[c] - expected[c]);
        error_sum += error;
        error_max = std::max(error_max, error);
      }
      ++n;
    }
    const double mean = error_sum / (3.0 * n);
    // Bilinear interpolation twice plus rounding; the averaging over 2^L blocks blurs the
    // pattern (wavelength >= 23 px) by a little more at each level.
    EXPECT_LT(mean, 1.0 + 1.5 * level) << "level " << level;
    EXPECT_LT(error_max, 4.0 + 6.0 * level) << "level " << level;
    std::printf("level %d: mean colour error %.3f, max %.2f (of 255) over %d points\n", level, mean, error_max, n);
  }
}

// Round trip of a checkerboard: undistorting the photo of a board drawn with the radial model
// gives the board drawn by the pinhole model, pixel for pixel except along square edges.
TEST(Undistort, CheckerboardRoundTrip) {
  const SfmCamera camera = DistortedCamera();
  const int square = 16;
  // The board lives on the normalised image plane (z = 1): square s in plane units of 1/focal.
  const auto board = [&](const Eigen::Vector2d& plane) {
    const int i = static_cast<int>(std::floor(plane.x() * camera.focal / square));
    const int j = static_cast<int>(std::floor(plane.y() * camera.focal / square));
    return ((i + j) & 1) ? 230 : 25;
  };
  // Distorted photo: invert the distortion of each pixel by fixed-point iteration.
  Image<uint8_t> photo(camera.width, camera.height, 3);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector2d d((u - camera.cx) / camera.focal, (v - camera.cy) / (camera.aspect * camera.focal));
      Eigen::Vector2d p = d;
      for (int k = 0; k < 50; ++k) {
        const double r2 = p.squaredNorm();
        p = d / (1.0 + r2 * (camera.k1 + camera.k2 * r2));
      }
      const uint8_t value = static_cast<uint8_t>(board(p));
      for (int c = 0; c < 3; ++c) photo.row(v)[3 * u + c] = value;
    }
  }
  auto view = UndistortView(photo, camera, Rigid3(), 0);
  ASSERT_TRUE(view.ok()) << view.status().ToString();
  int compared = 0, wrong = 0;
  for (int v = 0; v < view->height(); ++v) {
    for (int u = 0; u < view->width(); ++u) {
      const Eigen::Vector2d plane((u - view->cx) / view->fx, (v - view->cy) / view->fy);
      // Skip pixels within 1.5 px of a square edge and rays that leave the photo.
      const double gx = plane.x() * camera.focal / square, gy = plane.y() * camera.focal / square;
      const double edge = std::min(std::abs(gx - std::round(gx)), std::abs(gy - std::round(gy))) * square;
      if (edge < 1.5) continue;
      const Eigen::Vector2d source = camera.Project(Eigen::Vector3d(plane.x(), plane.y(), 1.0));
      if (source.x() < 1 || source.y() < 1 || source.x() > camera.width - 2 || source.y() > camera.height - 2) continue;
      ++compared;
      wrong += std::abs(view->gray.row(v)[u] - board(plane)) > 10 ? 1 : 0;
    }
  }
  EXPECT_GT(compared, 200000);
  EXPECT_EQ(wrong, 0);
}

TEST(Undistort, RejectsInconsistentInput) {
  const SfmCamera camera = DistortedCamera();
  const Image<uint8_t> photo(640, 480, 3);
  EXPECT_EQ(UndistortView(Image<uint8_t>(320, 240, 3), camera, Rigid3(), 0).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(UndistortView(Image<uint8_t>(640, 480, 1), camera, Rigid3(), 0).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(UndistortView(photo, camera, Rigid3(), 3).status().code(), StatusCode::kInvalidArgument);
  SfmCamera no_focal = camera;
  no_focal.focal = 0.0;
  EXPECT_EQ(UndistortView(photo, no_focal, Rigid3(), 0).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace reconar
