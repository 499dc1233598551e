#include "core/sfm/mapper.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "tests/core/sfm/synthetic_scene.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace {

using testing::MakeScene;
using testing::Scene;
using testing::SceneOptions;
using testing::SingleThreaded;

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Internal consistency of a model with its report: point3d_ids and tracks are each other's
// inverse, every live point has >= 2 observations in distinct registered images, the counts agree.
void ExpectModelConsistent(const Reconstruction& model, const MapperReport& report, size_t num_images) {
  ASSERT_EQ(model.images.size(), num_images);
  EXPECT_EQ(report.num_images, static_cast<int>(num_images));
  EXPECT_EQ(report.num_registered, model.NumRegisteredImages());
  EXPECT_EQ(report.num_points, model.NumPoints());
  EXPECT_EQ(report.unregistered.size(), num_images - static_cast<size_t>(model.NumRegisteredImages()));
  size_t observations = 0;
  for (size_t p = 0; p < model.points.size(); ++p) {
    const SfmPoint& point = model.points[p];
    if (point.deleted) continue;
    EXPECT_GE(point.track.size(), 2u) << "point " << p;
    EXPECT_TRUE(point.position.allFinite()) << "point " << p;
    std::set<int> images;
    for (const TrackElement& e : point.track) {
      ASSERT_GE(e.image_id, 0);
      ASSERT_LT(e.image_id, static_cast<int>(model.images.size()));
      const SfmImage& image = model.images[static_cast<size_t>(e.image_id)];
      ASSERT_GE(e.keypoint_id, 0);
      ASSERT_LT(e.keypoint_id, static_cast<int>(image.point3d_ids.size()));
      EXPECT_TRUE(image.registered) << "point " << p << " observed by unregistered " << image.name;
      EXPECT_EQ(image.point3d_ids[static_cast<size_t>(e.keypoint_id)], static_cast<int>(p));
      EXPECT_TRUE(images.insert(e.image_id).second) << "point " << p << " seen twice by " << image.name;
    }
    observations += point.track.size();
  }
  size_t referenced = 0;
  for (const SfmImage& image : model.images) {
    ASSERT_EQ(image.point3d_ids.size(), image.keypoints.size());
    ASSERT_GE(image.camera_id, 0);
    ASSERT_LT(image.camera_id, static_cast<int>(model.cameras.size()));
    for (int id : image.point3d_ids) {
      if (id < 0) continue;
      ++referenced;
      ASSERT_LT(id, static_cast<int>(model.points.size()));
      EXPECT_FALSE(model.points[static_cast<size_t>(id)].deleted);
    }
    if (!image.registered) {
      EXPECT_EQ(std::count(image.point3d_ids.begin(), image.point3d_ids.end(), -1),
                static_cast<std::ptrdiff_t>(image.point3d_ids.size()));
    }
  }
  EXPECT_EQ(referenced, observations);
  if (report.num_points > 0) {
    EXPECT_NEAR(report.mean_track_length, static_cast<double>(observations) / report.num_points, 1e-9);
  }
}

// ---- the full reconstruction ------------------------------------------------------------------

