#include "core/sfm/mapper_adjustment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/math/rotation.h"
#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

TEST(MapperAdjustmentTest, ExactModelRoundTripsUnchanged) {
  const testing::Scene scene = testing::MakeExactScene(6, 400);
  MapperModel model = testing::TrueModel(scene);
  const MapperModel before = model;
  MapperReport report;
  MapperAdjustment adjustment;
  adjustment.iterations = 20;
  adjustment.free.distortion = true;
  const Result<double> cost =
      BundleAdjust(&model, scene.images, model.RegisteredImages(), adjustment, testing::SingleThreaded(), &report);
  ASSERT_TRUE(cost.ok()) << cost.status().ToString();
  EXPECT_LT(cost.value(), 1e-12);
  EXPECT_EQ(report.num_global_ba, 1);
  EXPECT_EQ(report.num_local_ba, 0);
  EXPECT_EQ(report.num_failed_ba, 0);
  // The 12-double blocks carry every intrinsic and pose back (angle-axis round trip included).
  const SfmCamera& cam = model.rec.cameras[0];
  EXPECT_NEAR(cam.focal, scene.camera.focal, 1e-6);
  EXPECT_NEAR(cam.k1, scene.camera.k1, 1e-9);
  EXPECT_EQ(cam.cx, scene.camera.cx);
  EXPECT_EQ(cam.cy, scene.camera.cy);
  EXPECT_EQ(cam.aspect, scene.camera.aspect);
  for (size_t i = 0; i < model.rec.images.size(); ++i) {
    const Rigid3& pose = model.rec.images[i].cam_from_world;
    EXPECT_LT((pose.rotation - scene.poses[i].rotation).norm(), 1e-9) << "image " << i;
    EXPECT_LT((pose.translation - scene.poses[i].translation).norm(), 1e-8) << "image " << i;
  }
  for (size_t p = 0; p < model.rec.points.size(); ++p) {
    EXPECT_LT((model.rec.points[p].position - before.rec.points[p].position).norm(), 1e-8) << "point " << p;
  }
}

TEST(MapperAdjustmentTest, RecoversPerturbedPosesAndHoldsTheOthersConstant) {
  const testing::Scene scene = testing::MakeExactScene(6, 400);
  MapperModel model = testing::TrueModel(scene);
  const std::vector<int> variable = {2, 3, 4, 5};  // 0 and 1 fix the gauge (and the scale)
  for (int image : variable) {
    Rigid3& pose = model.rec.images[static_cast<size_t>(image)].cam_from_world;
    pose.rotation = RotationFromAngleAxis(Eigen::Vector3d(0.01, -0.008, 0.005 * image)) * pose.rotation;
    pose.translation += Eigen::Vector3d(0.05, -0.03, 0.02 * image);
  }
  for (size_t p = 0; p < model.rec.points.size(); ++p) {
    model.rec.points[p].position += 0.01 * Eigen::Vector3d(std::sin(p), std::cos(p), std::sin(2.0 * p));
  }
  const MapperModel before = model;
  MapperReport report;
  MapperAdjustment adjustment;
  adjustment.iterations = 100;
  adjustment.function_tolerance = 1e-14;
  const Result<double> cost =
      BundleAdjust(&model, scene.images, variable, adjustment, testing::SingleThreaded(), &report);
  ASSERT_TRUE(cost.ok()) << cost.status().ToString();
  EXPECT_LT(cost.value(), 1e-6);
  EXPECT_EQ(report.num_local_ba, 1);
  for (int image : variable) {
    const Rigid3& pose = model.rec.images[static_cast<size_t>(image)].cam_from_world;
    EXPECT_LT((pose.rotation - scene.poses[static_cast<size_t>(image)].rotation).norm(), 1e-5) << "image " << image;
    EXPECT_LT((pose.translation - scene.poses[static_cast<size_t>(image)].translation).norm(), 1e-4)
        << "image " << image;
  }
  for (int image : {0, 1}) {
    EXPECT_EQ(model.rec.images[static_cast<size_t>(image)].cam_from_world.rotation,
              before.rec.images[static_cast<size_t>(image)].cam_from_world.rotation);
    EXPECT_EQ(model.rec.images[static_cast<size_t>(image)].cam_from_world.translation,
              before.rec.images[static_cast<size_t>(image)].cam_from_world.translation);
  }
  // A local adjustment of a shared camera holds the intrinsics.
  EXPECT_EQ(model.rec.cameras[0].focal, before.rec.cameras[0].focal);
  EXPECT_EQ(model.rec.cameras[0].k1, before.rec.cameras[0].k1);
}

