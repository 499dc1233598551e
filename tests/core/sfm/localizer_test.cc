// Relocalisation (core/sfm/localizer.h) on a synthetic scene with known poses: a map built by
// BuildLocalizationMap from keyframes that see random points with random descriptors, and queries
// made by projecting those points into a camera of known pose.
#include "core/sfm/localizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "core/features/descriptor_distance.h"

namespace reconar {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;

RadialCamera TestCamera() {
  RadialCamera camera;
  camera.focal = 500.0;
  camera.cx = 319.5;
  camera.cy = 239.5;
  return camera;
}

uint8_t Clamp8(int v) { return static_cast<uint8_t>(std::clamp(v, 0, 255)); }

// A copy of a descriptor with uniform noise of +-amplitude per component.
void NoisyCopy(const uint8_t* from, int amplitude, std::mt19937* rng, uint8_t* to) {
  std::uniform_int_distribution<int> noise(-amplitude, amplitude);
  for (int d = 0; d < kDescriptorSize; ++d) to[d] = Clamp8(from[d] + noise(*rng));
}

struct Scene {
  std::vector<Eigen::Vector3d> points;
  std::vector<uint8_t> descriptors;  // per point
  Reconstruction model;
  std::map<std::string, std::vector<uint8_t>> image_descriptors;
};

Rigid3 CameraOnRing(double angle_deg) {
  const double a = angle_deg * M_PI / 180.0;
  return CamFromWorldLookingAt(Eigen::Vector3d(5.0 * std::cos(a), 0.3, 5.0 * std::sin(a)), Eigen::Vector3d::Zero(),
                               Eigen::Vector3d(0, -1, 0));
}

bool Visible(const RadialCamera& camera, const Rigid3& cam_from_world, const Eigen::Vector3d& point,
             Eigen::Vector2d* pixel) {
  const Eigen::Vector3d in_camera = cam_from_world * point;
  if (in_camera.z() <= 0.1) return false;
  *pixel = camera.Project(in_camera);
  return pixel->x() >= 0 && pixel->y() >= 0 && pixel->x() <= kWidth - 1 && pixel->y() <= kHeight - 1;
}

// 800 points in a 2 m cube seen by 8 keyframes every 45 degrees around it.
Scene MakeScene(unsigned seed) {
  Scene scene;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::uniform_int_distribution<int> component(0, 90);
  const int num_points = 800;
  scene.descriptors.resize(static_cast<size_t>(num_points) * kDescriptorSize);
  for (int i = 0; i < num_points; ++i) {
    scene.points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
    for (int d = 0; d < kDescriptorSize; ++d)
      scene.descriptors[static_cast<size_t>(i) * kDescriptorSize + d] = Clamp8(component(rng));
    SfmPoint point;
    point.position = scene.points.back();
    scene.model.points.push_back(point);
  }
  SfmCamera camera;
  static_cast<RadialCamera&>(camera) = TestCamera();
  camera.width = kWidth;
  camera.height = kHeight;
  scene.model.cameras.push_back(camera);
  for (int k = 0; k < 8; ++k) {
    SfmImage image;
    image.name = "key" + std::to_string(k) + ".png";
    image.camera_id = 0;
    image.registered = true;
    image.cam_from_world = CameraOnRing(45.0 * k);
    std::vector<uint8_t>& descriptors = scene.image_descriptors[image.name];
    for (int i = 0; i < num_points; ++i) {
      Eigen::Vector2d pixel;
      if (!Visible(TestCamera(), image.cam_from_world, scene.points[static_cast<size_t>(i)], &pixel)) continue;
      const int keypoint = static_cast<int>(image.keypoints.size());
      image.keypoints.push_back(pixel);
      image.point3d_ids.push_back(i);
      descriptors.resize(descriptors.size() + kDescriptorSize);
      NoisyCopy(&scene.descriptors[static_cast<size_t>(i) * kDescriptorSize], 4, &rng,
                &descriptors[descriptors.size() - kDescriptorSize]);
      scene.model.points[static_cast<size_t>(i)].track.push_back(
          TrackElement{static_cast<int>(scene.model.images.size()), keypoint});
    }
    scene.model.images.push_back(std::move(image));
  }
  return scene;
}

LocalizationMap BuildMap(const Scene& scene) {
  const ImageDescriptorLoader load = [&](const SfmImage& image) -> Result<std::vector<uint8_t>> {
    return scene.image_descriptors.at(image.name);
  };
  MapBuildOptions options;
  options.vocabulary.branching = 8;
  options.vocabulary.depth = 3;
  auto map = BuildLocalizationMap(scene.model, load, "arbitrary", false, options);
  EXPECT_TRUE(map.ok()) << map.status().ToString();
  return std::move(*map);
}

// The scene's points seen from cam_from_world as SIFT features (pixel noise 0.3 px), then
// `clutter` features with random descriptors at random pixels.
SiftFeatures Query(const Scene& scene, const Rigid3& cam_from_world, int clutter, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> pixel_noise(0.0, 0.3);
  SiftFeatures features;
  for (size_t i = 0; i < scene.points.size(); ++i) {
    Eigen::Vector2d pixel;
    if (!Visible(TestCamera(), cam_from_world, scene.points[i], &pixel)) continue;
    SiftKeypoint keypoint;
    keypoint.x = static_cast<float>(pixel.x() + pixel_noise(rng));
    keypoint.y = static_cast<float>(pixel.y() + pixel_noise(rng));
    keypoint.scale = 2.0f;
    features.keypoints.push_back(keypoint);
    features.descriptors.resize(features.descriptors.size() + kDescriptorSize);
    NoisyCopy(&scene.descriptors[i * kDescriptorSize], 4, &rng,
              &features.descriptors[features.descriptors.size() - kDescriptorSize]);
  }
  std::uniform_real_distribution<double> x(0, kWidth - 1), y(0, kHeight - 1);
  std::uniform_int_distribution<int> component(0, 90);
  for (int c = 0; c < clutter; ++c) {
    SiftKeypoint keypoint;
    keypoint.x = static_cast<float>(x(rng));
    keypoint.y = static_cast<float>(y(rng));
    features.keypoints.push_back(keypoint);
    for (int d = 0; d < kDescriptorSize; ++d) features.descriptors.push_back(Clamp8(component(rng)));
  }
  return features;
}

double RotationErrorDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return std::acos(std::clamp(((a * b.transpose()).trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / M_PI;
}

TEST(Localizer, FindsThePoseOfAViewBetweenKeyframesAmongClutter) {
  const Scene scene = MakeScene(1);
  const LocalizationMap map = BuildMap(scene);
  EXPECT_EQ(map.keyframes.size(), 8u);
  auto localizer = Localizer::Create(&map, LocalizerOptions());
  ASSERT_TRUE(localizer.ok());
  const Rigid3 truth = CameraOnRing(20.0);
  auto camera = ResolveQueryCamera(map, kWidth, kHeight, std::nullopt, 0.0);
  ASSERT_TRUE(camera.ok());
  EXPECT_EQ(camera->source, "map");
  auto result = localizer->Localize(Query(scene, truth, 300, 2), *camera);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_TRUE(result->registered) << result->reason;
  EXPECT_LT((CameraCenterInWorld(result->cam_from_world) - CameraCenterInWorld(truth)).norm(), 0.01);
  EXPECT_LT(RotationErrorDeg(result->cam_from_world.rotation, truth.rotation), 0.1);
  EXPECT_FALSE(result->keyframes.empty());
  EXPECT_EQ(result->inlier_points.size(), static_cast<size_t>(result->num_inliers));
}

TEST(Localizer, EstimatesTheFocalWhenTheCameraIsUnknown) {
  const Scene scene = MakeScene(3);
  const LocalizationMap map = BuildMap(scene);
  auto localizer = Localizer::Create(&map, LocalizerOptions());
  ASSERT_TRUE(localizer.ok());
  QueryCamera camera;
  camera.width = kWidth;
  camera.height = kHeight;
  camera.focal_prior_px = 650.0;
  camera.source = "default prior";
  const Rigid3 truth = CameraOnRing(200.0);
  auto result = localizer->Localize(Query(scene, truth, 100, 4), camera);
  ASSERT_TRUE(result.ok());
  ASSERT_TRUE(result->registered) << result->reason;
  EXPECT_NEAR(result->camera.focal, 500.0, 5.0);
  EXPECT_LT((CameraCenterInWorld(result->cam_from_world) - CameraCenterInWorld(truth)).norm(), 0.05);
}

TEST(Localizer, RefusesAnUnrelatedImage) {
  const Scene scene = MakeScene(5);
  const LocalizationMap map = BuildMap(scene);
  const Scene other = MakeScene(6);  // other points, other descriptors
  auto localizer = Localizer::Create(&map, LocalizerOptions());
  ASSERT_TRUE(localizer.ok());
  auto camera = ResolveQueryCamera(map, kWidth, kHeight, std::nullopt, 0.0);
  ASSERT_TRUE(camera.ok());
  for (int k = 0; k < 4; ++k) {
    auto result = localizer->Localize(Query(other, CameraOnRing(90.0 * k + 10.0), 300, 7 + k), *camera);
    ASSERT_TRUE(result.ok());
    EXPECT_FALSE(result->registered) << "view " << k << ": " << result->num_inliers << " inliers";
    EXPECT_FALSE(result->reason.empty());
  }
  SiftFeatures few = Query(scene, CameraOnRing(20.0), 0, 8);
  few.keypoints.resize(10);
  few.descriptors.resize(10 * kDescriptorSize);
  auto result = localizer->Localize(few, *camera);
  ASSERT_TRUE(result.ok());
  EXPECT_FALSE(result->registered);
  EXPECT_NE(result->reason.find("too few features"), std::string::npos) << result->reason;
  SiftFeatures inconsistent = few;
  inconsistent.descriptors.pop_back();
  EXPECT_EQ(localizer->Localize(inconsistent, *camera).status().code(), StatusCode::kInvalidArgument);
}

TEST(ResolveQueryCamera, ScalesTheMapCameraAndFallsBackToPriors) {
  const LocalizationMap map = BuildMap(MakeScene(9));
  auto half = ResolveQueryCamera(map, kWidth / 2, kHeight / 2, std::nullopt, 0.0);
  ASSERT_TRUE(half.ok());
  ASSERT_TRUE(half->known.has_value());
  EXPECT_DOUBLE_EQ(half->known->focal, 250.0);
  EXPECT_DOUBLE_EQ(half->known->cx, (319.5 + 0.5) / 2 - 0.5);
  // An EXIF focal that disagrees with the map's camera: another camera, its focal a prior.
  auto exif = ResolveQueryCamera(map, kWidth, kHeight, std::nullopt, 1200.0);
  ASSERT_TRUE(exif.ok());
  EXPECT_FALSE(exif->known.has_value());
  EXPECT_EQ(exif->source, "exif prior");
  EXPECT_DOUBLE_EQ(exif->focal_prior_px, 1200.0);
  auto agreeing = ResolveQueryCamera(map, kWidth, kHeight, std::nullopt, 520.0);
  ASSERT_TRUE(agreeing.ok());
  EXPECT_EQ(agreeing->source, "map");
  auto square = ResolveQueryCamera(map, 500, 500, std::nullopt, 0.0);  // no keyframe of this shape
  ASSERT_TRUE(square.ok());
  EXPECT_EQ(square->source, "default prior");
  EXPECT_DOUBLE_EQ(square->focal_prior_px, 600.0);
  CameraIntrinsics given;
  given.fx = given.fy = 800.0;
  given.cx = 319.5;
  given.cy = 239.5;
  auto intrinsics = ResolveQueryCamera(map, kWidth, kHeight, given, 0.0);
  ASSERT_TRUE(intrinsics.ok());
  EXPECT_EQ(intrinsics->source, "intrinsics");
  EXPECT_DOUBLE_EQ(intrinsics->known->focal, 800.0);
  given.width = 1000;
  given.height = 1000;
  EXPECT_EQ(ResolveQueryCamera(map, kWidth, kHeight, given, 0.0).status().code(), StatusCode::kInvalidArgument);
}

TEST(LocalizerOptions, CheckNamesTheBadField) {
  LocalizerOptions options;
  options.min_inliers = 3;
  EXPECT_NE(options.Check().message().find("min_inliers"), std::string::npos);
  options = LocalizerOptions();
  options.max_ratio = 1.5;
  EXPECT_NE(options.Check().message().find("max_ratio"), std::string::npos);
}

}  // namespace
}  // namespace reconar
