// The keyframe gate makes no heap allocation per frame once it has seen its first frame and taken
// its second keyframe (the keyframe pyramid's copy sizes its storage then): operator new is counted
// (tests/support/allocation_counter.h); also when map poses measure the baseline, and through
// blurred frames (the corners they lose are looked for again from the last sharp frame).
#include <gtest/gtest.h>

#include <vector>

#include "tests/support/allocation_counter.h"
#include "tests/support/frame_effects.h"
#include "tests/tracker/rotation_video.h"
#include "tracker/keyframe_gate.h"

namespace reconar {
namespace {

TEST(KeyframeGateAllocationTest, FramesDoNotAllocate) {
  auto scene = testing::MakeRotationScene(
      std::string(RECONAR_SHARED_DATA_DIR) + "/strecha_fountain-P11/images/0005.jpg", 2, 640, 480);
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  std::vector<Image<uint8_t>> frames;
  // A narrow view (the photo box-filtered by 2) turning 32 degrees: keyframes as the overlap runs
  // out; every 7th frame blurred.
  for (int i = 0; i < 80; ++i) {
    frames.push_back(testing::RenderRotatedView(*scene, testing::YawPitchRoll(-16.0 + 0.4 * i, 0, 0)));
    if (i % 7 == 6) frames.back() = testing::MotionBlurred(frames.back(), 9);
  }
  // With map poses too (a camera stepping sideways in front of points 5 m away): the angle's path.
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 300; ++i) points.emplace_back(0.01 * (i % 20) - 0.1, 0.01 * (i / 20) - 0.07, 5.0);
  const auto pose_at = [&](size_t index) {
    GateMapPose pose;
    pose.map_version = 1;
    pose.cam_from_world.translation = Eigen::Vector3d(-0.02 * static_cast<double>(index), 0.0, 0.0);
    pose.points = points.data();
    pose.num_points = static_cast<int>(points.size());
    return pose;
  };
  KeyframeGate gate;
  GateFrameReport report;
  size_t frame = 0;
  while (gate.keyframes() < 2 && frame < frames.size()) {
    const GateMapPose pose = pose_at(frame);
    ASSERT_TRUE(gate.Process(frames[frame++].view(), &report, &pose).ok());
  }
  ASSERT_EQ(gate.keyframes(), 2);
  const int keyframes_before = gate.keyframes();
  long allocations = 0;
  int measured_angles = 0, blurred = 0;
  {
    testing::NoAllocationScope scope;
    for (; frame < frames.size(); ++frame) {
      const GateMapPose pose = pose_at(frame);
      if (!gate.Process(frames[frame].view(), &report, &pose).ok()) break;
      measured_angles += report.triangulation_angle_deg >= 0.0;
      blurred += report.verdict == GateVerdict::kBlurred;
    }
    allocations = scope.allocations();
  }
  EXPECT_EQ(frame, frames.size());
  EXPECT_GT(gate.keyframes(), keyframes_before);  // the keyframe path ran inside the scope too
  EXPECT_GT(measured_angles, 0);
  EXPECT_GT(blurred, 0);
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace reconar
