#include "tests/support/object_capture.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace reconar::testing {
namespace {

constexpr double kDegree = M_PI / 180.0;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kDegree;
}

Eigen::Vector3d OpticalAxis(const GroundTruthCamera& camera) {
  return camera.cam_from_world_rotation.row(2).transpose();
}

TEST(ObjectCaptureTest, TheViewsWalkRoundTheCentreOnARisingSpiralLookingAtIt) {
  const ObjectCaptureOptions options;
  const Eigen::Vector3d centre(0.1, 0.2, -0.3);
  const std::vector<NamedGroundTruthCamera> views = ObjectCaptureCameras(options, centre);
  ASSERT_EQ(views.size(), 320u);
  EXPECT_EQ(views.front().name, "view_000.png");
  EXPECT_EQ(views.back().name, "view_319.png");
  double previous_azimuth = 0.0;
  for (size_t i = 0; i < views.size(); ++i) {
    const GroundTruthCamera& camera = views[i].camera;
    const Eigen::Vector3d offset = camera.Centre() - centre;
    EXPECT_NEAR(offset.norm(), options.distance_m, options.distance_jitter * options.distance_m + 1e-12) << i;
    const double elevation = std::asin(offset.y() / offset.norm()) / kDegree;
    const double expected_elevation =
        options.min_elevation_deg + (options.max_elevation_deg - options.min_elevation_deg) * i / (views.size() - 1.0);
    EXPECT_NEAR(elevation, expected_elevation, options.position_jitter_deg + 1e-9) << i;
    // The aim (pan and tilt) is off the centre by at most the hand's jitter, the roll leaves it.
    EXPECT_LE(AngleDeg(OpticalAxis(camera), -offset), std::sqrt(2.0) * options.aim_jitter_deg + 1e-6) << i;
    // Upright but for the roll: the image's x axis nearly level.
    const Eigen::Vector3d image_x = camera.cam_from_world_rotation.row(0).transpose();
    EXPECT_LE(std::abs(std::asin(image_x.y())) / kDegree, options.roll_jitter_deg + options.aim_jitter_deg) << i;
    const double azimuth = std::atan2(offset.x(), offset.z()) / kDegree;
    if (i > 0) {
      const double step = std::remainder(azimuth - previous_azimuth, 360.0);
      EXPECT_NEAR(step, 360.0 * options.revolutions / options.views, 2.0 * options.position_jitter_deg + 1e-9) << i;
    }
    previous_azimuth = azimuth;
  }
}

TEST(ObjectCaptureTest, WithoutTheHandsJitterTheCentreProjectsToThePrincipalPoint) {
  ObjectCaptureOptions options;
  options.views = 12;
  options.position_jitter_deg = options.distance_jitter = options.aim_jitter_deg = options.roll_jitter_deg = 0.0;
  const Eigen::Vector3d centre(-0.2, 0.05, 0.4);
  for (const NamedGroundTruthCamera& view : ObjectCaptureCameras(options, centre)) {
    const GroundTruthCamera& camera = view.camera;
    const Eigen::Vector3d seen =
        camera.K * (camera.cam_from_world_rotation * centre + camera.cam_from_world_translation);
    EXPECT_NEAR(seen.x() / seen.z(), 0.5 * (options.width - 1), 1e-9) << view.name;
    EXPECT_NEAR(seen.y() / seen.z(), 0.5 * (options.height - 1), 1e-9) << view.name;
    EXPECT_NEAR(seen.z(), options.distance_m, 1e-12) << view.name;
    EXPECT_NEAR(camera.cam_from_world_rotation(0, 1), 0.0, 1e-12) << view.name;  // image x level
    EXPECT_LT(camera.cam_from_world_rotation(1, 1), 0.0) << view.name;           // image y down, world y up
  }
}

// A cube of edge 2 * half standing on y = 0, its faces counter-clockwise from outside.
Mesh Cube(double half) {
  Mesh cube;
  for (int corner = 0; corner < 8; ++corner) {
    cube.positions.emplace_back(static_cast<float>((corner & 1 ? 1 : -1) * half),
                                static_cast<float>((corner & 2 ? 2 : 0) * half),
                                static_cast<float>((corner & 4 ? 1 : -1) * half));
  }
  const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& face : faces) {
    cube.triangles.push_back({face[0], face[1], face[2]});
    cube.triangles.push_back({face[0], face[2], face[3]});
  }
  return cube;
}

// Whether the ray from `origin` along `direction` meets the box [lo, hi] in front of the origin (slabs).
bool RayMeetsBox(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, const Eigen::Vector3d& lo,
                 const Eigen::Vector3d& hi) {
  double near = 0.0, far = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    const double t0 = (lo[axis] - origin[axis]) / direction[axis], t1 = (hi[axis] - origin[axis]) / direction[axis];
    near = std::max(near, std::min(t0, t1));
    far = std::min(far, std::max(t0, t1));
  }
  return near <= far;
}

