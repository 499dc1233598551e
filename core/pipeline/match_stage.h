#pragma once
// Match stage: kd-forest matching with Lowe's ratio test between the pairs of a project's images
// that PairSelector chooses (every pair of a small project; beyond, a sequential window plus
// vocabulary-tree retrieval: core/features/pair_selection.h), then two-view verification (F by
// LO-RANSAC, H screening), then the poorly matched photos extracted again and their pairs matched
// again (PoorlyMatchedPhotoOptions). Pairs with at
// least TwoViewOptions::min_inliers F-inliers go to <project>/matches/matches.txt:
//   # reconar matches v1
//   pair NAME_A NAME_B CONFIG NUM_INLIERS f11 f12 ... f33     (x_b^T F x_a = 0, pixels;
//                                                             CONFIG: verified or planar)
//   INDEX_A INDEX_B                                           (NUM_INLIERS lines, feature indices)
// Under a memory budget too small for every image's features and kd-forests at once, the images
// are cut into consecutive blocks and each pair of blocks is matched with only its two blocks in
// memory; the pairs and the file are the same either way.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/features/matcher.h"
#include "core/features/pair_selection.h"
#include "core/features/sift/sift.h"
#include "core/geometry/two_view.h"
#include "core/pipeline/matches_file.h"
#include "core/pipeline/project.h"

namespace reconar {

// Photos the default extraction leaves poorly matched (a plaster figure on velvet, a dark object
// on a plain ground: texture-poor by what matching found, not by a feature count, which differs
// between scenes and photo sizes) are extracted again at contrast_threshold, written to
// Project::RicherFeaturePath, and every pair they are in is matched again (PhotosToExtractAgain
// says which). Photos that match well keep their features, so a textured set costs nothing.
// min_partners = 0 turns it off.
struct PoorlyMatchedPhotoOptions {
  int min_partners = 2;  // a chain of photos needs two partners per photo
  // Three halvings of Lowe's 0.04: a plaster figure gives about a hundred features at 0.04 and
  // 250-400 here (dinoSparseRing).
  double contrast_threshold = 0.005;
  SiftOptions sift;  // the rest of the extraction: the feature stage's
};

struct MatchStageOptions {
  MatchOptions match;
  PairSelectionOptions pairs;
  TwoViewOptions two_view;
  PoorlyMatchedPhotoOptions poorly_matched;
  // Photos to extract again as the poorly matched ones are, whatever their partners, with why
  // (by name; reconstruct.h: the photos the mapper could register only provisionally, or not at
  // all, and their partners). Names not in the project are ignored.
  std::map<std::string, std::string> extract_again;
  int num_threads = 0;  // pairs in parallel; <= 0: one per core
  bool show_progress = true;
  size_t memory_budget_bytes = 0;  // for features and forests; 0: no limit
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
  // The photos extracted again (PoorlyMatchedPhotoOptions), and what it changed.
  struct ReextractedPhoto {
    std::string name;
    std::string reason;
    int partners_before = 0, partners_after = 0;  // verified or planar pairs
    int features_before = 0, features_after = 0;
    double contrast_threshold = 0.0;
  };
  std::vector<ReextractedPhoto> reextracted;
  std::map<std::string, std::string> extract_again;  // MatchStageOptions::extract_again, as asked
  double seconds_reextraction = 0;  // of which extracting and matching again
};

// Estimated bytes one feature holds while its image is being matched by `workers` workers.
double MatchBytesPerFeature(const MatchOptions& match, int workers);

// Verifies putative matches between two feature sets of images of the given sizes.
Result<VerifiedPair> VerifyMatches(const SiftFeatures& a, int width_a, int height_a, const SiftFeatures& b,
                                   int width_b, int height_b, const std::vector<FeatureMatch>& putative,
                                   const TwoViewOptions& options);

// `reconar match A B`: the two photos' features, extracted as the feature stage extracts them (with
// `sift`, on options.num_threads threads, in memory: nothing is written), matched with
// options.match and verified with options.two_view as the stage matches and verifies a pair.
struct TwoPhotoMatch {
  ProjectImage images[2];
  SiftFeatures features[2];
  VerifiedPair pair;  // image_a 0, image_b 1
};
// InvalidArgument "PATH: reason" for a photo that cannot be read; errors of the options.
Result<TwoPhotoMatch> MatchTwoPhotos(const std::string& path_a, const std::string& path_b, const SiftOptions& sift,
                                     const MatchStageOptions& options);
// The verified matches, one "xa ya xb yb" line each (pixels, three decimals): `reconar match --pairs`.
std::string MatchedPositionsText(const TwoPhotoMatch& match);

// Why a photo is extracted again.
enum class ReextractionReason {
  kNone,
  kPoorlyMatched,        // fewer verified partners than min_partners
  kAsTexturePoor,        // no more features than a poorly matched photo that has fewer than the
                         // set's median count: its partners need it richer as much as it does
  kTheSetMatchesPoorly,  // the set's median photo is poorly matched: every photo is
  kAskedFor,             // named in MatchStageOptions::extract_again
};
// Per photo, from its verified partners (pairs verified as general or planar) and its feature
// count: a photo with fewer than min_partners partners (the project's other photos when there
// are fewer) is poorly matched. A poorly matched photo with fewer features than the set's median
// is texture-poor, and so is every photo with no more features than it (two texture-poor objects
// in a textured set, a dark stretch of a walk): they are extracted again too. When the median
// photo is poorly matched, every photo is. A poorly matched photo with many features (an
// unrelated photo in the folder) is extracted again alone.
std::vector<ReextractionReason> PhotosToExtractAgain(const std::vector<int>& partners,
                                                     const std::vector<int>& feature_counts, int min_partners);
std::string ReextractionReasonText(ReextractionReason reason, int partners, int min_partners);

// The settings under which PROJECT/stages.txt records the stage (stage_record.h).
std::string MatchStageSettings(const MatchStageOptions& options);

// Writes PROJECT/matches/matches.txt and PROJECT/matches/report.json (the photos extracted again,
// MatchStageReportJson), after removing the richer features an earlier run left.
Result<MatchStageReport> RunMatchStage(const Project& project, const MatchStageOptions& options);

// " again=COUNT:DIGEST" naming MatchStageOptions::extract_again in a stage record (a 64-bit FNV-1a
// digest of the names), or nothing for none.
std::string ExtractAgainDigest(const std::map<std::string, std::string>& names);

// The report's photos extracted again, as the JSON object PROJECT/matches/report.json holds.
std::string MatchStageReportJson(const MatchStageReport& report);


}  // namespace reconar