// Reconstructs the ring scene and checks the model against the ground truth.
void ExpectRingReconstructed(const SceneOptions& scene_options, const MapperOptions& options) {
  const Scene scene = MakeScene(scene_options);
  ASSERT_GE(scene.pairs.size(), 20u);

  MapperReport report;
  std::vector<std::pair<int, int>> progress;
  const auto start = std::chrono::steady_clock::now();
  Result<Reconstruction> result = RunIncrementalMapper(
      scene.images, scene.pairs, options, &report,
      [&progress](int registered, int total) { progress.emplace_back(registered, total); });
  const double seconds = SecondsSince(start);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const Reconstruction& model = *result;
  const size_t n = scene.images.size();

  std::printf("  %zu pairs, %d true + %d wrong matches; %.2f s (BA %.2f s), %d local + %d global BA\n",
              scene.pairs.size(), scene.num_true_matches, scene.num_wrong_matches, seconds, report.seconds_ba,
              report.num_local_ba, report.num_global_ba);
  std::printf("  %d tracks (%d conflicting matches left out), %d points, mean track %.2f, mean error %.3f px, initial %s\n",
              report.num_tracks, report.num_conflicting_matches, report.num_points, report.mean_track_length,
              report.mean_reprojection_error_px, report.initial_pair.c_str());

  // Every image registered; the report agrees with the model.
  EXPECT_EQ(report.num_registered, static_cast<int>(n));
  for (const auto& u : report.unregistered) ADD_FAILURE() << u.name << " unregistered: " << u.reason;
  ExpectModelConsistent(model, report, n);
  EXPECT_FALSE(report.initial_pair.empty());
  EXPECT_GT(report.num_conflicting_matches, 0);  // the true-true wrong matches merge tracks
  EXPECT_GE(report.seconds_total, report.seconds_ba);
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.back(), std::make_pair(static_cast<int>(n), static_cast<int>(n)));
  for (size_t k = 1; k < progress.size(); ++k) EXPECT_EQ(progress[k].first, progress[k - 1].first + 1);
  for (size_t i = 0; i < n; ++i) EXPECT_EQ(model.images[i].name, scene.images[i].name);

  // No EXIF and one image size: the images share one camera, whose focal starts 33 % too long.
  ASSERT_EQ(model.cameras.size(), 1u);
  const SfmCamera& camera = model.cameras[0];
  std::printf("  camera: f %.3f cx %.2f cy %.2f k1 %.5f k2 %.5f aspect %.5f (pp %d dist %d aspect %d)\n",
              camera.focal, camera.cx, camera.cy, camera.k1, camera.k2, camera.aspect,
              report.principal_point_refined, report.distortion_refined, report.aspect_refined);
  EXPECT_NEAR(camera.focal, scene.camera.focal, 0.01 * scene.camera.focal);
  EXPECT_NEAR(camera.aspect * camera.focal, scene.camera.focal, 0.01 * scene.camera.focal);  // fy

  // Poses. The gauge (7 DoF) is free, so centres are compared after a similarity alignment.
  // Expected accuracy: a keypoint's direction is known to 0.4 / 900 ~ 4.4e-4 rad; each camera
  // is fixed by several hundred points at ~10 units, so its centre is good to roughly
  // 10 * 4.4e-4 / sqrt(300) * (a geometry factor of a few, for the depth range and the coupling
  // of focal and distance) ~ 1e-3 of the radius. The bound, 1 % of the ring radius (0.1 units,
  // i.e. 1.7 % of the 6-unit box), leaves a ten-fold margin and still catches a wrong focal
  // (a 1 % focal error shifts the centres along the viewing direction by ~1 % of the distance)
  // or a wrongly registered camera (errors of the order of the radius).
  std::vector<testing::CameraPose> estimated, truth;
  for (size_t i = 0; i < n; ++i) {
    estimated.push_back({model.images[i].cam_from_world.rotation, model.images[i].Center()});
    truth.push_back({scene.poses[i].rotation, CameraCenterInWorld(scene.poses[i])});
  }
  Result<testing::CameraPoseErrors> errors = testing::CameraCenterErrors(estimated, truth);
  ASSERT_TRUE(errors.ok()) << errors.status().ToString();
  std::printf("  centre error mean %.5f max %.5f (radius %.1f); rotation mean %.4f max %.4f deg\n",
              errors->centre_mean, errors->centre_max, scene_options.ring_radius, errors->rotation_mean_deg,
              errors->rotation_max_deg);
  EXPECT_LT(errors->centre_max, 0.01 * scene_options.ring_radius);
  // Orientation: the directions themselves are good to ~1e-3 degrees, but the principal point,
  // refined here together with k1 and k2 from ten views, trades against a rotation of each camera
  // (1 px = 1 / 900 rad = 0.064 degrees) and is only determined to a few pixels: 0.8 px on x86-64,
  // 2.4 px on aarch64, where fused multiply-adds change the RANSAC samples and so the solution
  // reached. Allow 4 px (0.25 degrees): a wrongly registered camera is off by degrees.
  EXPECT_LT(errors->rotation_max_deg, 0.25);
  EXPECT_LT(errors->relative_rotation_mean_deg, 0.25);

  // Points: each should map back to one true point and lie where that point is (after the same
  // alignment). A wrong match that forms a two-view track of its own (one or both ends on
  // clutter, or two true keypoints whose points are seen nowhere else) passes the 4 px bounds
  // when one end happens to fall near the epipolar line of the other: two-view triangulation
  // splits the epipolar distance between the images, so a band ~16 px wide across the
  // 1000 x 750 image, ~2 % of random positions, of which about half also lie in front of both
  // cameras with >= 1.5 degrees of parallax. Such a match is geometrically indistinguishable
  // from a true one: expect ~1 % of the wrong matches to become points, allow 3 %.
  // A point seen three or more times is over-determined: there a wrong observation must be
  // rejected unless it falls by chance within a few pixels of the true projection (probability
  // ~1e-4 per wrong match). None may be more than 8 px (twice the bound) from it.
  int wrong_points = 0, wrong_multiview_observations = 0;
  double position_error_sum = 0.0;
  int checked = 0;
  for (const SfmPoint& point : model.points) {
    if (point.deleted) continue;
    std::map<int, int> votes;  // true point (or -1) -> observations
    for (const TrackElement& e : point.track) {
      ++votes[scene.point_of_keypoint[static_cast<size_t>(e.image_id)][static_cast<size_t>(e.keypoint_id)]];
    }
    const auto majority = std::max_element(votes.begin(), votes.end(),
                                           [](const auto& x, const auto& y) { return x.second < y.second; });
    if (votes.size() != 1 || majority->first < 0) ++wrong_points;
    if (point.track.size() >= 3) {
      for (const TrackElement& e : point.track) {
        const Eigen::Vector2d& x = model.images[static_cast<size_t>(e.image_id)].keypoints[static_cast<size_t>(e.keypoint_id)];
        const bool far = majority->first < 0 ||
                         (scene.camera.Project(scene.poses[static_cast<size_t>(e.image_id)] * (
                              scene.points[static_cast<size_t>(majority->first)])) - x).norm() > 8.0;
        wrong_multiview_observations += far ? 1 : 0;
      }
    }
    if (votes.size() != 1 || majority->first < 0) continue;
    const Eigen::Vector3d aligned = errors->gt_from_estimate.Apply(point.position);
    position_error_sum += (aligned - scene.points[static_cast<size_t>(majority->first)]).norm();
    ++checked;
  }
  const double point_error = position_error_sum / std::max(checked, 1);
  std::printf("  %d points from wrong matches (of %d wrong matches), %d wrong observations in points seen >= 3 "
              "times; mean point error %.5f\n",
              wrong_points, scene.num_wrong_matches, wrong_multiview_observations, point_error);
  EXPECT_LE(wrong_points, 3 * scene.num_wrong_matches / 100);
  EXPECT_EQ(wrong_multiview_observations, 0);
  // Most true points are reconstructed (each is seen by ~3.5 cameras on average; those seen by
  // fewer than two, or only with little parallax, cannot be).
  EXPECT_GE(checked, 3 * scene_options.num_points / 4);
  // Points are 4-15 units from the cameras and triangulated from >= 1.5 degrees of parallax,
  // most from tens of degrees: each is good to a few 1e-3 units. The mean must stay below 0.01
  // (0.1 % of the radius).
  EXPECT_LT(point_error, 0.001 * scene_options.ring_radius);

  // Reprojection error: with Gaussian noise sigma per coordinate the image distance has mean
  // sigma sqrt(pi / 2) = 1.25 sigma; fitting the 3 coordinates of a point seen n times absorbs
  // 3 of its 2n residual degrees of freedom, so the expected residual norm is about
  // 1.25 sigma sqrt(1 - 3 / (2n)) (the cameras' parameters absorb a negligible share).
  double expected_sum = 0.0;
  size_t observations = 0;
  for (const SfmPoint& point : model.points) {
    if (point.deleted) continue;
    const double len = static_cast<double>(point.track.size());
    expected_sum += len * std::sqrt(M_PI / 2.0) * scene_options.noise_px * std::sqrt(1.0 - 3.0 / (2.0 * len));
    observations += point.track.size();
  }
  const double expected = expected_sum / static_cast<double>(observations);
  std::printf("  expected mean reprojection error %.3f px\n", expected);
  EXPECT_NEAR(report.mean_reprojection_error_px, expected, 0.15 * expected);

  // point.error is each point's mean reprojection error; the report's mean weights them by
  // track length.
  double weighted = 0.0;
  for (const SfmPoint& point : model.points) {
    if (!point.deleted) weighted += point.error * static_cast<double>(point.track.size());
  }
  EXPECT_NEAR(weighted / static_cast<double>(observations), report.mean_reprojection_error_px, 1e-9);

}