// A cube rendered small, without texture or noise: the pixels whose rays (from the true camera)
// meet it, and their neighbours' too, show the lit object; those whose rays and neighbours' miss
// it show the plain background.
TEST(ObjectCaptureTest, TheRenderedObjectIsWhereTheTrueCamerasSeeIt) {
  ObjectCaptureOptions options;
  options.views = 8;
  options.revolutions = 1.0;
  options.width = 80;
  options.height = 60;
  options.focal_px = 65.0;
  options.supersampling = 1;
  options.texture_contrast = options.background_contrast = options.noise_sigma = 0.0;
  const double half = 0.05;
  const Result<ObjectCaptureScene> scene = ObjectCaptureScene::Create(Cube(half), options);
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  EXPECT_NEAR(scene->centre().y(), half, 1e-7);
  EXPECT_NEAR(scene->floor_y(), 0.0, 1e-7);
  const Eigen::Vector3d lo(-half, 0.0, -half), hi(half, 2 * half, half);
  const int background = static_cast<int>(options.background_level);
  for (size_t i = 0; i < scene->views().size(); ++i) {
    const GroundTruthCamera& camera = scene->views()[i].camera;
    const Image<uint8_t> picture = scene->Render(i);
    ASSERT_EQ(picture.width(), options.width);
    ASSERT_EQ(picture.height(), options.height);
    const auto meets = [&](int x, int y) {
      const Eigen::Vector3d ray =
          camera.cam_from_world_rotation.transpose() * camera.K.inverse() * Eigen::Vector3d(x, y, 1.0);
      return RayMeetsBox(camera.Centre(), ray, lo, hi);
    };
    int object = 0, empty = 0;
    for (int y = 1; y + 1 < options.height; ++y) {
      for (int x = 1; x + 1 < options.width; ++x) {
        const bool here = meets(x, y);
        if (meets(x - 1, y) != here || meets(x + 1, y) != here || meets(x, y - 1) != here || meets(x, y + 1) != here) {
          continue;  // on the silhouette
        }
        const uint8_t* pixel = picture.row(y) + 3 * x;
        if (here) {
          ++object;
          EXPECT_GT(pixel[0], background + 5) << scene->views()[i].name << " (" << x << ", " << y << ")";
        } else {
          ++empty;
          EXPECT_TRUE(pixel[0] == background && pixel[1] == background && pixel[2] == background)
              << scene->views()[i].name << " (" << x << ", " << y << ")";
        }
      }
    }
    EXPECT_GT(object, 200) << scene->views()[i].name;
    EXPECT_GT(empty, 2000) << scene->views()[i].name;
  }
}

// A square standing on the floor, facing the camera: its pixels spread by the texture's standard
// deviation times the square's shade (no sensor noise, one sample per pixel).
TEST(ObjectCaptureTest, TheTexturesStandardDeviationIsTheOptions) {
  Mesh square;
  square.positions = {{-0.1f, 0.0f, 0.0f}, {0.1f, 0.0f, 0.0f}, {0.1f, 0.2f, 0.0f}, {-0.1f, 0.2f, 0.0f}};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  ObjectCaptureOptions options;
  options.views = 1;
  options.min_elevation_deg = options.max_elevation_deg = 0.0;
  options.position_jitter_deg = options.distance_jitter = options.aim_jitter_deg = options.roll_jitter_deg = 0.0;
  options.width = 160;
  options.height = 120;
  options.focal_px = 130.0;
  options.supersampling = 1;
  options.noise_sigma = 0.0;
  const Result<ObjectCaptureScene> scene = ObjectCaptureScene::Create(square, options);
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  const Image<uint8_t> picture = scene->Render(0);
  // The square's normal is +z, towards the camera; the light comes from (0.3, 1, 0.5).
  const double shade = options.ambient + (1.0 - options.ambient) * Eigen::Vector3d(0.3, 1.0, 0.5).normalized().z();
  double sum = 0.0, sum_squares = 0.0;
  int count = 0;
  for (int y = 35; y < 85; ++y) {  // well inside the square's 74 x 74 pixels round (79.5, 59.5)
    for (int x = 55; x < 105; ++x) {
      const double grey = picture.row(y)[3 * x];  // red: the clay's tint is 1 there
      sum += grey;
      sum_squares += grey * grey;
      ++count;
    }
  }
  const double mean = sum / count, deviation = std::sqrt(sum_squares / count - mean * mean);
  std::printf("square: mean %.2f, standard deviation %.2f grey levels (shade %.3f)\n", mean, deviation, shade);
  EXPECT_NEAR(mean, options.surface_level * shade, 1.0);
  EXPECT_NEAR(deviation, options.texture_contrast * shade, 0.25 * options.texture_contrast * shade);
}

TEST(ObjectCaptureTest, RefusesUnusableOptionsAndCamerasUnderTheFloor) {
  ObjectCaptureOptions options;
  options.views = 0;
  EXPECT_EQ(ObjectCaptureScene::Create(Cube(0.05), options).status().code(), StatusCode::kInvalidArgument);
  options = ObjectCaptureOptions();
  options.min_elevation_deg = -60.0;
  EXPECT_EQ(ObjectCaptureScene::Create(Cube(0.05), options).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ObjectCaptureScene::Create(Mesh(), ObjectCaptureOptions()).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace reconar::testing
