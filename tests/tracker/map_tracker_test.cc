// MapTracker on a real photo turned into a video with exact ground truth (rotation_video.h): a
// camera rotating about its centre over Strecha fountain-P11's photo 0005, a jump to an unrelated
// photo (castle-P19) and back. Checks the poses against the truth and the state sequence:
// tracking; relocalising, then lost, on the unrelated photo; relocalised and tracking on return.
#include "tracker/map_tracker.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "tests/tracker/rotation_video.h"
#include "tracker/map_follower.h"

namespace reconar {
namespace {

struct PoseError {
  double rotation_deg = 0.0;
  double centre = 0.0;
};

PoseError Compare(const Rigid3& estimate, const Rigid3& truth) {
  PoseError error;
  error.rotation_deg =
      Eigen::AngleAxisd(Eigen::Matrix3d(estimate.rotation * truth.rotation.transpose())).angle() * 180.0 / M_PI;
  error.centre = (CameraCenterInWorld(estimate) - CameraCenterInWorld(truth)).norm();
  return error;
}

// The sweep's rotation at step i (degrees: yaw -5 .. +10, a little pitch and roll).
Eigen::Matrix3d Sweep(int i) {
  return testing::YawPitchRoll(-5.0 + 0.3 * i, 1.5 * std::sin(i / 8.0), 1.0 * std::sin(i / 13.0));
}

class MapTrackerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string data = RECONAR_SHARED_DATA_DIR;
    auto scene = testing::MakeRotationScene(data + "/strecha_fountain-P11/images/0005.jpg", 4, 640, 480);
    ASSERT_TRUE(scene.ok()) << scene.status().ToString();
    scene_ = new testing::RotationScene(std::move(*scene));
    auto other = testing::MakeRotationScene(data + "/strecha_castle-P19/images/0000.jpg", 4, 640, 480);
    ASSERT_TRUE(other.ok()) << other.status().ToString();
    unrelated_ = new Image<uint8_t>(testing::RenderRotatedView(*other, Eigen::Matrix3d::Identity()));
    auto map = testing::BuildRotationSceneMap(
        *scene_, {testing::YawPitchRoll(-4, 0, 0), testing::YawPitchRoll(0, 0, 0), testing::YawPitchRoll(4, 0, 0)});
    ASSERT_TRUE(map.ok()) << map.status().ToString();
    map_ = new LocalizationMap(std::move(*map));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete unrelated_;
    delete map_;
  }

  static MapTrackerOptions Options() {
    MapTrackerOptions options;
    options.intrinsics = scene_->frame_camera;
    options.lost_after_frames = 4;
    options.lost_relocalise_interval = 2;
    return options;
  }

  static testing::RotationScene* scene_;
  static Image<uint8_t>* unrelated_;
  static LocalizationMap* map_;
};

testing::RotationScene* MapTrackerTest::scene_ = nullptr;
Image<uint8_t>* MapTrackerTest::unrelated_ = nullptr;
LocalizationMap* MapTrackerTest::map_ = nullptr;