// Photos without EXIF get the usual guess 1.2 x max(width, height) = 1200 px: a third too long
// for the true 900 px. The images share one unknown camera whose focal the mapper must recover.
TEST(IncrementalMapperTest, RingOfTenCamerasWithoutExif) {
  ExpectRingReconstructed(SceneOptions(), SingleThreaded());
}

// A flatter ring (heights +-1.5, no roll), otherwise the same. Only registration and the focal
// are checked: this geometry leaves the principal point and aspect weakly determined (see
// SceneOptions), so the accuracy bounds above do not apply.
SceneOptions FlatRing() {
  SceneOptions o;
  o.height_amplitude = 1.5;
  o.max_roll_deg = 0.0;
  return o;
}

void ExpectAllRegisteredWithTrueFocal(const SceneOptions& scene_options, const MapperOptions& options) {
  const Scene scene = MakeScene(scene_options);
  MapperReport report;
  Result<Reconstruction> result = RunIncrementalMapper(scene.images, scene.pairs, options, &report);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ExpectModelConsistent(*result, report, scene.images.size());
  EXPECT_EQ(report.num_registered, static_cast<int>(scene.images.size()));
  for (const auto& u : report.unregistered) ADD_FAILURE() << u.name << " unregistered: " << u.reason;
  ASSERT_EQ(result->cameras.size(), 1u);
  EXPECT_NEAR(result->cameras[0].focal, scene.camera.focal, 0.01 * scene.camera.focal);
}

