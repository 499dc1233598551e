#include "tracker/tag_pose.h"

#include <cmath>
#include <cstdlib>
#include <random>

#include <apriltag/apriltag.h>
#include <apriltag/apriltag_pose.h>
#include <apriltag/tag36h11.h>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "tests/tracker/synthetic_tag_image.h"

namespace reconar {
namespace {

using testing::ProjectedCorners;
using testing::RenderTags;
using testing::SyntheticRenderOptions;
using testing::SyntheticTag;

CameraIntrinsics TestCamera() {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = 610.0;
  camera.fy = 600.0;
  camera.cx = 322.0;
  camera.cy = 236.0;
  return camera;
}

// A pose looking at the tag (tag z toward the camera) from a random direction within 60 deg.
Rigid3 RandomCamFromTag(std::mt19937* rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Eigen::Matrix3d facing = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Vector3d axis = Eigen::Vector3d(unit(*rng), unit(*rng), 0.3 * unit(*rng)).normalized();
  Rigid3 pose;
  pose.rotation = Eigen::AngleAxisd(unit(*rng) * 60.0 * M_PI / 180.0, axis).toRotationMatrix() * facing;
  pose.translation = Eigen::Vector3d(0.1 * unit(*rng), 0.08 * unit(*rng), 0.5 + 0.2 * unit(*rng));
  return pose;
}

void CornersOf(const SyntheticTag& tag, const CameraIntrinsics& camera, Eigen::Vector2d (&corners)[4]) {
  const std::array<Eigen::Vector2d, 4> projected = ProjectedCorners(tag, camera);
  for (int k = 0; k < 4; ++k) corners[k] = projected[k];
}

TEST(TagPoseTest, TagCornersFollowLibapriltagOrder) {
  const std::array<Eigen::Vector3d, 4> c = TagCornersInTagFrame(0.2);
  EXPECT_EQ(c[0], Eigen::Vector3d(-0.1, -0.1, 0.0));
  EXPECT_EQ(c[1], Eigen::Vector3d(0.1, -0.1, 0.0));
  EXPECT_EQ(c[2], Eigen::Vector3d(0.1, 0.1, 0.0));
  EXPECT_EQ(c[3], Eigen::Vector3d(-0.1, 0.1, 0.0));
}

TEST(TagPoseTest, IppeRecoversExactPosesAndRefinementKeepsThem) {
  std::mt19937 rng(7);
  for (const double k1 : {0.0, -0.12}) {
    CameraIntrinsics camera = TestCamera();
    camera.k1 = k1;
    camera.k2 = k1 == 0.0 ? 0.0 : 0.03;
    for (int trial = 0; trial < 50; ++trial) {
      SyntheticTag tag;
      tag.size = 0.12;
      tag.cam_from_tag = RandomCamFromTag(&rng);
      Eigen::Vector2d corners[4];
      CornersOf(tag, camera, corners);
      // Raw IPPE: one of the two candidates is the true pose.
      Eigen::Vector2d plane[4], normalized[4];
      const std::array<Eigen::Vector3d, 4> tag_corners = TagCornersInTagFrame(tag.size);
      for (int k = 0; k < 4; ++k) {
        plane[k] = tag_corners[k].head<2>();
        normalized[k] = camera.Unproject(corners[k]);
      }
      std::array<Rigid3, 2> candidates;
      ASSERT_EQ(IppePoses(plane, normalized, 4, &candidates), 2);
      double best = 1e9;
      for (const Rigid3& c : candidates) {
        best = std::min(best, RotationAngle(c.rotation, tag.cam_from_tag.rotation) +
                                  (c.translation - tag.cam_from_tag.translation).norm());
      }
      EXPECT_LT(best, 1e-7) << "trial " << trial;

      const Result<TagPose> pose = EstimateTagPose(corners, tag.size, camera);
      ASSERT_TRUE(pose.ok()) << pose.status().ToString();
      EXPECT_LT(RotationAngle(pose->cam_from_tag.rotation, tag.cam_from_tag.rotation), 1e-7) << "trial " << trial;
      EXPECT_LT((pose->cam_from_tag.translation - tag.cam_from_tag.translation).norm(), 1e-8) << "trial " << trial;
      EXPECT_LT(pose->rms_reprojection_px, 1e-6);
      EXPECT_GE(pose->ambiguity_ratio, 0.0);
      EXPECT_LE(pose->ambiguity_ratio, 1.0);
    }
  }
}

TEST(TagPoseTest, NoisyCornersGiveCloseSolutionsAndAmbiguityReflectsTheView) {
  const CameraIntrinsics camera = TestCamera();
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.2);
  // Strongly tilted, near: the perspective decides between the two solutions.
  SyntheticTag tilted;
  tilted.size = 0.15;
  tilted.cam_from_tag.rotation = Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitY()).toRotationMatrix() *
                                 Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  tilted.cam_from_tag.translation = Eigen::Vector3d(0.0, 0.0, 0.35);
  // Small, far and fronto-parallel: the two solutions explain the corners equally well.
  SyntheticTag far = tilted;
  far.size = 0.05;
  far.cam_from_tag.rotation = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  far.cam_from_tag.translation = Eigen::Vector3d(0.0, 0.0, 2.0);
  double tilted_ratio = 0.0, far_ratio = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    for (SyntheticTag* tag : {&tilted, &far}) {
      Eigen::Vector2d corners[4];
      CornersOf(*tag, camera, corners);
      for (Eigen::Vector2d& c : corners) c += Eigen::Vector2d(noise(rng), noise(rng));
      const Result<TagPose> pose = EstimateTagPose(corners, tag->size, camera);
      ASSERT_TRUE(pose.ok());
      EXPECT_LT(pose->rms_reprojection_px, 0.6);
      if (tag == &tilted) {
        EXPECT_LT(RotationAngle(pose->cam_from_tag.rotation, tag->cam_from_tag.rotation), 2.0 * M_PI / 180.0);
        EXPECT_LT((pose->cam_from_tag.translation - tag->cam_from_tag.translation).norm(), 0.005);
        tilted_ratio += pose->ambiguity_ratio / 20;
      } else {
        far_ratio += pose->ambiguity_ratio / 20;
      }
    }
  }
  EXPECT_LT(tilted_ratio, 0.2);
  EXPECT_GT(far_ratio, 0.5);
}

