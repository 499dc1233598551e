#include "core/sfm/provisional_registration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

TEST(ProvisionalRegistrationTest, InlierSpreadIsTheShareOfTheImageThePointsCover) {
  std::vector<Eigen::Vector2d> patch, whole, line;
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 10; ++x) {
      patch.emplace_back(400.0 + 3.0 * x, 300.0 + 3.0 * y);  // 27 x 27 px
      whole.emplace_back(100.0 * x, 75.0 * y);                // the whole 1000 x 750 image
      line.emplace_back(100.0 * x + 10.0 * y, 375.0);         // one row
    }
  }
  EXPECT_LT(InlierSpread(patch, 1000, 750), 0.05);
  EXPECT_GT(InlierSpread(whole, 1000, 750), 0.6);
  EXPECT_LT(InlierSpread(line, 1000, 750), 1e-9);
  EXPECT_EQ(InlierSpread({{1.0, 2.0}, {3.0, 4.0}}, 1000, 750), 0.0);
}

// Image 3 of the true model, registered provisionally from 15 points: at its true pose the review
// holds it; tilted by 2 degrees about its centre, the points the other views determine no longer fit and it is
// refused with the reason.
TEST(ProvisionalRegistrationTest, TheReviewKeepsARightPoseAndRefusesAWrongOne) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel model = testing::TrueModel(scene);
  const MapperOptions options;
  const ProvisionalImage provisional{3, WeakEvidence::kFewInliers, 15, 4};
  EXPECT_EQ(ReviewProvisionalImage(model, provisional, options), "");

  const Rigid3 tilt{Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix(),
                    Eigen::Vector3d::Zero()};
  model.rec.images[3].cam_from_world = tilt * model.rec.images[3].cam_from_world;  // about its centre
  const std::string reason = ReviewProvisionalImage(model, provisional, options);
  EXPECT_NE(reason.find("fit the pose"), std::string::npos) << reason;
}

// Points seen by image 3 and one other lose their second view and go; the others only lose
// image 3's observation.
TEST(ProvisionalRegistrationTest, DeregisteringRemovesTheImagesObservationsAndItsTwoViewPoints) {
  const testing::Scene scene = testing::RegistrationRing();
  MapperModel model = testing::TrueModel(scene);
  int two_view = 0, more = 0;
  for (const int id : model.rec.images[3].point3d_ids) {
    if (id < 0) continue;
    (model.rec.points[static_cast<size_t>(id)].track.size() == 2 ? two_view : more) += 1;
  }
  ASSERT_GT(two_view + more, 0);
  const int points_before = model.rec.NumPoints();
  DeregisterImage(&model, 3, MapperOptions());
  EXPECT_FALSE(model.rec.images[3].registered);
  for (const int id : model.rec.images[3].point3d_ids) EXPECT_EQ(id, -1);
  for (const SfmPoint& point : model.rec.points) {
    if (point.deleted) continue;
    EXPECT_GE(point.track.size(), 2u);
    for (const TrackElement& e : point.track) EXPECT_NE(e.image_id, 3);
  }
  EXPECT_EQ(model.rec.NumPoints(), points_before - two_view);
}

}  // namespace
}  // namespace reconar
