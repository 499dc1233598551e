// The pair rule (core/features/pair_selection.h) on Middlebury's templeRing, whose 47 views are
// named out of ring order (the name order jumps by up to 164 degrees at six places): retrieval has
// to find the views of the same side that the sequential window misses. And the live capture's
// worker (on one thread or two) and the match stage choose the same pairs once retrieval is on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/features/pair_selection.h"
#include "core/pipeline/feature_stage.h"
#include "core/pipeline/live_reconstruction.h"
#include "core/pipeline/match_stage.h"
#include "tests/support/run_command.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace {

const std::string kRingDir = std::string(RECONAR_SHARED_DATA_DIR) + "/middlebury_templeRing";
const std::string kSparseRingDir = std::string(RECONAR_SHARED_DATA_DIR) + "/middlebury_templeSparseRing";

double AxisAngleDeg(const testing::CameraPose& a, const testing::CameraPose& b) {
  const double c = a.cam_from_world_rotation.row(2).dot(b.cam_from_world_rotation.row(2));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

TEST(PairSelectionRing, RetrievalFindsTheViewsTheWindowMisses) {
  auto truth = testing::ReadMiddleburyParInOrder(kRingDir + "/templeR_par.txt");
  ASSERT_TRUE(truth.ok()) << truth.status().ToString();
  std::vector<std::string> paths;
  std::vector<testing::CameraPose> poses;
  for (const testing::NamedGroundTruthCamera& camera : *truth) {
    paths.push_back(kRingDir + "/" + camera.name);
    poses.push_back(testing::PoseOf(camera.camera));
  }
  std::vector<SiftFeatures> features;
  FeatureStageOptions feature_options;
  feature_options.show_progress = false;
  auto extracted = RunFeatureStage(paths, nullptr, feature_options, &features);
  ASSERT_TRUE(extracted.ok()) << extracted.status().ToString();
  ASSERT_EQ(features.size(), paths.size());

  // A rule that hands most of the ring to retrieval.
  PairSelectionOptions options;
  options.exhaustive_up_to = 10;
  options.sequential_window = 2;
  options.retrieved = 3;
  auto selector = PairSelector::Create(options);
  ASSERT_TRUE(selector.ok()) << selector.status().ToString();
  // A view "sees the same side" as another within two ring steps (7.6 degrees each).
  const double kNear = 16.0;
  int retrieved = 0, retrieved_near = 0, candidates = 0, candidates_near = 0;
  int images_with_near = 0, images_given_near = 0;
  for (size_t i = 0; i < features.size(); ++i) {
    auto partners = selector->Add(features[i].descriptors.data(), static_cast<int>(features[i].keypoints.size()));
    ASSERT_TRUE(partners.ok()) << partners.status().ToString();
    const int image = static_cast<int>(i);
    if (image < options.exhaustive_up_to) continue;
    const int window_start = image - options.sequential_window;
    bool has_near = false, given_near = false;
    for (int other = 0; other < window_start; ++other) {
      const bool near = AxisAngleDeg(poses[i], poses[static_cast<size_t>(other)]) <= kNear;
      ++candidates;
      candidates_near += near;
      has_near |= near;
    }
    for (const int other : *partners) {
      const bool near = AxisAngleDeg(poses[i], poses[static_cast<size_t>(other)]) <= kNear;
      given_near |= near;
      if (other < window_start) {
        ++retrieved;
        retrieved_near += near;
      }
    }
    images_with_near += has_near;
    images_given_near += has_near && given_near;
  }
  const double precision = static_cast<double>(retrieved_near) / retrieved;
  const double chance = static_cast<double>(candidates_near) / candidates;
  std::printf(
      "templeRing retrieval: %d/%d retrieved partners within %.0f deg (precision %.2f, chance %.2f); %d of %d "
      "images with an earlier view that near got one\n",
      retrieved_near, retrieved, kNear, precision, chance, images_given_near, images_with_near);
  // At most 3 of the earlier views (12 % of them on average) lie that near; retrieval must be far better than a
  // random pick of the earlier views, and every view that has a near earlier view must be given one to match.
  EXPECT_GT(precision, 3.0 * chance);
  EXPECT_EQ(images_given_near, images_with_near);
}

std::string ReadOrEmpty(const std::string& path) {
  auto text = ReadFileToString(path);
  return text.ok() ? *text : std::string();
}

TEST(PairSelectionRing, LiveCaptureAndMatchStageChooseTheSamePairs) {
  auto truth = testing::ReadMiddleburyParInOrder(kSparseRingDir + "/templeSR_par.txt");
  ASSERT_TRUE(truth.ok()) << truth.status().ToString();
  LiveReconstructionOptions options;
  options.features.show_progress = false;
  options.matching.show_progress = false;
  options.matching.pairs.exhaustive_up_to = 6;
  options.matching.pairs.sequential_window = 2;
  options.matching.pairs.retrieved = 3;
  const int keyframes = static_cast<int>(truth->size());
  // The worker matching a keyframe's pairs on one thread and on two: the same matches and model.
  bool matches_reusable = true;
  const auto capture = [&](const Project& project, int threads) {
    options.worker_threads = threads;
    LiveReconstruction live(project, options);
    for (const testing::NamedGroundTruthCamera& camera : *truth) live.AddKeyframe(kSparseRingDir + "/" + camera.name);
    auto report = live.Finish();
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    // 15 pairs among the first 6, then 2 + 3 for each of the other 10.
    EXPECT_EQ(report->pairs_matched, 15 + 5 * (keyframes - 6));
    EXPECT_GT(report->registered, keyframes / 2);
    matches_reusable = report->matches_reusable;
  };
  const Project project(testing::MakeTestDirectory("reconar_pair_selection_live"));
  const Project on_one_thread(testing::MakeTestDirectory("reconar_pair_selection_live_one_thread"));
  capture(project, 2);
  capture(on_one_thread, 1);
  const std::string live_matches = ReadOrEmpty(project.MatchesPath());
  ASSERT_FALSE(live_matches.empty());
  EXPECT_EQ(ReadOrEmpty(on_one_thread.MatchesPath()), live_matches);
  for (const char* file : {"/cameras.txt", "/images.txt", "/points3D.txt"}) {
    const std::string model = ReadOrEmpty(project.LiveDir() + file);
    EXPECT_FALSE(model.empty()) << file;
    EXPECT_EQ(ReadOrEmpty(on_one_thread.LiveDir() + file), model) << file << " differs with the worker on one thread";
  }

  // The match stage extracts poorly matched photos again, which the live worker does not; the
  // capture says so (its matches do not stand as the match stage's then). Without that step, the
  // same pairs and matches.
  MatchStageOptions matching = options.matching;
  matching.num_threads = 2;
  auto extracting = RunMatchStage(project, matching);
  ASSERT_TRUE(extracting.ok()) << extracting.status().ToString();
  EXPECT_EQ(matches_reusable, extracting->reextracted.empty());
  matching.poorly_matched.min_partners = 0;
  auto report = RunMatchStage(project, matching);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->num_pairs, 15 + 5 * (keyframes - 6));
  EXPECT_EQ(ReadOrEmpty(project.MatchesPath()), live_matches) << "the match stage chose or matched other pairs";

  // Under a memory budget for a few images at a time, the pairs are chosen from the feature files
  // read in order: the same file again.
  matching.memory_budget_bytes = 3u << 20;
  auto in_blocks = RunMatchStage(project, matching);
  ASSERT_TRUE(in_blocks.ok()) << in_blocks.status().ToString();
  EXPECT_GT(in_blocks->num_blocks, 2);
  EXPECT_EQ(ReadOrEmpty(project.MatchesPath()), live_matches) << "matching in blocks chose or matched other pairs";
}

}  // namespace
}  // namespace reconar