// A nearly flat ring with a 33 % wrong focal prior: the initial pair is built with the prior (two
// views aimed at one point cannot fix the focal), so the third image must be registered with its
// focal free under a looser bound, after which a global adjustment corrects the model.
TEST(IncrementalMapperTest, FlatRingWithoutExifRegistersEveryImage) {
  ExpectAllRegisteredWithTrueFocal(FlatRing(), SingleThreaded());
}

// The same data with a looser registration bound (8 px): enough of the third image's
// correspondences fit the distorted two-view model, the first global adjustment with three
// images frees the focal, and the rest follows. Pins the failure above on the registration of
// the third image against the uncorrected prior, not on the later stages.
TEST(IncrementalMapperTest, FlatRingWithoutExifRegistersWithLooseRegistrationBound) {
  MapperOptions options = SingleThreaded();
  options.registration_max_error_px = 8.0;
  ExpectAllRegisteredWithTrueFocal(FlatRing(), options);
}

// ---- determinism ------------------------------------------------------------------------------

SceneOptions SmallScene() {
  SceneOptions o;
  o.num_cameras = 8;
  o.num_points = 800;
  // The true focal as prior: these tests are about other things.
  o.focal_prior_factor = 0.9;
  o.seed = 7;
  return o;
}

TEST(IncrementalMapperTest, TwoRunsGiveIdenticalModels) {
  const Scene scene = MakeScene(SmallScene());
  MapperReport first_report, second_report;
  const auto start = std::chrono::steady_clock::now();
  Result<Reconstruction> first = RunIncrementalMapper(scene.images, scene.pairs, SingleThreaded(), &first_report);
  std::printf("  one run: %.2f s\n", SecondsSince(start));
  Result<Reconstruction> second = RunIncrementalMapper(scene.images, scene.pairs, SingleThreaded(), &second_report);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_EQ(first_report.num_registered, static_cast<int>(scene.images.size()));

  testing::ExpectIdenticalModels(*first, *second);
  EXPECT_EQ(first_report.num_points, second_report.num_points);
  EXPECT_EQ(first_report.initial_pair, second_report.initial_pair);
  EXPECT_EQ(first_report.num_local_ba, second_report.num_local_ba);
  EXPECT_EQ(first_report.num_global_ba, second_report.num_global_ba);
  EXPECT_EQ(first_report.mean_reprojection_error_px, second_report.mean_reprojection_error_px);
  EXPECT_EQ(first_report.principal_point_refined, second_report.principal_point_refined);
  EXPECT_EQ(first_report.distortion_refined, second_report.distortion_refined);
  EXPECT_EQ(first_report.aspect_refined, second_report.aspect_refined);
}