TEST_F(MapTrackerTest, FollowsARotatingCameraLosesItOnAnUnrelatedViewAndRelocalisesOnReturn) {
  auto tracker = MapTracker::Create(map_, Options());
  ASSERT_TRUE(tracker.ok()) << tracker.status().ToString();
  MapTrackerFrameReport report;
  std::vector<double> rotation_errors, centre_errors, track_ms;
  std::string states;
  int relocalisations = 0, tracked_frames = 0;
  // 0..39 the sweep, 40..49 the unrelated photo, 50..69 the sweep again from where it was.
  for (int frame = 0; frame < 70; ++frame) {
    const bool away = frame >= 40 && frame < 50;
    const int step = frame < 40 ? frame : frame - 10;
    const Image<uint8_t> image = away ? *unrelated_ : testing::RenderRotatedView(*scene_, Sweep(step));
    ASSERT_TRUE((*tracker)->Track(image.view(), nullptr, &report).ok());
    EXPECT_EQ(report.frame_index, frame);
    states += MapTrackingStateName(report.state)[0];
    if (away) {
      EXPECT_FALSE(report.found) << "frame " << frame;  // never a pose on an unrelated view
      continue;
    }
    if (!report.found) continue;
    relocalisations += report.relocalised;
    const PoseError error = Compare(report.cam_from_world, testing::RotatedViewPose(*scene_, Sweep(step)));
    rotation_errors.push_back(error.rotation_deg);
    centre_errors.push_back(error.centre);
    EXPECT_LT(error.rotation_deg, 0.05) << "frame " << frame;
    EXPECT_LT(error.centre, 0.005) << "frame " << frame;
    EXPECT_EQ(report.inlier_pixels.size(), static_cast<size_t>(report.inliers));
    EXPECT_EQ(report.inlier_world_points.size(), static_cast<size_t>(report.inliers));
    if (!report.relocalised) {
      ++tracked_frames;
      track_ms.push_back(report.track_ms);
    }
  }
  std::sort(rotation_errors.begin(), rotation_errors.end());
  std::sort(centre_errors.begin(), centre_errors.end());
  std::sort(track_ms.begin(), track_ms.end());
  ASSERT_FALSE(rotation_errors.empty());
  ASSERT_FALSE(track_ms.empty());
  std::printf("states: %s\n", states.c_str());
  std::printf(
      "posed %zu of 60 frames on the scene (%d tracked, %d relocalised); rotation error median %.4f max %.4f deg; "
      "centre error median %.5f max %.5f (depths 2-4); tracked frame median %.2f ms\n",
      rotation_errors.size(), tracked_frames, relocalisations, rotation_errors[rotation_errors.size() / 2],
      rotation_errors.back(), centre_errors[centre_errors.size() / 2], centre_errors.back(),
      track_ms[track_ms.size() / 2]);
  // The state sequence: relocalised at once, tracked through the sweep; on the unrelated photo
  // relocalising for lost_after_frames - 1 frames, then lost; back on the scene, relocalised within
  // lost_relocalise_interval frames and tracked again.
  EXPECT_EQ(states.substr(0, 40), std::string(40, 't'));
  EXPECT_EQ(states.substr(40, 10), "rrrlllllll");
  EXPECT_TRUE(states.substr(50, 2) == "tt" || states.substr(50, 2) == "lt") << states.substr(50, 2);
  EXPECT_EQ(states.substr(52), std::string(18, 't'));
  EXPECT_GE(relocalisations, 2);  // the first frame, the return (and re-anchoring every 10 frames)
  EXPECT_GE(static_cast<int>(rotation_errors.size()), 59);
}

TEST_F(MapTrackerTest, APriorRestartsTrackingWithoutRelocalisation) {
  MapTrackerOptions options = Options();
  options.reanchor_interval = 0;  // only the prior and the flow
  auto tracker = MapTracker::Create(map_, options);
  ASSERT_TRUE(tracker.ok()) << tracker.status().ToString();
  MapTrackerFrameReport report;
  // First frame with a prior: tracking starts from the prior's projection of the map (no pose yet).
  const Rigid3 prior = testing::RotatedViewPose(*scene_, Sweep(0));
  ASSERT_TRUE((*tracker)->Track(testing::RenderRotatedView(*scene_, Sweep(0)).view(), &prior, &report).ok());
  EXPECT_TRUE(report.from_prior);
  EXPECT_FALSE(report.found);
  EXPECT_FALSE(report.relocalisation_tried);
  EXPECT_GT(report.seeded_points, 100);
  for (int step = 1; step < 12; ++step) {
    ASSERT_TRUE((*tracker)->Track(testing::RenderRotatedView(*scene_, Sweep(step)).view(), nullptr, &report).ok());
    EXPECT_TRUE(report.found) << step;
    EXPECT_FALSE(report.relocalised) << step;
    EXPECT_FALSE(report.relocalisation_tried) << step;
    EXPECT_EQ(report.state, MapTrackingState::kTracking);
    const PoseError error = Compare(report.cam_from_world, testing::RotatedViewPose(*scene_, Sweep(step)));
    EXPECT_LT(error.rotation_deg, 0.05) << step;
    EXPECT_LT(error.centre, 0.005) << step;
  }
}

