// ContinueIncrementalMapper: a model grown one photo at a time (a capture's live model), and a
// model continued from one read back by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "core/sfm/mapper.h"
#include "tests/core/sfm/synthetic_scene.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace {

using testing::MakeScene;
using testing::Scene;
using testing::SceneOptions;

// The first n images of a scene and the pairs among them.
struct Prefix {
  std::vector<MapperImage> images;
  std::vector<MapperPair> pairs;
};
Prefix FirstImages(const Scene& scene, int n) {
  Prefix prefix;
  prefix.images.assign(scene.images.begin(), scene.images.begin() + n);
  for (const MapperPair& pair : scene.pairs) {
    if (pair.matches.image_a < n && pair.matches.image_b < n) prefix.pairs.push_back(pair);
  }
  return prefix;
}

testing::CameraPoseErrors ErrorsAgainstTruth(const Reconstruction& model, const Scene& scene) {
  std::vector<testing::CameraPose> estimated, truth;
  for (const SfmImage& image : model.images) {
    if (!image.registered) continue;
    const auto in_scene = std::find_if(scene.images.begin(), scene.images.end(),
                                       [&](const MapperImage& photo) { return photo.name == image.name; });
    const Rigid3& pose = scene.poses[static_cast<size_t>(in_scene - scene.images.begin())];
    estimated.push_back({image.cam_from_world.rotation, image.Center()});
    truth.push_back({pose.rotation, CameraCenterInWorld(pose)});
  }
  Result<testing::CameraPoseErrors> errors = testing::CameraCenterErrors(estimated, truth);
  EXPECT_TRUE(errors.ok()) << errors.status().ToString();
  return errors.ok() ? *errors : testing::CameraPoseErrors{};
}

SceneOptions Ring() {
  SceneOptions options;
  options.num_cameras = 12;
  options.num_points = 1500;
  options.seed = 11;
  return options;
}

// A photo at a time, grown with local adjustments and adjusted as a whole once at the end: as
// accurate as the mapper's run over all the photos at once, with a global adjustment only at growth
// milestones, not at every photo (bench_live_model measures the time this saves).
TEST(MapperContinuationTest, AModelGrownAPhotoAtATimeMatchesTheWholeRun) {
  const SceneOptions options = Ring();
  const Scene scene = MakeScene(options);
  const MapperOptions mapper = testing::SingleThreaded();
  const int n = static_cast<int>(scene.images.size());

  int first = 2;
  Result<Reconstruction> model = InvalidArgument("no initial pair yet");
  while (!model.ok() && first < n) {
    ++first;
    const Prefix prefix = FirstImages(scene, first);
    model = RunIncrementalMapper(prefix.images, prefix.pairs, mapper, nullptr);
  }
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  MapperContinuation growth;
  growth.final_adjustment = false;
  growth.registered_at_last_global = model->NumRegisteredImages();
  int global_adjustments = 0;
  for (int size = first + 1; size <= n; ++size) {
    const Prefix prefix = FirstImages(scene, size);
    MapperReport report;
    model = ContinueIncrementalMapper(prefix.images, prefix.pairs, mapper, *model, &growth, &report);
    ASSERT_TRUE(model.ok()) << "at " << size << ": " << model.status().ToString();
    EXPECT_EQ(model->NumRegisteredImages(), size) << "the new photo registers at once";
    global_adjustments += report.num_global_ba;
  }
  model = ContinueIncrementalMapper(scene.images, scene.pairs, mapper, *model);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  ASSERT_EQ(model->NumRegisteredImages(), n);

  Result<Reconstruction> whole = RunIncrementalMapper(scene.images, scene.pairs, mapper, nullptr);
  ASSERT_TRUE(whole.ok()) << whole.status().ToString();
  const testing::CameraPoseErrors grown = ErrorsAgainstTruth(*model, scene);
  const testing::CameraPoseErrors at_once = ErrorsAgainstTruth(*whole, scene);
  std::printf(
      "  grown from %d photos: %d global adjustments; centre error mean %.5f max %.5f, rotation max %.4f deg, "
      "relative %.4f deg; all at once: mean %.5f max %.5f, rotation max %.4f deg, relative %.4f deg\n",
      first, global_adjustments, grown.centre_mean, grown.centre_max, grown.rotation_max_deg,
      grown.relative_rotation_mean_deg, at_once.centre_mean, at_once.centre_max, at_once.rotation_max_deg,
      at_once.relative_rotation_mean_deg);
  // A global refinement while the model grows is three adjustments (the choice of the distortion,
  // two; then one: mapper.cc); one per photo would be 3 (n - first).
  EXPECT_LT(global_adjustments, 3 * (n - first));
  // The bound of the mapper's ring test (1 % of the radius; see mapper_test.cc), and no worse than
  // the run over all photos by more than half again.
  EXPECT_LT(grown.centre_max, 0.01 * options.ring_radius);
  EXPECT_LE(grown.centre_mean, 1.5 * at_once.centre_mean + 1e-4 * options.ring_radius);
  // Orientation, against the run over all photos: the principal point, found to a few pixels, trades
  // against a rotation of every camera (1 px ~ 0.064 degrees; see mapper_test.cc), and how well
  // depends on the platform's arithmetic (the whole run: 0.15 degrees at most on x86-64, 0.35 on
  // aarch64). A wrongly registered camera is off by degrees.
  EXPECT_LE(grown.rotation_max_deg, 1.5 * at_once.rotation_max_deg + 0.05);
  EXPECT_LE(grown.relative_rotation_mean_deg, 1.5 * at_once.relative_rotation_mean_deg + 0.05);
  EXPECT_LT(grown.rotation_max_deg, 1.0);
  EXPECT_NEAR(model->cameras[0].focal, scene.camera.focal, 0.01 * scene.camera.focal);
}