// ---- failures and partial results -----------------------------------------------------------

MapperImage PlainImage(const std::string& name, int num_keypoints, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(0.0, 999.0), y(0.0, 749.0);
  MapperImage image;
  image.name = name;
  image.width = 1000;
  image.height = 750;
  image.focal_prior = 1200.0;
  for (int k = 0; k < num_keypoints; ++k) image.keypoints.emplace_back(x(rng), y(rng));
  return image;
}

TEST(IncrementalMapperTest, TwoImagesWithoutPairsFailWithAReason) {
  const std::vector<MapperImage> images = {PlainImage("a.jpg", 50, 1), PlainImage("b.jpg", 50, 2)};
  MapperReport report;
  Result<Reconstruction> result = RunIncrementalMapper(images, {}, SingleThreaded(), &report);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kFailedPrecondition) << result.status().ToString();
  EXPECT_FALSE(result.status().message().empty());
  EXPECT_EQ(report.num_images, 2);
  EXPECT_EQ(report.num_registered, 0);
}

TEST(IncrementalMapperTest, UnrelatedPairFailsWithAReason) {
  // A "verified" pair of random matches: no essential matrix or too few points, and the error
  // names the pair it tried.
  const std::vector<MapperImage> images = {PlainImage("a.jpg", 300, 1), PlainImage("b.jpg", 300, 2)};
  MapperPair pair;
  pair.matches.image_a = 0;
  pair.matches.image_b = 1;
  for (int k = 0; k < 300; ++k) pair.matches.matches.push_back({k, (k * 7) % 300});
  Result<Reconstruction> result = RunIncrementalMapper(images, {pair}, SingleThreaded(), nullptr);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kFailedPrecondition) << result.status().ToString();
  EXPECT_NE(result.status().message().find("a.jpg + b.jpg"), std::string::npos) << result.status().message();
}

TEST(IncrementalMapperTest, FewerThanTwoImagesIsAnError) {
  MapperReport report;
  Result<Reconstruction> none = RunIncrementalMapper({}, {}, SingleThreaded(), &report);
  ASSERT_FALSE(none.ok());
  EXPECT_FALSE(none.status().message().empty());
  Result<Reconstruction> one = RunIncrementalMapper({PlainImage("a.jpg", 10, 1)}, {}, SingleThreaded(), &report);
  ASSERT_FALSE(one.ok());
  EXPECT_NE(one.status().code(), StatusCode::kOk);
  EXPECT_FALSE(one.status().message().empty());
}

