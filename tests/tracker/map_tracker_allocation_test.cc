// MapTracker's tracked frames make no heap allocation in steady state: after a relocalisation and
// a few warm-up frames, frames tracked from the previous one (flow, pose, seeding new points)
// allocate nothing: operator new is counted (tests/support/allocation_counter.h). The tracker uses
// only fixed-size Eigen types, so Eigen never reaches malloc there either.
#include <gtest/gtest.h>

#include <vector>

#include "tests/support/allocation_counter.h"
#include "tests/tracker/rotation_video.h"
#include "tracker/map_tracker.h"

namespace reconar {
namespace {

TEST(MapTrackerAllocationTest, TrackedFramesDoNotAllocate) {
  const std::string data = RECONAR_SHARED_DATA_DIR;
  auto scene = testing::MakeRotationScene(data + "/strecha_fountain-P11/images/0005.jpg", 4, 640, 480);
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  auto map = testing::BuildRotationSceneMap(*scene, {testing::YawPitchRoll(-3, 0, 0), testing::YawPitchRoll(3, 0, 0)});
  ASSERT_TRUE(map.ok()) << map.status().ToString();
  // A sweep long enough that points leave the view and new ones are seeded.
  std::vector<Image<uint8_t>> frames;
  for (int i = 0; i < 30; ++i) {
    frames.push_back(testing::RenderRotatedView(*scene, testing::YawPitchRoll(-4.0 + 0.3 * i, 0.5 * i / 10.0, 0.0)));
  }
  MapTrackerOptions options;
  options.intrinsics = scene->frame_camera;
  options.max_tracked_points = 200;
  options.replenish_fraction = 1.0;  // seed whenever below capacity: the seeding path runs in tracked frames
  auto tracker = MapTracker::Create(&*map, options);
  ASSERT_TRUE(tracker.ok()) << tracker.status().ToString();
  MapTrackerFrameReport report;
  for (int frame = 0; frame < 3; ++frame) ASSERT_TRUE((*tracker)->Track(frames[frame].view(), nullptr, &report).ok());
  ASSERT_TRUE(report.found);
  // Each frame counted on its own: frames tracked from the previous one make no allocation; the
  // re-anchoring frames (a relocalisation every reanchor_interval frames) may.
  int tracked = 0, allocating_tracked = 0, reanchored = 0, seeded = 0;
  for (size_t frame = 3; frame < frames.size(); ++frame) {
    long allocations = -1;
    bool ok = false;
    {
      testing::NoAllocationScope scope;
      ok = (*tracker)->Track(frames[frame].view(), nullptr, &report).ok();
      allocations = scope.allocations();
    }
    ASSERT_TRUE(ok);
    ASSERT_TRUE(report.found) << frame;
    if (report.relocalisation_tried) {
      ++reanchored;
      continue;
    }
    EXPECT_FALSE(report.ransac_fallback) << frame;
    ++tracked;
    allocating_tracked += allocations != 0;
    EXPECT_EQ(allocations, 0) << "frame " << frame;
    seeded += report.seeded_points;
  }
  EXPECT_EQ(allocating_tracked, 0);
  EXPECT_GE(tracked, 22);
  EXPECT_GE(reanchored, 2);
  EXPECT_GT(seeded, 0);  // the seeding path ran inside the scopes
}

}  // namespace
}  // namespace reconar
