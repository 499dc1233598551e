// FusedPoseSource on a rotating-camera video of a real photo (tests/tracker/rotation_video.h: exact
// cam_from_world for every frame) with a real AprilTag bitmap drawn where a tag of the layout
// projects: while the tag is in view the frames are posed by the tags and the map together, when
// it has left the view by the map alone, when there is no map by the tags alone; every pose is
// checked against the exact one. Steady-state frames (tags and map tracked) allocate nothing.
#include "tracker/fused_pose_source.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tests/support/allocation_counter.h"
#include "tests/support/sfm_evaluation.h"
#include "tests/tracker/rotation_video.h"
#include "tests/tracker/synthetic_tag_image.h"

namespace reconar {
namespace {

constexpr int kTagId = 5;

// The photo's scene and its map, built once per process (the tests run in one: ONE_PROCESS in
// CMakeLists.txt); the map's SIFT is most of the setup's time under qemu.
struct SceneAndMap {
  testing::RotationScene scene;
  LocalizationMap map;
};

const SceneAndMap& SharedSceneAndMap() {
  static const SceneAndMap* const shared = [] {
    auto* built = new SceneAndMap;
    auto scene = testing::MakeRotationScene(
        std::string(RECONAR_SHARED_DATA_DIR) + "/strecha_fountain-P11/images/0005.jpg", 4, 640, 480);
    EXPECT_TRUE(scene.ok()) << scene.status().ToString();
    built->scene = std::move(*scene);
    auto map =
        testing::BuildRotationSceneMap(built->scene, {testing::YawPitchRoll(-3, 0, 0), testing::YawPitchRoll(3, 0, 0)});
    EXPECT_TRUE(map.ok()) << map.status().ToString();
    built->map = std::move(*map);
    return built;
  }();
  return *shared;
}

struct Video {
  const testing::RotationScene& scene;
  const LocalizationMap& map;
  TagLayout layout;
  std::vector<Image<uint8_t>> frames;
  std::vector<Rigid3> truth;
  std::vector<bool> tag_in_view;
};

// Frames sweeping from -6 to +6 degrees of yaw; the tag stands 1.2 m in front of the camera at
// rotation identity, left of centre, so it leaves the view during the sweep.
Video MakeVideo(int num_frames) {
  const SceneAndMap& shared = SharedSceneAndMap();
  Video video{shared.scene, shared.map};
  const testing::SyntheticTag placed = testing::TiltedTag(kTagId, Eigen::Vector3d(-0.45, 0.05, 1.2), 15.0);
  LayoutTag tag;
  tag.id = kTagId;
  tag.size = placed.size;
  tag.layout_from_tag = video.scene.photo_cam_from_world.Inverse() * placed.cam_from_tag;
  EXPECT_TRUE(video.layout.Add(tag).ok());
  for (int i = 0; i < num_frames; ++i) {
    const Eigen::Matrix3d rotation = testing::YawPitchRoll(-6.0 + 12.0 * i / (num_frames - 1), 0.3, 0.0);
    Image<uint8_t> frame = testing::RenderRotatedView(video.scene, rotation);
    const Rigid3 cam_from_world = testing::RotatedViewPose(video.scene, rotation);
    testing::SyntheticTag drawn = placed;
    drawn.cam_from_tag = cam_from_world * tag.layout_from_tag;
    testing::DrawTag(drawn, video.scene.frame_camera, 4, &frame);
    bool inside = true;
    for (const Eigen::Vector2d& corner : testing::ProjectedCorners(drawn, video.scene.frame_camera)) {
      inside = inside && corner.x() > 10 && corner.y() > 10 && corner.x() < frame.width() - 10 &&
               corner.y() < frame.height() - 10;
    }
    video.frames.push_back(std::move(frame));
    video.truth.push_back(cam_from_world);
    video.tag_in_view.push_back(inside);
  }
  return video;
}

FusedPoseSourceOptions OptionsFor(const Video& video, bool with_map) {
  FusedPoseSourceOptions options;
  options.tags.tracker.intrinsics = video.scene.frame_camera;
  options.tags.tracker.tag_size = 0.1;
  options.tags.tracker.detector.quad_decimate = 1.0f;
  options.tags.layout = video.layout;
  options.map = with_map ? &video.map : nullptr;
  options.map_tracking.max_tracked_points = 200;
  return options;
}

double RotationErrorDeg(const Rigid3& estimate, const Rigid3& truth) {
  return testing::RotationAngleDeg(estimate.rotation, truth.rotation);
}

TEST(FusedPoseSource, TagsAndMapTogetherThenTheMapAloneThenTagsWithoutAMap) {
  const Video video = MakeVideo(40);
  int frames_with_tag = 0, frames_without_tag = 0;
  for (bool in_view : video.tag_in_view) (in_view ? frames_with_tag : frames_without_tag)++;
  ASSERT_GE(frames_with_tag, 10);
  ASSERT_GE(frames_without_tag, 10);

  auto source = FusedPoseSource::Create(OptionsFor(video, true));
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  WorldPose pose;
  int fused = 0, by_map = 0, by_tags = 0;
  double worst_rotation = 0.0, worst_centre = 0.0;
  for (size_t i = 0; i < video.frames.size(); ++i) {
    ASSERT_TRUE((*source)->Track(video.frames[i].view(), &pose).ok());
    const PoseSourceKind kind = (*source)->source();
    fused += kind == PoseSourceKind::kTagsAndMap;
    by_map += kind == PoseSourceKind::kMap;
    by_tags += kind == PoseSourceKind::kTags;
    if (!video.tag_in_view[i]) {
      EXPECT_NE(kind, PoseSourceKind::kTags) << "frame " << i << ": no tag in view";
    }
    if (!pose.found) continue;
    worst_rotation = std::max(worst_rotation, RotationErrorDeg(pose.cam_from_world, video.truth[i]));
    worst_centre =
        std::max(worst_centre, (CameraCenterInWorld(pose.cam_from_world) - CameraCenterInWorld(video.truth[i])).norm());
    if (kind == PoseSourceKind::kTagsAndMap) {
      EXPECT_GT((*source)->fused_map_points(), 0);
    }
  }
  std::printf("fused %d, map %d, tags %d of %zu frames (tag in view in %d); worst rotation %.4f deg, centre %.2f mm\n",
              fused, by_map, by_tags, video.frames.size(), frames_with_tag, worst_rotation, 1000.0 * worst_centre);
  // The first frame relocalises the map and the tags are found at once; afterwards every frame with
  // the tag in view is posed by both, every frame without it by the map.
  EXPECT_GE(fused, frames_with_tag - 2);
  EXPECT_GE(by_map, frames_without_tag - 2);
  EXPECT_LT(worst_rotation, 0.2);
  EXPECT_LT(worst_centre, 0.02);

  // Without a map the same frames are posed by the tag alone, and only while it is in view.
  auto tags_only = FusedPoseSource::Create(OptionsFor(video, false));
  ASSERT_TRUE(tags_only.ok()) << tags_only.status().ToString();
  EXPECT_EQ((*tags_only)->map_report(), nullptr);
  int posed = 0;
  double tags_worst_rotation = 0.0, tags_worst_centre = 0.0;
  for (size_t i = 0; i < video.frames.size(); ++i) {
    ASSERT_TRUE((*tags_only)->Track(video.frames[i].view(), &pose).ok());
    if (!pose.found) continue;
    ++posed;
    tags_worst_rotation = std::max(tags_worst_rotation, RotationErrorDeg(pose.cam_from_world, video.truth[i]));
    tags_worst_centre = std::max(
        tags_worst_centre, (CameraCenterInWorld(pose.cam_from_world) - CameraCenterInWorld(video.truth[i])).norm());
    EXPECT_EQ((*tags_only)->source(), PoseSourceKind::kTags);
  }
  std::printf("tags alone: %d frames posed; worst rotation %.4f deg, centre %.2f mm\n", posed, tags_worst_rotation,
              1000.0 * tags_worst_centre);
  EXPECT_GE(posed, frames_with_tag - 2);
  EXPECT_LE(posed, frames_with_tag + 2);
}

TEST(FusedPoseSource, AMapNeedsTheLayoutOfItsFrame) {
  const Video video = MakeVideo(2);
  FusedPoseSourceOptions options = OptionsFor(video, true);
  options.tags.layout = TagLayout();
  auto source = FusedPoseSource::Create(options);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), StatusCode::kInvalidArgument);
}

