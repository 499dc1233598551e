#include "core/sfm/initial_pair.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/math/rotation.h"
#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

// Three cameras 10 units from the origin: view0 and view1 a hair apart (0.02: under 0.2 degrees
// of parallax), view2 40 degrees around.
testing::Scene ThreeViews() {
  testing::SceneOptions o;
  o.num_points = 800;
  o.wrong_fraction = 0.0;
  o.distortion = false;
  const double a = 40.0 * M_PI / 180.0;
  o.centres = {Eigen::Vector3d(10.0, 0.0, 1.0), Eigen::Vector3d(10.0, 0.02, 1.0),
               Eigen::Vector3d(10.0 * std::cos(a), 10.0 * std::sin(a), 2.0)};
  return testing::MakeScene(o);
}

// The model before initialisation: tracks and cameras, nothing registered.
MapperModel Unstarted(const testing::Scene& scene) {
  MapperModel model = testing::TrueModel(scene);
  model.Reset();
  for (SfmImage& image : model.rec.images) image.cam_from_world = Rigid3();
  return model;
}

size_t MatchesOf(const testing::Scene& scene, int a, int b) {
  for (const MapperPair& pair : scene.pairs) {
    if (pair.matches.image_a == a && pair.matches.image_b == b) return pair.matches.matches.size();
  }
  return 0;
}

TEST(InitialPairTest, PrefersAPairWithBaselineOverOneWithMoreMatchesAndNone) {
  const testing::Scene scene = ThreeViews();
  ASSERT_GT(MatchesOf(scene, 0, 1), MatchesOf(scene, 0, 2));
  ASSERT_GT(MatchesOf(scene, 0, 1), MatchesOf(scene, 1, 2));
  MapperModel model = Unstarted(scene);
  MapperReport report;
  const Status status = InitializeFromBestPair(&model, scene.images, scene.pairs, testing::SingleThreaded(), &report);
  ASSERT_TRUE(status.ok()) << status.ToString();
  EXPECT_EQ(report.init_relaxations, 0);
  EXPECT_NE(report.initial_pair.find("view2.jpg"), std::string::npos) << report.initial_pair;
  ASSERT_EQ(model.rec.NumRegisteredImages(), 2);
  EXPECT_TRUE(model.rec.images[2].registered);
  const int other = model.rec.images[0].registered ? 0 : 1;
  // The relative rotation is the true one.
  const Eigen::Matrix3d estimated = model.rec.images[2].cam_from_world.rotation *
                                    model.rec.images[static_cast<size_t>(other)].cam_from_world.rotation.transpose();
  const Eigen::Matrix3d truth = scene.poses[2].rotation * scene.poses[static_cast<size_t>(other)].rotation.transpose();
  EXPECT_LT(RotationAngle(estimated, truth) * 180.0 / M_PI, 0.2);
  EXPECT_GE(model.rec.NumPoints(), testing::SingleThreaded().init_min_points);
}

