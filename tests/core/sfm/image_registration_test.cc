#include "core/sfm/image_registration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "core/math/rotation.h"
#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

TEST(ImageRegistrationTest, RecoversTheTruePoseAndAddsTheInlierObservations) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel model = testing::TrueModel(scene);
  const int image = 3;
  testing::Unregister(&model, image);
  MapperOptions options;
  options.num_threads = 1;
  bool focal_changed = true;
  ASSERT_TRUE(RegisterImage(&model, scene.images, image, options, &focal_changed))
      << model.failure[static_cast<size_t>(image)];
  EXPECT_FALSE(focal_changed);  // seven images confirm the shared camera's focal
  const SfmImage& img = model.rec.images[static_cast<size_t>(image)];
  EXPECT_TRUE(img.registered);
  EXPECT_TRUE(model.failure[static_cast<size_t>(image)].empty());
  EXPECT_LT(RotationAngle(img.cam_from_world.rotation, scene.poses[static_cast<size_t>(image)].rotation) * 180.0 / M_PI,
            0.05);
  EXPECT_LT((img.Center() - CameraCenterInWorld(scene.poses[static_cast<size_t>(image)])).norm(), 0.01);
  // The observations added are of the right points, and most visible points are observed.
  int observed = 0;
  for (size_t kp = 0; kp < img.point3d_ids.size(); ++kp) {
    const int id = img.point3d_ids[kp];
    if (id < 0) continue;
    ++observed;
    EXPECT_EQ(scene.point_of_keypoint[static_cast<size_t>(image)][kp],
              testing::TruePointOf(scene, model.rec.points[static_cast<size_t>(id)]));
    const std::vector<TrackElement>& track = model.rec.points[static_cast<size_t>(id)].track;
    EXPECT_EQ(track.back().image_id, image);
    EXPECT_EQ(track.back().keypoint_id, static_cast<int>(kp));
  }
  EXPECT_GE(observed, model.CountVisiblePoints(image) * 9 / 10);
}

TEST(ImageRegistrationTest, FailureGivesTheReasonAndLeavesTheImageUnregistered) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel model = testing::TrueModel(scene);
  testing::Unregister(&model, 5);
  MapperOptions options;
  options.registration_min_inliers = 100000;
  bool focal_changed = true;
  EXPECT_FALSE(RegisterImage(&model, scene.images, 5, options, &focal_changed));
  EXPECT_FALSE(focal_changed);
  EXPECT_FALSE(model.rec.images[5].registered);
  EXPECT_NE(model.failure[5].find("2D-3D correspondences failed"), std::string::npos) << model.failure[5];
  for (int id : model.rec.images[5].point3d_ids) EXPECT_EQ(id, -1);
}

// 15 correspondences are under the 30 that register unchecked, but all fit and the pose puts the
// image's many two-view matches on their epipolar lines.
TEST(ImageRegistrationTest, FewPointsRegisterWhenTheTwoViewMatchesAgree) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel model = testing::TrueModelWithFewPointsSeenBy(scene, 3, 15);
  bool focal_changed = true;
  ASSERT_TRUE(RegisterImage(&model, scene.images, 3, MapperOptions(), &focal_changed))
      << model.failure[3];
  const SfmImage& img = model.rec.images[3];
  EXPECT_LT(RotationAngle(img.cam_from_world.rotation, scene.poses[3].rotation) * 180.0 / M_PI, 0.3);
  EXPECT_LT((img.Center() - CameraCenterInWorld(scene.poses[3])).norm(), 0.1);  // ring radius 10
}

// The same 15 keypoints moved to where a camera tilted by 5 degrees would see their points: they
// fit that wrong pose exactly, but the image's other matches do not lie on its epipolar lines.
// (Tilted, not turned: the ring's baselines are horizontal, and a turn about the vertical moves
// points along their epipolar lines, which no two-view check can see.)
TEST(ImageRegistrationTest, FewPointsAgainstTheTwoViewMatchesAreRefused) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel model = testing::TrueModelWithFewPointsSeenBy(scene, 3, 15);
  Rigid3 wrong = scene.poses[3];
  wrong.rotation = Eigen::AngleAxisd(5.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix() * wrong.rotation;
  SfmImage& img = model.rec.images[3];
  const std::vector<int>& track_of = model.tracks.track_of[3];
  for (size_t kp = 0; kp < track_of.size(); ++kp) {
    const int t = track_of[kp];
    const int point = t < 0 ? -1 : model.point_of_track[static_cast<size_t>(t)];
    if (point >= 0)
      img.keypoints[kp] = scene.camera.Project(wrong * model.rec.points[static_cast<size_t>(point)].position);
  }
  bool focal_changed = true;
  EXPECT_FALSE(RegisterImage(&model, scene.images, 3, MapperOptions(), &focal_changed));
  EXPECT_FALSE(model.rec.images[3].registered);
  EXPECT_NE(model.failure[3].find("on their epipolar lines"), std::string::npos) << model.failure[3];
}

// Image 2 gets its own camera with an EXIF focal `factor` x the true one; no registered image
// uses that camera yet, so the registration estimates the focal (paper eq. 5 keeps the EXIF
// focal when it lies within 0.7-1.4 x the estimate).
double FocalAfterRegistration(double factor) {
  const testing::Scene scene = testing::RegistrationRing();
  std::vector<MapperImage> images = scene.images;
  images[2].focal_from_exif = true;
  images[2].focal_prior = factor * scene.camera.focal;
  MapperModel model = testing::TrueModel(scene);
  SfmCamera exif = scene.camera;
  exif.focal = images[2].focal_prior;
  model.rec.cameras.push_back(exif);
  model.camera_prior.push_back(exif.focal);
  model.camera_from_exif.push_back(true);
  model.rec.images[2].camera_id = 1;
  testing::Unregister(&model, 2);
  bool focal_changed = false;
  EXPECT_TRUE(RegisterImage(&model, images, 2, MapperOptions(), &focal_changed)) << model.failure[2];
  EXPECT_TRUE(focal_changed);
  return model.rec.cameras[1].focal;
}

TEST(ImageRegistrationTest, UnconfirmedFocalIsEstimatedAndADistrustedExifFocalReplaced) {
  EXPECT_NEAR(FocalAfterRegistration(1.6), 900.0, 0.02 * 900.0);
  EXPECT_EQ(FocalAfterRegistration(1.2), 1.2 * 900.0);
}

TEST(ImageRegistrationTest, GuessCameraAveragesRegisteredCamerasOfTheSameSize) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel model = testing::TrueModel(scene);
  SfmCamera fresh = scene.camera;
  fresh.focal = 2000.0;
  fresh.k1 = 0.0;
  model.rec.cameras.push_back(fresh);
  model.camera_prior.push_back(fresh.focal);
  model.camera_from_exif.push_back(false);
  model.rec.images[4].camera_id = 1;
  testing::Unregister(&model, 4);
  // Camera 1 is unused and has no EXIF: the guess is camera 0's focal and distortion.
  const SfmCamera guess = GuessCamera(model, 4);
  EXPECT_EQ(guess.focal, scene.camera.focal);
  EXPECT_NEAR(guess.k1, scene.camera.k1, 1e-15);
  model.camera_from_exif[1] = true;
  EXPECT_EQ(GuessCamera(model, 4).focal, 2000.0);
}

}  // namespace
}  // namespace reconar
