// The keyframe gate makes no heap allocation per frame once it has seen its first frame and taken
// its second keyframe (the keyframe pyramid's copy sizes its storage then): operator new is counted
// (tests/support/allocation_counter.h).
#include <gtest/gtest.h>

#include <vector>

#include "tests/support/allocation_counter.h"
#include "tests/tracker/rotation_video.h"
#include "tracker/keyframe_gate.h"

namespace reconar {
namespace {

TEST(KeyframeGateAllocationTest, FramesDoNotAllocate) {
  auto scene = testing::MakeRotationScene(
      std::string(RECONAR_SHARED_DATA_DIR) + "/strecha_fountain-P11/images/0005.jpg", 2, 640, 480);
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  std::vector<Image<uint8_t>> frames;
  // A narrow view (the photo box-filtered by 2) turning 32 degrees: keyframes as the overlap runs out.
  for (int i = 0; i < 80; ++i)
    frames.push_back(testing::RenderRotatedView(*scene, testing::YawPitchRoll(-16.0 + 0.4 * i, 0, 0)));
  KeyframeGate gate;
  GateFrameReport report;
  size_t frame = 0;
  while (gate.keyframes() < 2 && frame < frames.size()) ASSERT_TRUE(gate.Process(frames[frame++].view(), &report).ok());
  ASSERT_EQ(gate.keyframes(), 2);
  const int keyframes_before = gate.keyframes();
  long allocations = 0;
  {
    testing::NoAllocationScope scope;
    for (; frame < frames.size(); ++frame) {
      if (!gate.Process(frames[frame].view(), &report).ok()) break;
    }
    allocations = scope.allocations();
  }
  EXPECT_EQ(frame, frames.size());
  EXPECT_GT(gate.keyframes(), keyframes_before);  // the keyframe path ran inside the scope too
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace reconar