// A project without tags: the map alone poses every frame, the tag in view or not, and no tag is
// searched.
TEST(FusedPoseSource, WithoutTagsTheMapAlonePosesEveryFrame) {
  const Video video = MakeVideo(12);
  ASSERT_GT(std::count(video.tag_in_view.begin(), video.tag_in_view.end(), true), 0);
  FusedPoseSourceOptions options = OptionsFor(video, true);
  options.track_tags = false;
  options.tags.layout = TagLayout();
  options.tags.tracker.tag_size = 0.0;  // not used
  auto source = FusedPoseSource::Create(options);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  EXPECT_EQ((*source)->tags(), nullptr);
  WorldPose pose;
  int by_map = 0;
  double worst_rotation = 0.0, worst_centre = 0.0;
  for (size_t i = 0; i < video.frames.size(); ++i) {
    ASSERT_TRUE((*source)->Track(video.frames[i].view(), &pose).ok());
    EXPECT_TRUE(pose.markers.empty());
    if (!pose.found) continue;
    EXPECT_EQ((*source)->source(), PoseSourceKind::kMap);
    ++by_map;
    worst_rotation = std::max(worst_rotation, RotationErrorDeg(pose.cam_from_world, video.truth[i]));
    worst_centre =
        std::max(worst_centre, (CameraCenterInWorld(pose.cam_from_world) - CameraCenterInWorld(video.truth[i])).norm());
  }
  std::printf("without tags: %d of %zu frames posed by the map; worst rotation %.4f deg, centre %.2f mm\n", by_map,
              video.frames.size(), worst_rotation, 1000.0 * worst_centre);
  EXPECT_GE(by_map, static_cast<int>(video.frames.size()) - 1);
  EXPECT_LT(worst_rotation, 0.2);
  EXPECT_LT(worst_centre, 0.02);

  options.map = nullptr;  // nothing to pose from
  EXPECT_EQ(FusedPoseSource::Create(options).status().code(), StatusCode::kInvalidArgument);
}

TEST(FusedPoseSource, SteadyStateFramesDoNotAllocate) {
  const Video video = MakeVideo(30);
  auto source = FusedPoseSource::Create(OptionsFor(video, true));
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  WorldPose pose;
  for (int i = 0; i < 3; ++i) ASSERT_TRUE((*source)->Track(video.frames[i].view(), &pose).ok());
  ASSERT_TRUE(pose.found);
  long allocations = -1;
  int posed = 0, relocalised = 0;
  {
    testing::NoAllocationScope scope;
    for (size_t i = 3; i < video.frames.size(); ++i) {
      if (!(*source)->Track(video.frames[i].view(), &pose).ok()) break;
      posed += pose.found;
      relocalised += (*source)->map_report()->relocalisation_tried;
    }
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(posed, static_cast<int>(video.frames.size()) - 3);
  EXPECT_EQ(relocalised, 0);
}

}  // namespace
}  // namespace reconar