TEST(MapperAdjustmentTest, NumericFailureReturnsAStatusAndLeavesTheModelUnchanged) {
  const testing::Scene scene = testing::MakeExactScene(6, 400);
  MapperModel model = testing::TrueModel(scene);
  // A keypoint that is not a number makes the initial cost non-finite.
  const TrackElement e = model.rec.points[0].track[0];
  model.rec.images[static_cast<size_t>(e.image_id)].keypoints[static_cast<size_t>(e.keypoint_id)].x() =
      std::numeric_limits<double>::quiet_NaN();
  for (size_t i = 0; i < model.rec.images.size(); ++i) {
    model.rec.images[i].cam_from_world.translation.x() += 0.01;  // something to adjust
  }
  const MapperModel before = model;
  MapperReport report;
  MapperAdjustment adjustment;
  adjustment.iterations = 10;
  const Result<double> cost =
      BundleAdjust(&model, scene.images, model.RegisteredImages(), adjustment, testing::SingleThreaded(), &report);
  ASSERT_FALSE(cost.ok());
  EXPECT_EQ(cost.status().code(), StatusCode::kNumericFailure);
  EXPECT_NE(cost.status().message().find("numeric failure"), std::string::npos) << cost.status().message();
  testing::ExpectIdenticalModels(model.rec, before.rec);
  EXPECT_EQ(report.num_global_ba, 1);  // it ran

  // Counted, the first message kept, the mapper carries on.
  EXPECT_TRUE(CountFailedAdjustment(cost.status(), &report).ok());
  EXPECT_TRUE(CountFailedAdjustment(NumericFailure("second"), &report).ok());
  EXPECT_EQ(report.num_failed_ba, 2);
  EXPECT_EQ(report.first_ba_failure, cost.status().message());
}

TEST(MapperAdjustmentTest, InvalidOptionsAreAnErrorThatIsNotCounted) {
  const testing::Scene scene = testing::MakeExactScene(6, 400);
  MapperModel model = testing::TrueModel(scene);
  for (size_t i = 0; i < model.rec.images.size(); ++i) model.rec.images[i].cam_from_world.translation.y() += 0.01;
  const MapperModel before = model;
  MapperReport report;
  MapperAdjustment adjustment;
  adjustment.iterations = 10;
  adjustment.function_tolerance = -1.0;
  const Result<double> cost =
      BundleAdjust(&model, scene.images, model.RegisteredImages(), adjustment, testing::SingleThreaded(), &report);
  ASSERT_FALSE(cost.ok());
  EXPECT_EQ(cost.status().code(), StatusCode::kInvalidArgument);
  testing::ExpectIdenticalModels(model.rec, before.rec);
  const Status counted = CountFailedAdjustment(cost.status(), &report);
  EXPECT_EQ(counted.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(report.num_failed_ba, 0);
  EXPECT_TRUE(CountFailedAdjustment(Status::Ok(), &report).ok());
  EXPECT_EQ(report.num_failed_ba, 0);
}

TEST(MapperAdjustmentTest, LocalBundleIsTheImageAndItsBestConnectedNeighbours) {
  const testing::Scene scene = testing::MakeExactScene(6, 400);
  const MapperModel model = testing::TrueModel(scene);
  MapperOptions options;
  options.local_ba_images = 2;
  const std::vector<int> local = LocalBundle(model, 0, options);
  ASSERT_EQ(local.size(), 3u);
  EXPECT_EQ(local[0], 0);
  // Points image 0 shares with each image, counted from the points' observations.
  std::vector<int> shared(scene.images.size(), 0);
  for (const SfmPoint& point : model.rec.points) {
    bool in0 = false;
    for (const TrackElement& e : point.track) in0 = in0 || e.image_id == 0;
    for (const TrackElement& e : point.track) shared[static_cast<size_t>(e.image_id)] += in0 ? 1 : 0;
  }
  EXPECT_GE(shared[static_cast<size_t>(local[1])], shared[static_cast<size_t>(local[2])]);
  for (size_t i = 1; i < scene.images.size(); ++i) {
    if (static_cast<int>(i) == local[1] || static_cast<int>(i) == local[2]) continue;
    EXPECT_LE(shared[i], shared[static_cast<size_t>(local[2])]) << "image " << i;
  }
}

}  // namespace
}  // namespace reconar