TEST(TagPoseTest, RejectsBadInput) {
  const CameraIntrinsics camera = TestCamera();
  Eigen::Vector2d corners[4] = {{100, 100}, {200, 100}, {200, 200}, {100, 200}};
  EXPECT_FALSE(EstimateTagPose(corners, 0.0, camera).ok());
  EXPECT_FALSE(EstimateTagPose(corners, 0.1, CameraIntrinsics()).ok());
  Eigen::Vector2d collinear[4] = {{100, 100}, {150, 100}, {200, 100}, {250, 100}};
  EXPECT_FALSE(EstimateTagPose(collinear, 0.1, camera).ok());
  Eigen::Vector2d nan_corners[4] = {{NAN, 100}, {200, 100}, {200, 200}, {100, 200}};
  EXPECT_FALSE(EstimateTagPose(nan_corners, 0.1, camera).ok());
}

// Against libapriltag's own estimate_tag_pose on a rendered tag: its frame is ours rotated 180
// deg about x (x right, y down, z into the tag).
TEST(TagPoseTest, AgreesWithLibapriltagEstimateTagPose) {
  const CameraIntrinsics camera = TestCamera();
  apriltag_family_t* family = tag36h11_create();
  apriltag_detector_t* detector = apriltag_detector_create();
  apriltag_detector_add_family_bits(detector, family, 1);
  detector->quad_decimate = 1.0f;
  std::mt19937 rng(11);
  const Eigen::Matrix3d flip = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  int compared = 0;
  for (int trial = 0; trial < 8; ++trial) {
    SyntheticTag tag;
    tag.id = 5 + trial;
    tag.size = 0.1;
    tag.cam_from_tag = RandomCamFromTag(&rng);
    SyntheticRenderOptions render;
    render.blur_sigma = 0.5;
    Image<uint8_t> image = RenderTags(&tag, 1, camera, render);
    image_u8_t wrapped = {image.width(), image.height(), image.width(), image.data()};
    zarray_t* detections = apriltag_detector_detect(detector, &wrapped);
    if (zarray_size(detections) != 1) {
      apriltag_detections_destroy(detections);
      ADD_FAILURE() << "trial " << trial << ": " << zarray_size(detections) << " detections";
      continue;
    }
    apriltag_detection_t* det = nullptr;
    zarray_get(detections, 0, &det);
    // libapriltag's corners are in its own pixel convention, so its principal point is ours + 0.5.
    apriltag_detection_info_t info{det, tag.size, camera.fx, camera.fy, camera.cx + 0.5, camera.cy + 0.5};
    apriltag_pose_t theirs;
    estimate_tag_pose(&info, &theirs);
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R(r, c) = MATD_EL(theirs.R, r, c);
      t(r) = MATD_EL(theirs.t, r, 0);
    }
    free(theirs.R);  // matd_destroy is not exported by Debian's libapriltag 3.3 (PLATFORM_NOTES)
    free(theirs.t);
    Eigen::Vector2d corners[4];
    // As TagDetector does: libapriltag's corners to our convention.
    for (int k = 0; k < 4; ++k) corners[k] = Eigen::Vector2d(det->p[k][0], det->p[k][1]) - Eigen::Vector2d(0.5, 0.5);
    apriltag_detections_destroy(detections);
    const Result<TagPose> ours = EstimateTagPose(corners, tag.size, camera);
    ASSERT_TRUE(ours.ok());
    const Eigen::Matrix3d theirs_in_our_frame = R * flip;
    EXPECT_LT(RotationAngle(ours->cam_from_tag.rotation, theirs_in_our_frame), 0.5 * M_PI / 180.0) << trial;
    EXPECT_LT((ours->cam_from_tag.translation - t).norm(), 0.002) << trial;
    // And both against the truth.
    EXPECT_LT(RotationAngle(ours->cam_from_tag.rotation, tag.cam_from_tag.rotation), 1.0 * M_PI / 180.0) << trial;
    EXPECT_LT((ours->cam_from_tag.translation - tag.cam_from_tag.translation).norm(), 0.003) << trial;
    ++compared;
  }
  EXPECT_EQ(compared, 8);
  apriltag_detector_destroy(detector);
  tag36h11_destroy(family);
}

}  // namespace
}  // namespace reconar
