// TagPoseSource: the world from one chosen tag or from a layout of tags, on synthetic frames of two
// tags at known poses; and no heap allocation per frame in steady state.
#include "tracker/tag_pose_source.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <vector>

#include "tests/support/allocation_counter.h"
#include "tests/tracker/synthetic_tag_image.h"

namespace reconar {
namespace {

constexpr double kTagSize = 0.07;

// cam_from_tag of tag 4 + i in frame `frame`: two tags side by side on one plane (a board whose
// layout is tags 4 and 5, 0.2 m apart along x) moving slowly.
Rigid3 CamFromTag(int i, int frame) {
  Rigid3 cam_from_board;
  cam_from_board.rotation =
      Eigen::AngleAxisd(0.2 + 0.01 * frame, Eigen::Vector3d(0.1, 1.0, 0.3).normalized()).toRotationMatrix() *
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  cam_from_board.translation = Eigen::Vector3d(0.003 * frame, 0.0, 0.55);
  Rigid3 board_from_tag;
  board_from_tag.translation = Eigen::Vector3d(-0.1 + 0.2 * i, 0.0, 0.0);
  return cam_from_board * board_from_tag;
}

// Frames of the two tags; tag 5 only from frame `second_from` on.
std::vector<Image<uint8_t>> Frames(int count, int second_from = 0) {
  std::vector<Image<uint8_t>> frames;
  for (int frame = 0; frame < count; ++frame) {
    testing::SyntheticTag tags[2];
    for (int i = 0; i < 2; ++i) {
      tags[i].id = 4 + i;
      tags[i].size = kTagSize;
      tags[i].cam_from_tag = CamFromTag(i, frame);
    }
    frames.push_back(testing::RenderTags(tags, frame >= second_from ? 2 : 1, testing::TestCamera(),
                                         testing::SyntheticRenderOptions()));
  }
  return frames;
}

// Tags 4 and 5 of the frames, and with `tags` 3 also tag 6 between them, 0.1 m lower (in view, never
// drawn).
TagLayout Board(int tags = 2) {
  TagLayout layout;
  for (int i = 0; i < tags; ++i) {
    LayoutTag tag;
    tag.id = 4 + i;
    tag.size = kTagSize;
    tag.layout_from_tag.translation =
        i < 2 ? Eigen::Vector3d(-0.1 + 0.2 * i, 0.0, 0.0) : Eigen::Vector3d(0.0, -0.1, 0.0);
    EXPECT_TRUE(layout.Add(tag).ok());
  }
  return layout;
}

TagPoseSourceOptions Options() {
  TagPoseSourceOptions options;
  options.tracker.intrinsics = testing::TestCamera();
  options.tracker.tag_size = kTagSize;
  return options;
}

TEST(TagPoseSourceTest, OneTagIsTheLowestIdOrTheChosenOne) {
  const std::vector<Image<uint8_t>> frames = Frames(3);
  for (const int wanted : {-1, 5}) {
    TagPoseSourceOptions options = Options();
    options.tag_id = wanted;
    auto source = TagPoseSource::Create(options);
    ASSERT_TRUE(source.ok()) << source.status().ToString();
    WorldPose pose;
    for (int frame = 0; frame < 3; ++frame) {
      ASSERT_TRUE((*source)->Track(frames[frame].view(), &pose).ok());
      ASSERT_TRUE(pose.found);
      const int expected_id = wanted < 0 ? 4 : wanted;
      ASSERT_EQ(pose.markers.size(), 1u);
      EXPECT_EQ(pose.markers[0].id, expected_id);
      EXPECT_EQ(pose.markers[0].size, kTagSize);
      EXPECT_TRUE(pose.markers[0].layout_from_tag.rotation.isIdentity(0.0));
      EXPECT_EQ(pose.anchors_used, 1);
      EXPECT_EQ(pose.track_ms, (*source)->report().total_ms);
      const TrackedTag* tag = nullptr;
      for (const TrackedTag& t : (*source)->report().tags) tag = t.id == expected_id ? &t : tag;
      ASSERT_NE(tag, nullptr);
      EXPECT_EQ(pose.cam_from_world.translation, tag->cam_from_tag.translation);  // the measured pose itself
      EXPECT_NEAR((pose.cam_from_world.translation - CamFromTag(expected_id - 4, frame).translation).norm(), 0.0, 2e-3);
      EXPECT_EQ((*source)->board(), nullptr);
    }
  }
}

TEST(TagPoseSourceTest, SmoothedUsesTheFilteredPose) {
  const std::vector<Image<uint8_t>> frames = Frames(3);
  TagPoseSourceOptions options = Options();
  options.smoothed = true;
  auto source = TagPoseSource::Create(options);
  ASSERT_TRUE(source.ok());
  WorldPose pose;
  for (const Image<uint8_t>& frame : frames) ASSERT_TRUE((*source)->Track(frame.view(), &pose).ok());
  ASSERT_TRUE(pose.found);
  EXPECT_EQ(pose.cam_from_world.translation, (*source)->report().tags.front().smoothed_cam_from_tag.translation);
}

TEST(TagPoseSourceTest, LayoutWorldIsTheBoardPoseOfAllItsTagsInView) {
  const std::vector<Image<uint8_t>> frames = Frames(3);
  TagPoseSourceOptions options = Options();
  options.layout = Board();
  auto source = TagPoseSource::Create(options);
  ASSERT_TRUE(source.ok());
  WorldPose pose;
  for (int frame = 0; frame < 3; ++frame) {
    ASSERT_TRUE((*source)->Track(frames[frame].view(), &pose).ok());
    ASSERT_TRUE(pose.found);
    const BoardPose* board = (*source)->board();
    ASSERT_NE(board, nullptr);
    EXPECT_EQ(board->tags_used, 2);
    EXPECT_EQ(pose.anchors_used, 2);
    EXPECT_EQ(pose.rms_reprojection_px, board->rms_reprojection_px);
    EXPECT_EQ(pose.cam_from_world.translation, board->cam_from_layout.translation);
    ASSERT_EQ(pose.markers.size(), 2u);
    EXPECT_EQ(pose.markers[0].id, 4);
    EXPECT_EQ(pose.markers[1].id, 5);
    // The board's origin (between the tags) in the camera frame.
    const Eigen::Vector3d origin = CamFromTag(0, frame) * Eigen::Vector3d(0.1, 0.0, 0.0);
    EXPECT_NEAR((pose.cam_from_world.translation - origin).norm(), 0.0, 2e-3);
  }
}

// Tag 5 enters the view at frame 3 while only tag 4's region is searched: the board pose from tag 4
// predicts it and it is found in that frame, and the board pose then uses both.
TEST(TagPoseSourceTest, LayoutTagEnteringTheViewIsFoundInTheSameFrame) {
  const std::vector<Image<uint8_t>> frames = Frames(5, 3);
  for (const bool predict : {true, false}) {
    TagPoseSourceOptions options = Options();
    options.tracker.full_frame_interval = 0;  // no periodic full-frame search
    options.layout = Board();
    options.predict_layout_tags = predict;
    auto source = TagPoseSource::Create(options);
    ASSERT_TRUE(source.ok());
    WorldPose pose;
    for (int frame = 0; frame < 5; ++frame) {
      ASSERT_TRUE((*source)->Track(frames[frame].view(), &pose).ok());
      ASSERT_TRUE(pose.found) << frame;
      const TagTrackerFrameReport& report = (*source)->report();
      EXPECT_EQ(report.search == TagTrackerFrameReport::Search::kRegions, frame > 0) << frame;
      const int expected_tags = frame >= 3 && predict ? 2 : 1;
      EXPECT_EQ(pose.anchors_used, expected_tags) << frame << " predict " << predict;
      EXPECT_EQ(pose.markers.size(), static_cast<size_t>(expected_tags)) << frame;
      EXPECT_EQ(report.predicted_found, frame == 3 && predict ? 1 : 0) << frame;
      if (predict && frame >= 3) {
        const Eigen::Vector3d origin = CamFromTag(0, frame) * Eigen::Vector3d(0.1, 0.0, 0.0);
        EXPECT_NEAR((pose.cam_from_world.translation - origin).norm(), 0.0, 2e-3) << frame;
      }
    }
  }
}

// The board 1.6 m away (tags 26 px wide): the full-frame search decimated by 4 misses both tags; a
// prior pose of the frame predicts them and the predicted search (decimation from the predicted
// size: 1) finds them.
TEST(TagPoseSourceTest, PriorPosePredictsTheLayoutsTags) {
  Rigid3 away;
  away.translation = Eigen::Vector3d(0.0, 0.0, 1.05);
  testing::SyntheticTag tags[2];
  for (int i = 0; i < 2; ++i) {
    tags[i].id = 4 + i;
    tags[i].size = kTagSize;
    tags[i].cam_from_tag = away * CamFromTag(i, 0);
  }
  const std::vector<Image<uint8_t>> frames = {
      testing::RenderTags(tags, 2, testing::TestCamera(), testing::SyntheticRenderOptions())};
  TagPoseSourceOptions options = Options();
  options.tracker.detector.quad_decimate = 4.0f;
  options.layout = Board();
  auto source = TagPoseSource::Create(options);
  ASSERT_TRUE(source.ok());
  WorldPose pose;
  ASSERT_TRUE((*source)->Track(frames[0].view(), &pose).ok());
  EXPECT_FALSE(pose.found);  // the full frame alone
  EXPECT_EQ((*source)->report().predicted_searched, 0);
  // The prior is off by 1 cm and 1 degree.
  const Eigen::Vector3d origin = tags[0].cam_from_tag * Eigen::Vector3d(0.1, 0.0, 0.0);
  Rigid3 prior = tags[0].cam_from_tag;
  prior.translation = origin + Eigen::Vector3d(0.01, 0.0, -0.005);
  prior.rotation = Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix() * prior.rotation;
  ASSERT_TRUE((*source)->Track(frames[0].view(), &prior, &pose).ok());
  ASSERT_TRUE(pose.found);
  EXPECT_EQ(pose.anchors_used, 2);
  EXPECT_EQ((*source)->report().predicted_found, 2);
  EXPECT_NEAR((pose.cam_from_world.translation - origin).norm(), 0.0, 5e-3);
  // Without a layout the prior is not used.
  options.layout = TagLayout();
  auto one_tag = TagPoseSource::Create(options);
  ASSERT_TRUE(one_tag.ok());
  ASSERT_TRUE((*one_tag)->Track(frames[0].view(), &prior, &pose).ok());
  EXPECT_FALSE(pose.found);
}

TEST(TagPoseSourceTest, BadOptionsAreInvalidArgument) {
  TagPoseSourceOptions options = Options();
  options.tag_id = -2;
  EXPECT_EQ(TagPoseSource::Create(options).status().code(), StatusCode::kInvalidArgument);
  options = Options();
  options.tracker.tag_size = 0.0;
  EXPECT_EQ(TagPoseSource::Create(options).status().code(), StatusCode::kInvalidArgument);
}

TEST(TagPoseSourceTest, SteadyStateDoesNotAllocate) {
  const std::vector<Image<uint8_t>> frames = Frames(24);
  for (const bool with_layout : {false, true}) {
    TagPoseSourceOptions options = Options();
    options.tracker.full_frame_interval = 6;  // the periodic full-frame path is exercised too
    // Tag 6 of the layout is in view but not drawn: searched by prediction in every frame whose
    // full frame is not searched.
    if (with_layout) options.layout = Board(3);
    auto source = TagPoseSource::Create(options);
    ASSERT_TRUE(source.ok());
    WorldPose pose;
    for (int frame = 0; frame < 4; ++frame) ASSERT_TRUE((*source)->Track(frames[frame].view(), &pose).ok());
    long allocations = -1;
    int found = 0, predicted_searched = 0;
    {
      testing::NoAllocationScope scope;
      for (size_t frame = 4; frame < frames.size(); ++frame) {
        if (!(*source)->Track(frames[frame].view(), &pose).ok()) break;
        found += pose.found;
        predicted_searched += (*source)->report().predicted_searched;
      }
      allocations = scope.allocations();
    }
    EXPECT_EQ(allocations, 0) << "with layout " << with_layout;
    EXPECT_EQ(found, 20);
    EXPECT_EQ(predicted_searched > 10, with_layout) << predicted_searched;
  }
}

}  // namespace
}  // namespace reconar
