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

// Tag 30, still, to the right of the moving tag 21.
SyntheticTag StillTag() {
  SyntheticTag tag;
  tag.id = 30;
  tag.size = 0.08;
  tag.cam_from_tag.rotation = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  tag.cam_from_tag.translation = Eigen::Vector3d(0.15, 0.1, 0.6);
  return tag;
}

// A tag entering the view is found in the frame it appears by the predicted search, while only
// the regions of the followed tag are searched (no full-frame search is due).
TEST(TagTrackerTest, PredictedSearchFindsATagEnteringTheViewInTheSameFrame) {
  const CameraIntrinsics camera = TestCamera();
  auto tracker = TagTracker::Create(TestOptions());  // full_frame_interval 0: never periodic
  ASSERT_TRUE(tracker.ok());
  TagTrackerFrameReport report;
  PredictedTag predicted;
  predicted.id = 30;
  predicted.cam_from_tag = StillTag().cam_from_tag;
  // The caller's prediction is off by 1 cm and 2 degrees.
  predicted.cam_from_tag.translation += Eigen::Vector3d(0.01, -0.005, 0.005);
  predicted.cam_from_tag.rotation = Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix() *
                                    predicted.cam_from_tag.rotation;
  for (int frame = 0; frame < 6; ++frame) {
    const SyntheticTag tags[2] = {MovingTag(frame), StillTag()};
    const Image<uint8_t> image = RenderTags(tags, frame >= 3 ? 2 : 1, camera, SyntheticRenderOptions());
    ASSERT_TRUE((*tracker)->Track(image.view(), &report).ok());
    EXPECT_EQ(report.search == TagTrackerFrameReport::Search::kFullFrame, frame == 0) << frame;
    const size_t followed_before = report.tags.size();
    EXPECT_EQ(followed_before, frame > 3 ? 2u : 1u) << frame;  // Track alone does not find tag 30
    ASSERT_TRUE((*tracker)->SearchPredicted(image.view(), &predicted, 1, &report).ok());
    EXPECT_EQ(report.search == TagTrackerFrameReport::Search::kRegions, frame > 0) << frame;
    const TrackedTag* found = nullptr;
    for (const TrackedTag& t : report.tags) found = t.id == 30 && t.measured ? &t : found;
    if (frame < 3) {
      EXPECT_EQ(found, nullptr) << frame;
      // Searched where it would be (not there) once only regions are searched: the full-frame
      // search of frame 0 looked there at the resolution the region would have.
      EXPECT_EQ(report.predicted_searched, frame == 0 ? 0 : 1) << frame;
      EXPECT_EQ(report.predicted_found, 0) << frame;
      continue;
    }
    ASSERT_NE(found, nullptr) << frame;
    if (frame == 3) {
      EXPECT_EQ(report.predicted_searched, 1);
      EXPECT_EQ(report.predicted_found, 1);
      EXPECT_TRUE(found->found_by_prediction);
      EXPECT_EQ(found->state, TagTrackState::kTracking);
      const std::array<Eigen::Vector2d, 4> truth = ProjectedCorners(StillTag(), camera);
      for (int k = 0; k < 4; ++k) EXPECT_LT((found->detection.corners[k] - truth[k]).norm(), 0.3);
    } else {
      // From the next frame on it is followed in its own region; the prediction is not searched.
      EXPECT_FALSE(found->found_by_prediction) << frame;
      EXPECT_TRUE(found->found_in_region) << frame;
      EXPECT_EQ(report.predicted_searched, 0) << frame;
    }
  }
}

// Predicted tags that cannot be in view are not searched: behind the camera, seen from the back,
// outside the frame, too small; an id already measured in the frame is not searched again.
TEST(TagTrackerTest, PredictedSearchSkipsTagsOutOfView) {
  const CameraIntrinsics camera = TestCamera();
  TagTrackerOptions options = TestOptions();
  auto tracker = TagTracker::Create(options);
  ASSERT_TRUE(tracker.ok());
  TagTrackerFrameReport report;
  const SyntheticTag tag = MovingTag(0);
  const Image<uint8_t> image = RenderTags(&tag, 1, camera, SyntheticRenderOptions());
  ASSERT_TRUE((*tracker)->Track(image.view(), &report).ok());
  ASSERT_TRUE((*tracker)->Track(image.view(), &report).ok());
  ASSERT_EQ(report.search, TagTrackerFrameReport::Search::kRegions);
  PredictedTag predicted[6];
  for (int i = 0; i < 6; ++i) {
    predicted[i].id = 40 + i;
    predicted[i].cam_from_tag = StillTag().cam_from_tag;
  }
  predicted[0].cam_from_tag.translation.z() = -0.6;                  // behind the camera
  predicted[1].cam_from_tag.rotation = Eigen::Matrix3d::Identity();  // its back toward the camera
  predicted[2].cam_from_tag.translation.x() = 2.0;                   // far right of the frame
  predicted[3].cam_from_tag.translation.z() = 6.0;                   // 8 px wide
  predicted[4].id = 21;                                              // measured already
  // predicted[5] is in view (though not in the image): the one searched.
  ASSERT_TRUE((*tracker)->SearchPredicted(image.view(), predicted, 6, &report).ok());
  EXPECT_EQ(report.predicted_searched, 1);
  EXPECT_EQ(report.predicted_found, 0);
  ASSERT_EQ(report.tags.size(), 1u);
  EXPECT_TRUE(report.tags[0].measured);
  // A frame of another size than the tracked one is refused.
  const Image<uint8_t> small(320, 240, 1);
  EXPECT_EQ((*tracker)->SearchPredicted(small.view(), predicted, 5, &report).code(), StatusCode::kInvalidArgument);
}