// A tracker given the map's localizer built beforehand (the live model's worker builds it with the
// map) follows the camera exactly as one that builds its own: the first frame relocalised, the
// next ones tracked. Trackers may share one localizer.
TEST_F(MapTrackerTest, ATrackerOnALocalizerBuiltBeforehandFollowsAsOneBuildingItsOwn) {
  auto localizer = Localizer::Create(map_, Options().localizer);
  ASSERT_TRUE(localizer.ok()) << localizer.status().ToString();
  const auto shared = std::make_shared<const Localizer>(std::move(*localizer));
  auto own = MapTracker::Create(map_, Options());
  auto given = MapTracker::Create(shared, Options());
  ASSERT_TRUE(own.ok() && given.ok());
  EXPECT_TRUE(MapTracker::Create(shared, Options()).ok());
  MapTrackerFrameReport own_report, given_report;
  int found = 0;
  for (int step = 0; step < 3; ++step) {
    const Image<uint8_t> image = testing::RenderRotatedView(*scene_, Sweep(step));
    ASSERT_TRUE((*own)->Track(image.view(), nullptr, &own_report).ok());
    ASSERT_TRUE((*given)->Track(image.view(), nullptr, &given_report).ok());
    EXPECT_EQ(given_report.found, own_report.found) << step;
    EXPECT_EQ(given_report.relocalised, own_report.relocalised) << step;
    EXPECT_EQ(given_report.inliers, own_report.inliers) << step;
    EXPECT_EQ(given_report.cam_from_world.rotation, own_report.cam_from_world.rotation) << step;
    EXPECT_EQ(given_report.cam_from_world.translation, own_report.cam_from_world.translation) << step;
    found += own_report.found;
  }
  EXPECT_EQ(found, 3);
  EXPECT_FALSE(MapTracker::Create(std::shared_ptr<const Localizer>(), Options()).ok());
}

TEST_F(MapTrackerTest, RejectsBadOptionsAndInputs) {
  MapTrackerOptions options = Options();
  options.intrinsics.fx = 0.0;
  EXPECT_FALSE(MapTracker::Create(map_, options).ok());
  options = Options();
  options.min_inliers = options.max_tracked_points + 1;
  EXPECT_FALSE(MapTracker::Create(map_, options).ok());
  EXPECT_FALSE(MapTracker::Create(nullptr, Options()).ok());
  auto tracker = MapTracker::Create(map_, Options());
  ASSERT_TRUE(tracker.ok());
  MapTrackerFrameReport report;
  EXPECT_FALSE((*tracker)->Track(ImageView<const uint8_t>(), nullptr, &report).ok());
  // A frame of another aspect ratio than the intrinsics.
  Image<uint8_t> square(300, 300);
  EXPECT_FALSE((*tracker)->Track(square.view(), nullptr, &report).ok());
  EXPECT_STREQ(MapTrackingStateName(MapTrackingState::kRelocalising), "relocalising");
  // Intrinsics without a size take any frame; tiny frames are refused or lost, never read beyond.
  options = Options();
  options.intrinsics.width = options.intrinsics.height = 0;
  auto any_size = MapTracker::Create(map_, options);
  ASSERT_TRUE(any_size.ok());
  for (const int side : {1, 3, 9, 17}) {
    Image<uint8_t> tiny(side, side + 1);
    std::fill(tiny.data(), tiny.data() + side * (side + 1), static_cast<uint8_t>(40 * side));
    const Status status = (*any_size)->Track(tiny.view(), nullptr, &report);
    if (status.ok()) {
      EXPECT_FALSE(report.found) << side;
    }
  }
}

// The map moved by the similarity: points and keyframe poses (what each keyframe sees is unchanged).
LocalizationMap Moved(const LocalizationMap& map, const Sim3& moved_from_map) {
  LocalizationMap moved = map;
  for (Eigen::Vector3d& point : moved.points) point = moved_from_map.Apply(point);
  for (MapKeyframe& keyframe : moved.keyframes) {
    const Eigen::Vector3d centre = moved_from_map.Apply(CameraCenterInWorld(keyframe.cam_from_world));
    keyframe.cam_from_world.rotation = keyframe.cam_from_world.rotation * moved_from_map.rotation.transpose();
    keyframe.cam_from_world.translation = -(keyframe.cam_from_world.rotation * centre);
  }
  return moved;
}