TEST(IncrementalMapperTest, OutOfRangeKeypointOrImageIsInvalidArgument) {
  const Scene scene = MakeScene(SmallScene());
  ASSERT_FALSE(scene.pairs.empty());
  const int num_a = static_cast<int>(scene.images[static_cast<size_t>(scene.pairs.back().matches.image_a)].keypoints.size());
  const auto run_with = [&](const std::function<void(MapperPair*)>& edit) {
    std::vector<MapperPair> pairs = scene.pairs;
    edit(&pairs.back());
    return RunIncrementalMapper(scene.images, pairs, SingleThreaded(), nullptr);
  };
  const auto expect_invalid = [](const Result<Reconstruction>& result, const char* what) {
    ASSERT_FALSE(result.ok()) << what;
    EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument) << what << ": " << result.status().ToString();
  };
  expect_invalid(run_with([&](MapperPair* p) { p->matches.matches.push_back({num_a + 1000000, 0}); }), "index_a too big");
  expect_invalid(run_with([&](MapperPair* p) {
                   const int n = static_cast<int>(scene.images[static_cast<size_t>(p->matches.image_b)].keypoints.size());
                   p->matches.matches.push_back({0, n});
                 }),
                 "index_b == keypoint count");
  expect_invalid(run_with([&](MapperPair* p) { p->matches.matches.insert(p->matches.matches.begin(), {-1, 0}); }),
                 "negative index_a");
  expect_invalid(run_with([&](MapperPair* p) { p->matches.image_b = static_cast<int>(scene.images.size()); }),
                 "image_b out of range");
  expect_invalid(run_with([&](MapperPair* p) { p->matches.image_a = -1; }), "negative image_a");
  expect_invalid(run_with([&](MapperPair* p) { p->matches.image_b = p->matches.image_a; }), "self pair");

  MapperOptions bad = SingleThreaded();
  bad.registration_min_inliers = 2;
  Result<Reconstruction> result = RunIncrementalMapper(scene.images, scene.pairs, bad, nullptr);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);

  std::vector<MapperImage> images = scene.images;
  images[1].focal_prior = 0.0;
  result = RunIncrementalMapper(images, scene.pairs, SingleThreaded(), nullptr);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
}

// A bundle adjustment that refuses its options is a programming error: it ends the run with
// InvalidArgument (it was once swallowed as an infinite cost), unlike a numeric failure, which is
// counted in the report while the mapper carries on.
TEST(IncrementalMapperTest, AdjustmentRefusingItsOptionsIsInvalidArgument) {
  const Scene scene = MakeScene(SmallScene());
  MapperOptions options = SingleThreaded();
  options.final_ba_function_tolerance = -1.0;  // reaches only the final adjustments
  MapperReport report;
  const Result<Reconstruction> result = RunIncrementalMapper(scene.images, scene.pairs, options, &report);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument) << result.status().ToString();
  EXPECT_NE(result.status().message().find("function_tolerance"), std::string::npos) << result.status().message();
  EXPECT_EQ(report.num_failed_ba, 0);

  const Result<Reconstruction> fine = RunIncrementalMapper(scene.images, scene.pairs, SingleThreaded(), &report);
  ASSERT_TRUE(fine.ok()) << fine.status().ToString();
  EXPECT_EQ(report.num_failed_ba, 0);
  EXPECT_TRUE(report.first_ba_failure.empty());
}

TEST(IncrementalMapperTest, ImagesThatCannotBeRegisteredAreListedWithAReason) {
  Scene scene = MakeScene(SmallScene());
  const size_t n = scene.images.size();
  // An image with keypoints but no pairs, and one whose only pair has 12 matches (enough for the
  // pair to exist, too few to register against the model: registration_min_inliers is 30).
  scene.images.push_back(PlainImage("lonely.jpg", 200, 3));
  MapperImage weak = scene.images[0];
  weak.name = "weak.jpg";
  scene.images.push_back(weak);
  MapperPair pair;
  pair.matches.image_a = 0;
  pair.matches.image_b = static_cast<int>(n + 1);
  for (int k = 0; k < 12; ++k) pair.matches.matches.push_back({k, k});
  scene.pairs.push_back(pair);

  MapperReport report;
  Result<Reconstruction> result = RunIncrementalMapper(scene.images, scene.pairs, SingleThreaded(), &report);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ExpectModelConsistent(*result, report, scene.images.size());
  for (const auto& u : report.unregistered) std::printf("  %s: %s\n", u.name.c_str(), u.reason.c_str());
  EXPECT_EQ(report.num_registered, static_cast<int>(n));
  EXPECT_FALSE(result->images[n].registered);
  EXPECT_FALSE(result->images[n + 1].registered);
  ASSERT_EQ(report.unregistered.size(), 2u);
  std::set<std::string> names;
  for (const auto& u : report.unregistered) {
    names.insert(u.name);
    EXPECT_FALSE(u.reason.empty()) << u.name;
  }
  EXPECT_EQ(names, (std::set<std::string>{"lonely.jpg", "weak.jpg"}));
}

