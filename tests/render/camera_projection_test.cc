// The clip transform and model placement as plain maths (no GL): the clip transform followed by
// GL's viewport mapping must give CameraIntrinsics::Project's pixel, shifted to GL's pixel centres.
#include "render/camera_projection.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "render/model_placement.h"
#include "tests/render/test_cameras.h"

namespace reconar {
namespace {

// GL's viewport transform for a viewport at (0, 0) of width x height, depth range [0, 1]; window
// row y_w = v + 0.5 in the renderer's top-row-first framebuffers.
Eigen::Vector3d WindowFromClip(const Eigen::Vector4d& clip, int width, int height) {
  const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
  return Eigen::Vector3d((ndc.x() + 1.0) * 0.5 * width, (ndc.y() + 1.0) * 0.5 * height, (ndc.z() + 1.0) * 0.5);
}

using testing::OffCentreCamera;

TEST(CameraProjectionTest, ClipTransformLandsOnProjectedPixels) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  DepthRange depth;
  depth.near_m = 0.05;
  depth.far_m = 20.0;
  const Eigen::Matrix4d clip_from_cam = ClipFromCamera(intrinsics, 640, 480, depth);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> lateral(-1.0, 1.0);
  std::uniform_real_distribution<double> distance(0.1, 15.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d cam_point(lateral(random), lateral(random), distance(random));
    const Eigen::Vector2d pixel = intrinsics.Project(cam_point);
    const Eigen::Vector3d window = WindowFromClip(clip_from_cam * cam_point.homogeneous(), 640, 480);
    EXPECT_NEAR(window.x(), pixel.x() + 0.5, 1e-9);
    EXPECT_NEAR(window.y(), pixel.y() + 0.5, 1e-9);
    EXPECT_GT(window.z(), 0.0);
    EXPECT_LT(window.z(), 1.0);
  }
  // The depth range maps to the ends of the depth buffer.
  EXPECT_NEAR(WindowFromClip(clip_from_cam * Eigen::Vector4d(0, 0, depth.near_m, 1), 640, 480).z(), 0.0, 1e-12);
  EXPECT_NEAR(WindowFromClip(clip_from_cam * Eigen::Vector4d(0, 0, depth.far_m, 1), 640, 480).z(), 1.0, 1e-12);
}

TEST(CameraProjectionTest, IntrinsicsRescaleToAnotherTargetSize) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  const CameraIntrinsics half = IntrinsicsForTarget(intrinsics, 320, 240);
  EXPECT_EQ(half.width, 320);
  EXPECT_DOUBLE_EQ(half.fx, intrinsics.fx / 2);
  // The pixel edge at 0 (u = -0.5) stays at the edge; the centre of the image stays the centre.
  EXPECT_DOUBLE_EQ(half.cx, (intrinsics.cx + 0.5) / 2 - 0.5);
  const Eigen::Vector3d point(0.1, -0.2, 2.0);
  EXPECT_NEAR((half.Project(point).x() + 0.5) * 2, intrinsics.Project(point).x() + 0.5, 1e-12);
  // Same size, or unknown size: unchanged.
  EXPECT_DOUBLE_EQ(IntrinsicsForTarget(intrinsics, 640, 480).cx, intrinsics.cx);
  CameraIntrinsics unsized = intrinsics;
  unsized.width = unsized.height = 0;
  EXPECT_DOUBLE_EQ(IntrinsicsForTarget(unsized, 320, 240).fx, intrinsics.fx);
}

TEST(CameraProjectionTest, DepthRangeCheck) {
  EXPECT_TRUE(DepthRange().Check().ok());
  DepthRange bad;
  bad.near_m = 0.0;
  EXPECT_EQ(bad.Check().code(), StatusCode::kInvalidArgument);
  bad.near_m = 5.0;
  bad.far_m = 1.0;
  EXPECT_EQ(bad.Check().code(), StatusCode::kInvalidArgument);
}

Mesh Box(const Eigen::Vector3f& low, const Eigen::Vector3f& high) {
  Mesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.positions.emplace_back((i & 1) ? high.x() : low.x(), (i & 2) ? high.y() : low.y(),
                                (i & 4) ? high.z() : low.z());
  }
  return mesh;
}