// A tag predicted while lost is re-acquired by the predicted search (its miss of the frame undone).
TEST(TagTrackerTest, PredictedSearchReacquiresALostTag) {
  const CameraIntrinsics camera = TestCamera();
  TagTrackerOptions options = TestOptions();
  auto tracker = TagTracker::Create(options);
  ASSERT_TRUE(tracker.ok());
  TagTrackerFrameReport report;
  const SyntheticTag tags[2] = {StillTag(), MovingTag(0)};
  const Image<uint8_t> both = RenderTags(tags, 2, camera, SyntheticRenderOptions());
  const Image<uint8_t> only_21 = RenderTags(&tags[1], 1, camera, SyntheticRenderOptions());
  ASSERT_TRUE((*tracker)->Track(both.view(), &report).ok());
  for (int frame = 0; frame < 4; ++frame) ASSERT_TRUE((*tracker)->Track(only_21.view(), &report).ok());
  ASSERT_TRUE((*tracker)->Track(both.view(), &report).ok());  // tag 30 lost: regions of 21 only
  const auto find = [&](int id) -> const TrackedTag* {
    for (const TrackedTag& t : report.tags) {
      if (t.id == id) return &t;
    }
    return nullptr;
  };
  ASSERT_NE(find(30), nullptr);
  EXPECT_EQ(find(30)->state, TagTrackState::kLost);
  EXPECT_EQ(find(30)->missed_frames, 5);
  PredictedTag predicted;
  predicted.id = 30;
  predicted.cam_from_tag = StillTag().cam_from_tag;
  ASSERT_TRUE((*tracker)->SearchPredicted(both.view(), &predicted, 1, &report).ok());
  ASSERT_NE(find(30), nullptr);
  EXPECT_TRUE(find(30)->measured);
  EXPECT_TRUE(find(30)->reacquired);
  EXPECT_TRUE(find(30)->found_by_prediction);
  EXPECT_EQ(find(30)->missed_frames, 0);
  EXPECT_EQ(find(30)->state, TagTrackState::kTracking);
  EXPECT_EQ(report.predicted_found, 1);
}

// With max_tags tracks, a new id takes the place of the track lost the longest; it is dropped only
// while every track is tracking or searching.
TEST(TagTrackerTest, ANewIdReplacesALostTrackWhenAllAreUsed) {
  const CameraIntrinsics camera = TestCamera();
  TagTrackerOptions options = TestOptions();
  options.max_tags = 1;
  auto tracker = TagTracker::Create(options);
  ASSERT_TRUE(tracker.ok());
  TagTrackerFrameReport report;
  const SyntheticTag tag_21 = MovingTag(0);
  const SyntheticTag tag_30 = StillTag();
  const Image<uint8_t> image_21 = RenderTags(&tag_21, 1, camera, SyntheticRenderOptions());
  const Image<uint8_t> image_30 = RenderTags(&tag_30, 1, camera, SyntheticRenderOptions());
  ASSERT_TRUE((*tracker)->Track(image_21.view(), &report).ok());
  for (int frame = 0; frame < 4; ++frame) {
    ASSERT_TRUE((*tracker)->Track(image_30.view(), &report).ok());
    ASSERT_EQ(report.tags.size(), 1u);
    if (frame < 2) {  // 21 is searching (missed 1, 2 frames): 30 is dropped
      EXPECT_EQ(report.tags[0].id, 21) << frame;
      EXPECT_EQ(report.tags_dropped, 1) << frame;
    } else if (frame == 2) {  // 21 lost at this frame's end: 30 still dropped in this frame
      EXPECT_EQ(report.tags[0].id, 21);
      EXPECT_EQ(report.tags[0].state, TagTrackState::kLost);
    } else {  // 30 takes 21's place
      EXPECT_EQ(report.tags[0].id, 30);
      EXPECT_TRUE(report.tags[0].measured);
      EXPECT_EQ(report.tags_dropped, 0);
    }
  }
}

}  // namespace
}  // namespace reconar
