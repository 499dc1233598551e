#include "core/sfm/neighbour_registration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/math/rotation.h"
#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

TEST(NeighbourRegistrationTest, FivePointsFixTheBaselineOfTheNeighboursTwoViewPose) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel model = testing::TrueModelWithFewPointsSeenBy(scene, 3, 5);
  const std::vector<int> candidates = NeighbourRegistrationCandidates(model, scene.pairs, model.tried_with);
  ASSERT_EQ(candidates.size(), 1u);
  EXPECT_EQ(candidates[0], 3);
  ASSERT_TRUE(RegisterImageFromNeighbour(&model, scene.pairs, 3, MapperOptions()))
      << model.failure[3];
  const SfmImage& img = model.rec.images[3];
  EXPECT_LT(RotationAngle(img.cam_from_world.rotation, scene.poses[3].rotation) * 180.0 / M_PI, 0.3);
  // Ring radius 10, neighbours about 4.5 apart.
  EXPECT_LT((img.Center() - CameraCenterInWorld(scene.poses[3])).norm(), 0.1);
  int observed = 0;
  for (int id : img.point3d_ids) observed += id >= 0;
  EXPECT_EQ(observed, 5);
  EXPECT_TRUE(model.failure[3].empty());
}

TEST(NeighbourRegistrationTest, TooFewPointsOrWrongOnesAreRefusedWithAReason) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel too_few = testing::TrueModelWithFewPointsSeenBy(scene, 3, 4);
  EXPECT_FALSE(RegisterImageFromNeighbour(&too_few, scene.pairs, 3, MapperOptions()));
  EXPECT_FALSE(too_few.rec.images[3].registered);

  // Five points, three of them moved 1 % of the ring radius: no baseline length fits five.
  MapperModel moved = testing::TrueModelWithFewPointsSeenBy(scene, 3, 5);
  int shifted = 0;
  for (int id : moved.rec.images[3].point3d_ids) EXPECT_EQ(id, -1);
  const std::vector<int>& track_of = moved.tracks.track_of[3];
  for (size_t kp = 0; kp < track_of.size() && shifted < 3; ++kp) {
    const int t = track_of[kp];
    const int point = t < 0 ? -1 : moved.point_of_track[static_cast<size_t>(t)];
    if (point < 0) continue;
    moved.rec.points[static_cast<size_t>(point)].position += Eigen::Vector3d(0.0, 0.1 * (shifted + 1), 0.0);
    ++shifted;
  }
  EXPECT_FALSE(RegisterImageFromNeighbour(&moved, scene.pairs, 3, MapperOptions()));
  EXPECT_NE(moved.failure[3].find("agree on the baseline length"), std::string::npos) << moved.failure[3];
}

// Off with 0 (`--strict-registration`).
TEST(NeighbourRegistrationTest, OffWhenNoPointsAreAskedFor) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel model = testing::TrueModelWithFewPointsSeenBy(scene, 3, 5);
  MapperOptions options;
  options.registration_min_baseline_points = 0;
  EXPECT_FALSE(RegisterImageFromNeighbour(&model, scene.pairs, 3, options));
}

}  // namespace
}  // namespace reconar