Sim3 ASimilarity() {
  Sim3 similarity;
  similarity.scale = 1.7;
  similarity.rotation = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 0.9, -0.3).normalized()).matrix();
  similarity.translation = Eigen::Vector3d(0.5, -2.0, 3.0);
  return similarity;
}

TEST_F(MapTrackerTest, AFollowerTakesUpANewMapAndPosesInItsFrame) {
  MapFollower follower(Options());
  MapTrackerFrameReport report;
  EXPECT_EQ(follower.Track(ImageView<const uint8_t>(), &report).code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(follower.TakeUp(1, nullptr, nullptr, scene_->frame_camera, 640, 480).status().code(),
            StatusCode::kInvalidArgument);
  const Image<uint8_t> frame = testing::RenderRotatedView(*scene_, Sweep(0));
  // The map's camera at twice the frame's size: the follower scales it to the frame.
  CameraIntrinsics map_camera = scene_->frame_camera;
  map_camera.fx *= 2.0;
  map_camera.fy *= 2.0;
  map_camera.cx *= 2.0;
  map_camera.cy *= 2.0;
  map_camera.width *= 2;
  map_camera.height *= 2;
  auto first = follower.TakeUp(1, std::make_shared<const LocalizationMap>(*map_), nullptr, map_camera, 640, 480);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  EXPECT_FALSE(first->new_from_old.has_value());  // no map before
  ASSERT_TRUE(follower.Track(frame.view(), &report).ok());
  ASSERT_TRUE(report.found);
  const Rigid3 in_first = report.cam_from_world;
  EXPECT_LT(Compare(in_first, testing::RotatedViewPose(*scene_, Sweep(0))).rotation_deg, 0.2);

  const Sim3 moved = ASimilarity();
  auto second = follower.TakeUp(2, std::make_shared<const LocalizationMap>(Moved(*map_, moved)), nullptr, map_camera,
                                640, 480);
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_EQ(follower.version(), 2);
  // The keyframes of a camera turning on the spot share one centre: no similarity from them.
  EXPECT_FALSE(second->new_from_old.has_value());
  ASSERT_TRUE(follower.Track(frame.view(), &report).ok());
  ASSERT_TRUE(report.found);
  const Eigen::Vector3d expected_centre = moved.Apply(CameraCenterInWorld(in_first));
  EXPECT_LT((CameraCenterInWorld(report.cam_from_world) - expected_centre).norm(), 0.01 * moved.scale);
  const Eigen::Matrix3d expected_rotation = in_first.rotation * moved.rotation.transpose();
  EXPECT_LT(Eigen::AngleAxisd(Eigen::Matrix3d(report.cam_from_world.rotation * expected_rotation.transpose())).angle(),
            0.2 * M_PI / 180.0);
}

TEST(MapFromMapTest, TheSharedKeyframesCentresGiveTheSimilarity) {
  LocalizationMap old_map;
  for (int k = 0; k < 5; ++k) {
    MapKeyframe keyframe;
    keyframe.name = "keyframe_" + std::to_string(k) + ".jpg";
    keyframe.cam_from_world.rotation = Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d::UnitY()).matrix();
    keyframe.cam_from_world.translation = Eigen::Vector3d(std::cos(k), 0.2 * k, std::sin(k) + 4.0);
    old_map.keyframes.push_back(keyframe);
  }
  const Sim3 truth = ASimilarity();
  LocalizationMap new_map = Moved(old_map, truth);
  new_map.keyframes.erase(new_map.keyframes.begin());  // the new map need not hold every keyframe
  const std::optional<Sim3> new_from_old = MapFromMap(new_map, old_map);
  ASSERT_TRUE(new_from_old.has_value());
  EXPECT_NEAR(new_from_old->scale, truth.scale, 1e-9);
  EXPECT_LT((new_from_old->rotation - truth.rotation).norm(), 1e-9);
  EXPECT_LT((new_from_old->translation - truth.translation).norm(), 1e-9);
  new_map.keyframes.resize(2);  // two shared keyframes are not enough
  EXPECT_FALSE(MapFromMap(new_map, old_map).has_value());
}

}  // namespace
}  // namespace reconar
