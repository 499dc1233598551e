#include "tracker/board_pose.h"

#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "tests/tracker/synthetic_tag_image.h"

namespace reconar {
namespace {

using testing::RenderTags;
using testing::SyntheticRenderOptions;
using testing::SyntheticTag;

CameraIntrinsics TestCamera() {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = camera.fy = 620.0;
  camera.cx = 320.0;
  camera.cy = 240.0;
  return camera;
}

// Renders the layout's tags under cam_from_layout and checks the recovered pose.
void CheckBoardPose(const TagLayout& layout, const Rigid3& cam_from_layout, double max_rotation_deg,
                    double max_translation_m) {
  const CameraIntrinsics camera = TestCamera();
  std::vector<SyntheticTag> tags;
  for (const LayoutTag& t : layout.tags()) {
    SyntheticTag tag;
    tag.id = t.id;
    tag.size = t.size;
    tag.cam_from_tag = cam_from_layout * t.layout_from_tag;
    tags.push_back(tag);
  }
  SyntheticRenderOptions render;
  render.blur_sigma = 0.5;
  const Image<uint8_t> image = RenderTags(tags.data(), static_cast<int>(tags.size()), camera, render);
  TagDetectorOptions options;
  options.quad_decimate = 1.0f;
  auto detector = TagDetector::Create(options);
  ASSERT_TRUE(detector.ok());
  TagDetectionList detections(16);
  ASSERT_TRUE((*detector)->Detect(image.view(), &detections).ok());
  ASSERT_EQ(detections.size(), static_cast<int>(tags.size()));
  const Result<BoardPose> board = EstimateBoardPose(layout, detections, camera);
  ASSERT_TRUE(board.ok()) << board.status().ToString();
  EXPECT_EQ(board->tags_used, static_cast<int>(tags.size()));
  EXPECT_LT(RotationAngle(board->cam_from_layout.rotation, cam_from_layout.rotation) * 180.0 / M_PI,
            max_rotation_deg);
  EXPECT_LT((board->cam_from_layout.translation - cam_from_layout.translation).norm(), max_translation_m);
  EXPECT_LT(board->rms_reprojection_px, 0.3);
}

TEST(BoardPoseTest, PlanarBoardPoseFromAllCorners) {
  const Result<TagLayout> layout =
      ParseTagLayout("0 0.06 -0.05 -0.05\n1 0.06 0.05 -0.05 90\n2 0.06 0.05 0.05\n3 0.06 -0.05 0.05 -30\n", "board");
  ASSERT_TRUE(layout.ok());
  Rigid3 cam_from_layout;
  cam_from_layout.rotation = Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix() *
                             Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  cam_from_layout.translation = Eigen::Vector3d(0.01, -0.02, 0.45);
  CheckBoardPose(*layout, cam_from_layout, 0.3, 0.002);
}

TEST(BoardPoseTest, NonPlanarLayoutPoseFromAllCorners) {
  // Two tags on the faces of a box corner, 90 deg apart.
  const Result<TagLayout> layout = ParseTagLayout(
      "4 0.06 0.05 0 0 1 0 0 0\n"
      "5 0.06 0 0 -0.05 0.7071067811865476 0 -0.7071067811865476 0\n",
      "corner");
  ASSERT_TRUE(layout.ok());
  EXPECT_FALSE(layout->IsPlanar());
  Rigid3 cam_from_layout;
  cam_from_layout.rotation = Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()).toRotationMatrix() *
                             Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  cam_from_layout.translation = Eigen::Vector3d(0.0, 0.0, 0.4);
  CheckBoardPose(*layout, cam_from_layout, 0.3, 0.002);
}

TEST(BoardPoseTest, NeedsALayoutTag) {
  const Result<TagLayout> layout = ParseTagLayout("0 0.06 0 0\n", "board");
  ASSERT_TRUE(layout.ok());
  TagDetectionList none(4);
  EXPECT_EQ(EstimateBoardPose(*layout, none, TestCamera()).status().code(), StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace reconar
