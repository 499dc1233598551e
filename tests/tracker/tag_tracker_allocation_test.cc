// The tracking loop makes no heap allocation (operator new) in steady state. libapriltag's own C
// malloc calls inside apriltag_detector_detect are not operator new and are not counted.
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "tests/support/allocation_counter.h"
#include "tests/tracker/synthetic_tag_image.h"
#include "tracker/tag_pose.h"
#include "tracker/tag_tracker.h"

namespace reconar {
namespace {

TEST(TagTrackerAllocationTest, SteadyStateTrackingDoesNotAllocate) {
  const CameraIntrinsics camera = testing::TestCamera();
  std::vector<Image<uint8_t>> frames;
  std::vector<testing::SyntheticTag> truth;
  // Tag 9 enters the view at frame 14 (not a periodic full-frame frame); every frame the caller predicts it
  // (SearchPredicted).
  testing::SyntheticTag entering;
  entering.id = 9;
  entering.size = 0.07;
  entering.cam_from_tag.rotation = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  entering.cam_from_tag.translation = Eigen::Vector3d(0.0, -0.12, 0.6);
  PredictedTag predicted;
  predicted.id = entering.id;
  predicted.cam_from_tag = entering.cam_from_tag;
  for (int frame = 0; frame < 24; ++frame) {
    testing::SyntheticTag tags[3];
    for (int i = 0; i < 2; ++i) {
      tags[i].id = 4 + i;
      tags[i].size = 0.07;
      tags[i].cam_from_tag.rotation =
          Eigen::AngleAxisd(0.2 + 0.01 * frame, Eigen::Vector3d(0.1, 1.0, 0.3).normalized()).toRotationMatrix() *
          Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
      tags[i].cam_from_tag.translation = Eigen::Vector3d(-0.1 + 0.2 * i + 0.003 * frame, 0.01 * i, 0.55);
    }
    tags[2] = entering;
    frames.push_back(testing::RenderTags(tags, frame >= 14 ? 3 : 2, camera, testing::SyntheticRenderOptions()));
  }
  TagTrackerOptions options;
  options.intrinsics = camera;
  options.tag_size = 0.07;
  options.full_frame_interval = 6;  // the periodic full-frame path is exercised too
  auto tracker = TagTracker::Create(options);
  ASSERT_TRUE(tracker.ok());
  TagTrackerFrameReport report;
  for (int frame = 0; frame < 4; ++frame) ASSERT_TRUE((*tracker)->Track(frames[frame].view(), &report).ok());
  long allocations = -1;
  int measured = 0, region_frames = 0, full_frames = 0, predicted_searched = 0, predicted_found = 0;
  {
    testing::NoAllocationScope scope;
    for (size_t frame = 4; frame < frames.size(); ++frame) {
      const Status status = (*tracker)->Track(frames[frame].view(), &report);
      if (!status.ok()) break;
      if (!(*tracker)->SearchPredicted(frames[frame].view(), &predicted, 1, &report).ok()) break;
      predicted_searched += report.predicted_searched;
      predicted_found += report.predicted_found;
      for (const TrackedTag& t : report.tags) measured += t.measured;
      region_frames += report.search == TagTrackerFrameReport::Search::kRegions;
      full_frames += report.search != TagTrackerFrameReport::Search::kRegions;
    }
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(measured, 2 * 20 + 10);  // tag 9 from frame 14 on
  EXPECT_GT(predicted_searched, 5);
  EXPECT_EQ(predicted_found, 1);  // found by prediction when it enters, then followed
  EXPECT_GT(region_frames, 10);
  EXPECT_GT(full_frames, 0);
}

// The counter does see operator new inside a scope (so the zeros above mean something).
TEST(TagTrackerAllocationTest, CounterSeesOperatorNew) {
  long allocations = -1;
  // The block's address goes through a volatile pointer that is read: clang may otherwise elide an
  // allocation nobody uses (C++14 [expr.new]).
  int* volatile published = nullptr;
  {
    testing::NoAllocationScope scope;
    std::vector<int> storage(16);
    published = storage.data();
    allocations = scope.allocations();
  }
  EXPECT_NE(published, nullptr);
  EXPECT_EQ(allocations, 1);
}

TEST(TagTrackerAllocationTest, PoseEstimationDoesNotAllocate) {
  CameraIntrinsics camera;
  camera.fx = camera.fy = 600.0;
  camera.cx = 320.0;
  camera.cy = 240.0;
  camera.k1 = -0.1;
  const Eigen::Vector2d corners[4] = {{280, 270}, {362, 268}, {360, 190}, {282, 195}};
  long allocations = -1;
  double rms = -1.0;
  {
    testing::NoAllocationScope scope;
    const Result<TagPose> pose = EstimateTagPose(corners, 0.1, camera);
    rms = pose.ok() ? pose->rms_reprojection_px : -2.0;
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_GE(rms, 0.0);
}

}  // namespace
}  // namespace reconar
