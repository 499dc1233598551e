#include "tracker/tag_tracker.h"

#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "tests/tracker/synthetic_tag_image.h"

namespace reconar {
namespace {

using testing::ProjectedCorners;
using testing::RenderTags;
using testing::SyntheticRenderOptions;
using testing::SyntheticTag;
using testing::TestCamera;

// Tag 21 sliding and turning slowly in front of the camera.
SyntheticTag MovingTag(int frame) {
  SyntheticTag tag;
  tag.id = 21;
  tag.size = 0.08;
  tag.cam_from_tag.rotation =
      Eigen::AngleAxisd(0.3 + 0.02 * frame, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix() *
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  tag.cam_from_tag.translation = Eigen::Vector3d(-0.08 + 0.006 * frame, 0.02 - 0.002 * frame, 0.5);
  return tag;
}

TagTrackerOptions TestOptions() {
  TagTrackerOptions options;
  options.intrinsics = TestCamera();
  options.tag_size = 0.08;
  options.lost_after_missed_frames = 3;
  options.full_frame_interval = 0;
  return options;
}

TEST(TagTrackerTest, RejectsBadOptions) {
  TagTrackerOptions options = TestOptions();
  options.tag_size = 0.0;
  EXPECT_FALSE(TagTracker::Create(options).ok());
  options = TestOptions();
  options.intrinsics = CameraIntrinsics();
  EXPECT_FALSE(TagTracker::Create(options).ok());
  options = TestOptions();
  options.rotation_alpha = 0.0;
  EXPECT_FALSE(TagTracker::Create(options).ok());
}

// Tracking -> (tag removed) searching -> lost -> (tag back) re-acquired -> tracking, with the
// regions searched while tracking and the poses close to the truth.
TEST(TagTrackerTest, StatesFollowTheTagDisappearingAndComingBack) {
  const CameraIntrinsics camera = TestCamera();
  auto tracker = TagTracker::Create(TestOptions());
  ASSERT_TRUE(tracker.ok());
  TagTrackerFrameReport report;
  SyntheticRenderOptions render;
  render.blur_sigma = 0.6;
  const Image<uint8_t> empty = RenderTags(nullptr, 0, camera, render);
  for (int frame = 0; frame < 20; ++frame) {
    const bool visible = frame < 8 || frame >= 13;  // gone for 5 frames
    const SyntheticTag tag = MovingTag(frame);
    const Image<uint8_t> image = visible ? RenderTags(&tag, 1, camera, render) : empty;
    ASSERT_TRUE((*tracker)->Track(image.view(), &report).ok());
    ASSERT_EQ(report.tags.size(), 1u) << frame;
    const TrackedTag& t = report.tags[0];
    EXPECT_EQ(t.id, 21);
    EXPECT_EQ(t.measured, visible) << frame;
    if (visible) {
      EXPECT_EQ(t.state, TagTrackState::kTracking) << frame;
      EXPECT_EQ(t.reacquired, frame == 13) << frame;
      // Regions from the second frame on, and again once re-acquired.
      const bool expect_regions = frame >= 1 && frame != 13 && frame != 8;
      EXPECT_EQ(report.search == TagTrackerFrameReport::Search::kRegions, expect_regions) << frame;
      EXPECT_EQ(t.found_in_region, expect_regions) << frame;
      const std::array<Eigen::Vector2d, 4> truth = ProjectedCorners(tag, camera);
      for (int k = 0; k < 4; ++k) EXPECT_LT((t.detection.corners[k] - truth[k]).norm(), 0.3) << frame;
      EXPECT_LT(RotationAngle(t.cam_from_tag.rotation, tag.cam_from_tag.rotation), 1.5 * M_PI / 180.0) << frame;
      EXPECT_LT((t.cam_from_tag.translation - tag.cam_from_tag.translation).norm(), 0.003) << frame;
      // The smoothed pose stays near the measurement for this slow motion.
      EXPECT_LT((t.smoothed_cam_from_tag.translation - tag.cam_from_tag.translation).norm(), 0.01) << frame;
    } else {
      const int missed = frame - 7;
      EXPECT_EQ(t.missed_frames, missed);
      EXPECT_EQ(t.state, missed >= 3 ? TagTrackState::kLost : TagTrackState::kSearching) << frame;
      // A missed region search falls back to the full frame; once lost, only the full frame is searched.
      EXPECT_EQ(report.search, missed >= 4 ? TagTrackerFrameReport::Search::kFullFrame
                                           : TagTrackerFrameReport::Search::kRegionsThenFullFrame)
          << frame;
    }
  }
}

TEST(TagTrackerTest, PeriodicFullFrameSearchFindsANewTag) {
  const CameraIntrinsics camera = TestCamera();
  TagTrackerOptions options = TestOptions();
  options.full_frame_interval = 4;
  auto tracker = TagTracker::Create(options);
  ASSERT_TRUE(tracker.ok());
  TagTrackerFrameReport report;
  SyntheticTag second;
  second.id = 30;
  second.size = 0.08;
  second.cam_from_tag.rotation = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  second.cam_from_tag.translation = Eigen::Vector3d(0.15, 0.1, 0.6);
  for (int frame = 0; frame < 9; ++frame) {
    const SyntheticTag tags[2] = {MovingTag(frame), second};
    const Image<uint8_t> image = RenderTags(tags, frame >= 2 ? 2 : 1, camera, SyntheticRenderOptions());
    ASSERT_TRUE((*tracker)->Track(image.view(), &report).ok());
    const size_t expected_tags = frame >= 4 ? 2u : 1u;  // tag 30 appears at 2, found by the search at 4
    EXPECT_EQ(report.tags.size(), expected_tags) << frame;
    EXPECT_EQ(report.search == TagTrackerFrameReport::Search::kFullFrame, frame % 4 == 0) << frame;
  }
}

}  // namespace
}  // namespace reconar