TEST(InitialPairTest, PairsWithoutParallaxAloneGiveNoModel) {
  testing::Scene scene = ThreeViews();
  for (MapperPair& pair : scene.pairs) pair.planar = pair.matches.image_b == 2;  // only (0, 1) is tried
  MapperModel model = Unstarted(scene);
  MapperReport report;
  const Status status = InitializeFromBestPair(&model, scene.images, scene.pairs, testing::SingleThreaded(), &report);
  EXPECT_EQ(status.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(status.message().find("view0.jpg + view1.jpg"), std::string::npos) << status.message();
  EXPECT_EQ(model.rec.NumRegisteredImages(), 0);
  EXPECT_TRUE(model.rec.points.empty());
}

TEST(InitialPairTest, BoundsAreRelaxedDownToTheFloors) {
  const testing::Scene scene = ThreeViews();
  MapperOptions options = testing::SingleThreaded();
  options.init_min_points = 8000;  // ten times the scene's points: relaxed 8000, 4000, 2000, 1000, 500, ...
  options.init_min_points_floor = 25;
  MapperModel model = Unstarted(scene);
  MapperReport report;
  const Status status = InitializeFromBestPair(&model, scene.images, scene.pairs, options, &report);
  ASSERT_TRUE(status.ok()) << status.ToString();
  EXPECT_GE(report.init_relaxations, 4);
  EXPECT_GE(model.rec.NumPoints(), std::max(25, 8000 >> report.init_relaxations));
  EXPECT_LT(model.rec.NumPoints(), 8000 >> (report.init_relaxations - 1));

  // With the floor at the bound nothing is relaxed, and the reason says so.
  options.init_min_points_floor = 8000;
  MapperModel again = Unstarted(scene);
  const Status failed = InitializeFromBestPair(&again, scene.images, scene.pairs, options, &report);
  EXPECT_EQ(failed.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(failed.message().find("relaxed to 8000 points"), std::string::npos) << failed.message();
}

// Eight views within 0.03 of each other (28 pairs without baseline, more than the 20 full tries)
// and a ninth 40 degrees around: the search goes on down the match-count order to the wide pairs.
TEST(InitialPairTest, SearchesPastThePairsWithoutBaseline) {
  testing::SceneOptions o;
  o.num_points = 800;
  o.wrong_fraction = 0.0;
  o.distortion = false;
  for (int i = 0; i < 8; ++i) o.centres.push_back(Eigen::Vector3d(10.0, 0.004 * i, 1.0));
  const double a = 40.0 * M_PI / 180.0;
  o.centres.push_back(Eigen::Vector3d(10.0 * std::cos(a), 10.0 * std::sin(a), 2.0));
  const testing::Scene scene = testing::MakeScene(o);
  MapperOptions options = testing::SingleThreaded();
  ASSERT_LT(options.init_max_pairs_tried, 28);
  MapperModel model = Unstarted(scene);
  MapperReport report;
  const Status status = InitializeFromBestPair(&model, scene.images, scene.pairs, options, &report);
  ASSERT_TRUE(status.ok()) << status.ToString();
  EXPECT_EQ(report.init_relaxations, 0);
  EXPECT_TRUE(model.rec.images[8].registered) << report.initial_pair;
  EXPECT_GT(report.init_pairs_scored, 28);
}

// A model whose points no third view sees enough of (here: the rule asks for more points than the
// scene has) is a dead end; with nothing better it is still the result, not "no model".
TEST(InitialPairTest, ADeadEndPairIsTheLastResort) {
  const testing::Scene scene = ThreeViews();
  MapperOptions options = testing::SingleThreaded();
  options.registration_min_inliers = options.registration_min_verified_inliers = 100000;
  MapperModel model = Unstarted(scene);
  MapperReport report;
  const Status status = InitializeFromBestPair(&model, scene.images, scene.pairs, options, &report);
  ASSERT_TRUE(status.ok()) << status.ToString();
  EXPECT_EQ(model.rec.NumRegisteredImages(), 2);
  EXPECT_NE(report.initial_pair.find("view2.jpg"), std::string::npos) << report.initial_pair;
  EXPECT_NE(CheckExtendable(model, "p", options).find("no other image sees 100000"), std::string::npos);
}

TEST(InitialPairTest, CheckExtendableAsksForAThirdViewThatSeesEnough) {
  const testing::Scene scene = ThreeViews();
  MapperModel model = testing::TrueModel(scene);
  testing::Unregister(&model, 1);
  const int seen = model.CountVisiblePoints(1);
  MapperOptions options = testing::SingleThreaded();
  options.registration_min_inliers = options.registration_min_verified_inliers = seen;
  EXPECT_EQ(CheckExtendable(model, "p", options), "");
  options.registration_min_inliers = options.registration_min_verified_inliers = seen + 1;
  EXPECT_NE(CheckExtendable(model, "p", options).find("at most " + std::to_string(seen)), std::string::npos);
  // The looser of the two rules counts.
  options.registration_min_verified_inliers = seen;
  EXPECT_EQ(CheckExtendable(model, "p", options), "");
}

TEST(InitialPairTest, CheckInitialModelNamesTheUnmetBound) {
  const testing::Scene scene = ThreeViews();
  MapperModel model = testing::TrueModel(scene);
  const int n = model.rec.NumPoints();
  EXPECT_EQ(CheckInitialModel(model, "p", {n, 0.0}), "");
  EXPECT_NE(CheckInitialModel(model, "p", {n + 1, 0.0}).find("only " + std::to_string(n) + " points"),
            std::string::npos);
  EXPECT_NE(CheckInitialModel(model, "p", {n, 89.0}).find("median triangulation angle"), std::string::npos);
}

}  // namespace
}  // namespace reconar