// While the model grows, the distortion is refined only when the data has it: a camera without
// distortion keeps k1 = k2 = 0 exactly through every adjustment, one with it gets its barrel back.
TEST(MapperContinuationTest, TheGrowthRefinesTheDistortionOnlyWhenTheDataHasIt) {
  for (const bool distortion : {false, true}) {
    SceneOptions options = Ring();
    options.distortion = distortion;
    const Scene scene = MakeScene(options);
    const MapperOptions mapper = testing::SingleThreaded();
    const Prefix start = FirstImages(scene, 4);
    Result<Reconstruction> seed = RunIncrementalMapper(start.images, start.pairs, mapper, nullptr);
    ASSERT_TRUE(seed.ok()) << seed.status().ToString();
    MapperContinuation growth;
    growth.final_adjustment = false;
    growth.registered_at_last_global = seed->NumRegisteredImages();
    MapperReport report;
    Result<Reconstruction> grown =
        ContinueIncrementalMapper(scene.images, scene.pairs, mapper, *seed, &growth, &report);
    ASSERT_TRUE(grown.ok()) << grown.status().ToString();
    ASSERT_EQ(grown->NumRegisteredImages(), static_cast<int>(scene.images.size()));
    const SfmCamera& camera = grown->cameras[0];
    std::printf("  %s: grown to %d photos, k1 %.5f k2 %.5f (truth %.5f %.5f), distortion refined %d\n",
                distortion ? "with distortion" : "without", grown->NumRegisteredImages(), camera.k1, camera.k2,
                scene.camera.k1, scene.camera.k2, report.distortion_refined);
    EXPECT_EQ(report.distortion_refined, distortion);
    if (distortion) {
      EXPECT_LT(testing::RadialFactorAt06(camera),
                0.25 * testing::RadialFactorAt06(scene.camera));  // barrel, as in the data
      EXPECT_GT(testing::RadialFactorAt06(camera), 1.75 * testing::RadialFactorAt06(scene.camera));
    } else {
      EXPECT_EQ(camera.k1, 0.0);
      EXPECT_EQ(camera.k2, 0.0);
    }
  }
}

