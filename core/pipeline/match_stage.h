#pragma once
// Match stage: kd-forest matching with Lowe's ratio test between the pairs of a project's images
// that PairSelector chooses (every pair of a small project; beyond, a sequential window plus
// vocabulary-tree retrieval: core/features/pair_selection.h), then two-view verification (F by
// LO-RANSAC, H screening). Pairs with at
// least TwoViewOptions::min_inliers F-inliers go to <project>/matches/matches.txt:
//   # reconar matches v1
//   pair NAME_A NAME_B CONFIG NUM_INLIERS f11 f12 ... f33     (x_b^T F x_a = 0, pixels;
//                                                             CONFIG: verified or planar)
//   INDEX_A INDEX_B                                           (NUM_INLIERS lines, feature indices)
// Under a memory budget too small for every image's features and kd-forests at once, the images
// are cut into consecutive blocks and each pair of blocks is matched with only its two blocks in
// memory; the pairs and the file are the same either way.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/features/matcher.h"
#include "core/features/pair_selection.h"
#include "core/features/sift/sift.h"
#include "core/geometry/two_view.h"
#include "core/pipeline/project.h"

namespace reconar {

struct MatchStageOptions {
  MatchOptions match;
  PairSelectionOptions pairs;
  TwoViewOptions two_view;
  int num_threads = 0;  // pairs in parallel; <= 0: one per core
  bool show_progress = true;
  size_t memory_budget_bytes = 0;  // for features and forests; 0: no limit
};

struct VerifiedPair {
  int image_a = -1;
  int image_b = -1;
  int num_putative = 0;
  TwoViewGeometry geometry;
  std::vector<FeatureMatch> inlier_matches;
};

struct MatchStageReport {
  int num_images = 0;
  int num_pairs = 0;      // matched (chosen by PairSelector)
  int num_verified = 0;   // kVerified
  int num_planar = 0;     // kPlanarOrRotation (kept: good matches, low parallax)
  int num_rejected = 0;   // kTooFewInliers
  int num_blocks = 1;     // image blocks matched a pair of blocks at a time (1: all images at once)
  double estimated_peak_bytes = 0;  // features and forests held at once
  double seconds_pair_selection = 0;  // of which training the vocabulary
  double seconds = 0;
  std::vector<VerifiedPair> pairs;  // kept pairs only, without per-pair rejects
};

// Estimated bytes one feature holds while its image is being matched by `workers` workers.
double MatchBytesPerFeature(const MatchOptions& match, int workers);

// Verifies putative matches between two feature sets of images of the given sizes.
Result<VerifiedPair> VerifyMatches(const SiftFeatures& a, int width_a, int height_a, const SiftFeatures& b,
                                   int width_b, int height_b, const std::vector<FeatureMatch>& putative,
                                   const TwoViewOptions& options);

// The settings under which PROJECT/stages.txt records the stage (stage_record.h).
std::string MatchStageSettings(const MatchStageOptions& options);

Result<MatchStageReport> RunMatchStage(const Project& project, const MatchStageOptions& options);

// Writes PROJECT/matches/matches.txt (atomically) from pairs in the stage's order (image_a <
// image_b, indices into `images`); pairs with too few inliers are left out.
Status WriteMatchesFile(const Project& project, const std::vector<ProjectImage>& images,
                        const std::vector<VerifiedPair>& pairs);

struct MatchesFilePair {
  std::string name_a, name_b, config;  // config: "verified" or "planar"
  Eigen::Matrix3d F;
  std::vector<FeatureMatch> matches;
};
Result<std::vector<MatchesFilePair>> ReadMatchesFile(const std::string& path);

}  // namespace reconar
