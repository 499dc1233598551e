#include "core/sfm/intrinsics_selection.h"

#include <gtest/gtest.h>

#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

// Distortion is compared by testing::RadialFactorAt06. (The scene fills the middle of the images,
// where the focal takes up part of the distortion too: the bounds below are loose.)
using testing::RadialFactorAt06;

struct Selection {
  IntrinsicsChoice choice;
  MapperReport report;
  SfmCamera camera;
};

// The true model of a ring (0.4 px noise) started without distortion (and with the principal
// point at the image centre, 5.5 and 3.5 px off, when `centred`), then the choice.
Selection Select(bool distortion, MapperOptions::PrincipalPoint principal_point, bool centred) {
  testing::SceneOptions o;
  o.num_cameras = 8;
  o.num_points = 1500;
  o.wrong_fraction = 0.0;
  o.distortion = distortion;
  const testing::Scene scene = testing::MakeScene(o);
  MapperModel model = testing::TrueModel(scene);
  model.rec.cameras[0].k1 = model.rec.cameras[0].k2 = 0.0;
  if (centred) {
    model.rec.cameras[0].cx = 0.5 * (scene.camera.width - 1);
    model.rec.cameras[0].cy = 0.5 * (scene.camera.height - 1);
  }
  MapperOptions options;
  options.num_threads = 1;
  options.principal_point = principal_point;
  Selection selection;
  const Result<IntrinsicsChoice> choice = SelectIntrinsicsModel(&model, scene.images, options, &selection.report);
  EXPECT_TRUE(choice.ok()) << choice.status().ToString();
  if (choice.ok()) selection.choice = choice.value();
  selection.camera = model.rec.cameras[0];
  return selection;
}

TEST(IntrinsicsSelectionTest, DistortionIsFreedWhenTheDataHasIt) {
  const Selection s = Select(/*distortion=*/true, MapperOptions::PrincipalPoint::kFixed, /*centred=*/false);
  EXPECT_TRUE(s.choice.distortion);
  EXPECT_TRUE(s.report.distortion_refined);
  EXPECT_FALSE(s.choice.principal_point);
  EXPECT_LT(RadialFactorAt06(s.camera), 0.25 * RadialFactorAt06(testing::TrueCamera()));  // barrel, as in the data
  EXPECT_GT(RadialFactorAt06(s.camera), 1.75 * RadialFactorAt06(testing::TrueCamera()));
  EXPECT_EQ(s.camera.cx, testing::TrueCamera().cx);  // fixed
}

TEST(IntrinsicsSelectionTest, DistortionStaysZeroWhenTheDataHasNone) {
  const Selection s = Select(/*distortion=*/false, MapperOptions::PrincipalPoint::kFixed, /*centred=*/true);
  EXPECT_FALSE(s.choice.distortion);
  EXPECT_FALSE(s.report.distortion_refined);
  EXPECT_EQ(s.camera.k1, 0.0);
  EXPECT_EQ(s.camera.k2, 0.0);
}

TEST(IntrinsicsSelectionTest, AnOffCentrePrincipalPointIsFreedUnderAuto) {
  const Selection s = Select(/*distortion=*/true, MapperOptions::PrincipalPoint::kAuto, /*centred=*/true);
  EXPECT_TRUE(s.choice.principal_point);
  EXPECT_TRUE(s.report.principal_point_refined);
  EXPECT_TRUE(s.choice.distortion);
  EXPECT_NEAR(s.camera.cx, testing::TrueCamera().cx, 1.5);
  EXPECT_NEAR(s.camera.cy, testing::TrueCamera().cy, 1.5);
  EXPECT_LT(RadialFactorAt06(s.camera), 0.25 * RadialFactorAt06(testing::TrueCamera()));  // barrel, as in the data
  EXPECT_GT(RadialFactorAt06(s.camera), 1.75 * RadialFactorAt06(testing::TrueCamera()));
}

}  // namespace
}  // namespace reconar