TEST(ModelPlacementTest, StandingOnTagPutsTheModelUprightOnTheTagCentre) {
  // A box 2 wide (x), 4 tall (model y is up), 1 deep, off the origin.
  const Mesh box = Box(Eigen::Vector3f(1, 10, -3), Eigen::Vector3f(3, 14, -2));
  auto placement = ModelPlacement::StandingOnTag(box, 0.2);
  ASSERT_TRUE(placement.ok()) << placement.status().ToString();
  EXPECT_DOUBLE_EQ(placement->scale, 0.05);
  const Eigen::Matrix4d tag_from_model = placement->TagFromModel();
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e9);
  Eigen::Vector3d high = -low;
  for (const Eigen::Vector3f& p : box.positions) {
    const Eigen::Vector3d in_tag = (tag_from_model * p.cast<double>().homogeneous()).head<3>();
    low = low.cwiseMin(in_tag);
    high = high.cwiseMax(in_tag);
  }
  EXPECT_NEAR(low.z(), 0.0, 1e-12);             // on the tag plane
  EXPECT_NEAR(high.z(), 0.2, 1e-12);            // the requested height along the tag's z
  EXPECT_NEAR(low.x() + high.x(), 0.0, 1e-12);  // centred on the tag
  EXPECT_NEAR(low.y() + high.y(), 0.0, 1e-12);
  EXPECT_NEAR(high.x() - low.x(), 0.1, 1e-12);   // model x stays tag x, scaled
  EXPECT_NEAR(high.y() - low.y(), 0.05, 1e-12);  // model depth becomes tag y
  EXPECT_NEAR(placement->rotation.determinant(), 1.0, 1e-12);
}

TEST(ModelPlacementTest, CamFromModelComposesTagPoseAndPlacement) {
  Rigid3 cam_from_tag;
  cam_from_tag.rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  cam_from_tag.translation = Eigen::Vector3d(0.1, -0.05, 0.8);
  ModelPlacement placement;
  placement.scale = 2.5;
  placement.rotation = Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  placement.offset = Eigen::Vector3d(0.01, 0.02, 0.03);
  const Eigen::Vector3d model_point(0.3, -0.4, 0.5);
  const Eigen::Vector3d expected =
      cam_from_tag * (placement.scale * (placement.rotation * model_point) + placement.offset);
  const Eigen::Vector4d actual = CamFromModel(cam_from_tag, placement) * model_point.homogeneous();
  EXPECT_NEAR((actual.head<3>() - expected).norm(), 0.0, 1e-12);
}

TEST(ModelPlacementTest, ScaledAndTurnedAboutTheTagNormal) {
  // Model z up: a fixed scale keeps it along the tag's z.
  const ModelPlacement scaled = ModelPlacement::Scaled(0.5, Eigen::Vector3d::UnitZ());
  EXPECT_DOUBLE_EQ(scaled.scale, 0.5);
  EXPECT_NEAR((scaled.rotation - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(scaled.offset.norm(), 0.0, 0.0);
  // Model y up (the default) becomes the tag's z.
  EXPECT_NEAR((ModelPlacement::Scaled(1.0).rotation * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 0.0,
              1e-12);

  ModelPlacement placement = scaled;
  placement.offset = Eigen::Vector3d(0.1, 0.0, 0.02);
  const ModelPlacement turned = placement.Turned(90.0, Eigen::Vector3d(0.0, 0.0, 0.01));
  EXPECT_DOUBLE_EQ(turned.scale, 0.5);
  // A quarter turn about z: x goes to y, the offset turns with the model, then the shift is added.
  EXPECT_NEAR((turned.rotation * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((turned.offset - Eigen::Vector3d(0.0, 0.1, 0.03)).norm(), 0.0, 1e-12);
}

TEST(ModelPlacementTest, RejectsUnusableInput) {
  EXPECT_EQ(ModelPlacement::StandingOnTag(Mesh(), 1.0).status().code(), StatusCode::kInvalidArgument);
  const Mesh flat = Box(Eigen::Vector3f(0, 1, 0), Eigen::Vector3f(1, 1, 1));  // no extent along y
  EXPECT_EQ(ModelPlacement::StandingOnTag(flat, 1.0).status().code(), StatusCode::kInvalidArgument);
  const Mesh box = Box(Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 1, 1));
  EXPECT_EQ(ModelPlacement::StandingOnTag(box, -1.0).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ModelPlacement::StandingOnTag(box, 1.0, Eigen::Vector3d::Zero()).status().code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace reconar