// A model is found by its images' names: continued over the images in another order, with more
// of them, it keeps its poses and registers the rest.
TEST(MapperContinuationTest, TheSeedIsFoundByNameInAnyOrder) {
  const Scene scene = MakeScene(Ring());
  const MapperOptions mapper = testing::SingleThreaded();
  const int n = static_cast<int>(scene.images.size());
  const Prefix half = FirstImages(scene, n / 2 + 1);
  Result<Reconstruction> seed = RunIncrementalMapper(half.images, half.pairs, mapper, nullptr);
  ASSERT_TRUE(seed.ok()) << seed.status().ToString();
  ASSERT_EQ(seed->NumRegisteredImages(), n / 2 + 1);

  // Reversed image order; pairs renumbered to match.
  std::vector<MapperImage> reversed(scene.images.rbegin(), scene.images.rend());
  std::vector<MapperPair> pairs = scene.pairs;
  for (MapperPair& pair : pairs) {
    pair.matches.image_a = n - 1 - pair.matches.image_a;
    pair.matches.image_b = n - 1 - pair.matches.image_b;
  }
  MapperReport report;
  Result<Reconstruction> continued = ContinueIncrementalMapper(reversed, pairs, mapper, *seed, nullptr, &report);
  ASSERT_TRUE(continued.ok()) << continued.status().ToString();
  EXPECT_EQ(continued->NumRegisteredImages(), n);
  for (int i = 0; i < n; ++i)
    EXPECT_EQ(continued->images[static_cast<size_t>(i)].name, reversed[static_cast<size_t>(i)].name);
  // The seed's cameras keep their poses, up to what the final adjustment moves (a small share of
  // the ring's radius: the gauge is the seed's).
  for (const SfmImage& seeded : seed->images) {
    const SfmImage& now =
        continued->images[static_cast<size_t>(n - 1) - static_cast<size_t>(&seeded - &seed->images[0])];
    ASSERT_EQ(now.name, seeded.name);
    EXPECT_LT((now.Center() - seeded.Center()).norm(), 0.01 * Ring().ring_radius) << seeded.name;
  }
  const testing::CameraPoseErrors errors = ErrorsAgainstTruth(*continued, scene);
  EXPECT_LT(errors.centre_max, 0.01 * Ring().ring_radius);
}

TEST(MapperContinuationTest, ASeedOfOtherImagesIsInvalidArgument) {
  SceneOptions small = Ring();
  small.num_cameras = 6;
  small.num_points = 600;
  const Scene scene = MakeScene(small);
  const MapperOptions mapper = testing::SingleThreaded();
  Result<Reconstruction> seed = RunIncrementalMapper(scene.images, scene.pairs, mapper, nullptr);
  ASSERT_TRUE(seed.ok()) << seed.status().ToString();

  const auto registered = std::find_if(seed->images.begin(), seed->images.end(),
                                       [](const SfmImage& image) { return image.registered; });
  ASSERT_NE(registered, seed->images.end());
  const size_t renamed_image = static_cast<size_t>(registered - seed->images.begin());
  std::vector<MapperImage> renamed = scene.images;
  renamed[renamed_image].name = "another.jpg";
  Result<Reconstruction> other = ContinueIncrementalMapper(renamed, scene.pairs, mapper, *seed);
  ASSERT_FALSE(other.ok());
  EXPECT_EQ(other.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(other.status().message().find(scene.images[renamed_image].name), std::string::npos)
      << other.status().ToString();

  std::vector<MapperImage> resized = scene.images;
  for (MapperImage& image : resized) image.width *= 2;
  Result<Reconstruction> larger = ContinueIncrementalMapper(resized, scene.pairs, mapper, *seed);
  ASSERT_FALSE(larger.ok());
  EXPECT_NE(larger.status().message().find("another size"), std::string::npos) << larger.status().ToString();

  Reconstruction one = *seed;
  for (size_t i = 1; i < one.images.size(); ++i) one.images[i].registered = false;
  EXPECT_EQ(ContinueIncrementalMapper(scene.images, scene.pairs, mapper, one).status().code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace reconar