// Two unrelated rings in one set: the larger is returned, the smaller becomes model 2 with every
// one of its images, and neither takes an image of the other.
TEST(IncrementalMapperTest, UnrelatedSetsBecomeSeparateModelsTheLargestFirst) {
  SceneOptions small_options = SmallScene();
  small_options.num_cameras = 6;
  small_options.seed = 11;
  const Scene large = MakeScene(SmallScene());
  const Scene small = MakeScene(small_options);
  std::vector<MapperImage> images = small.images;  // the smaller set first: its model starts first
  for (MapperImage& image : images) image.name = "small_" + image.name;
  std::vector<MapperPair> pairs = small.pairs;
  const int offset = static_cast<int>(images.size());
  images.insert(images.end(), large.images.begin(), large.images.end());
  for (MapperPair pair : large.pairs) {
    pair.matches.image_a += offset;
    pair.matches.image_b += offset;
    pairs.push_back(pair);
  }
  MapperReport report;
  std::vector<Reconstruction> others;
  Result<Reconstruction> result = RunIncrementalMapper(images, pairs, SingleThreaded(), &report, nullptr, &others);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ExpectModelConsistent(*result, report, images.size());
  ASSERT_EQ(report.models.size(), 2u);
  ASSERT_EQ(others.size(), 1u);
  // Each model holds every image its initial pair is joined to: neither is a failed start
  // (MapperOptions::min_model_images), however small next to the whole set.
  EXPECT_EQ(report.init_starts, 1);
  EXPECT_EQ(report.models[0].images.size(), large.images.size());
  EXPECT_EQ(report.models[1].images.size(), small.images.size());
  EXPECT_EQ(report.models[0].num_points, result->NumPoints());
  EXPECT_EQ(report.models[1].num_points, others[0].NumPoints());
  for (size_t i = 0; i < images.size(); ++i) {
    const bool in_large = static_cast<int>(i) >= offset;
    EXPECT_EQ(result->images[i].registered, in_large) << images[i].name;
    EXPECT_EQ(others[0].images[i].registered, !in_large) << images[i].name;
  }
  for (const auto& u : report.unregistered) {
    EXPECT_EQ(u.name.rfind("small_", 0), 0u) << u.name;
    EXPECT_NE(u.reason.find("in model 2"), std::string::npos) << u.name << ": " << u.reason;
  }
  // Each model is right on its own.
  for (const auto& [model, scene, first] :
       {std::tuple<const Reconstruction*, const Scene*, int>{&*result, &large, offset}, {&others[0], &small, 0}}) {
    std::vector<testing::CameraPose> estimated, truth;
    for (size_t i = 0; i < scene->images.size(); ++i) {
      const SfmImage& image = model->images[i + static_cast<size_t>(first)];
      estimated.push_back({image.cam_from_world.rotation, image.Center()});
      truth.push_back({scene->poses[i].rotation, CameraCenterInWorld(scene->poses[i])});
    }
    const auto errors = testing::CameraCenterErrors(estimated, truth);
    ASSERT_TRUE(errors.ok());
    EXPECT_LT(errors->rotation_max_deg, 0.5);
    EXPECT_LT(errors->centre_max, 0.01 * 10.0);  // ring radius 10
  }
}

}  // namespace
}  // namespace reconar
