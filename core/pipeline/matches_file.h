#pragma once
// PROJECT/matches/matches.txt, the verified pairs the match stage (and the capture's live model)
// writes and mapping reads: "# reconar matches v1", then per pair a line "pair NAME_A NAME_B
// verified|planar COUNT F00 .. F22" followed by COUNT lines "INDEX_A INDEX_B" (keypoint indices
// into each photo's features). Its one writer and one reader.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/features/matcher.h"
#include "core/geometry/two_view.h"
#include "core/pipeline/project.h"

namespace reconar {

// A pair as matching verified it (indices into the project's image list).
struct VerifiedPair {
  int image_a = -1;
  int image_b = -1;
  int num_putative = 0;
  TwoViewGeometry geometry;
  std::vector<FeatureMatch> inlier_matches;
};

// Writes PROJECT/matches/matches.txt (atomically) from pairs in the stage's order (image_a <
// image_b, indices into `images`); pairs with too few inliers are left out.
Status WriteMatchesFile(const Project& project, const std::vector<ProjectImage>& images,
                        const std::vector<VerifiedPair>& pairs);

struct MatchesFilePair {
  std::string name_a, name_b, config;  // config: "verified" or "planar"
  Eigen::Matrix3d F;
  std::vector<FeatureMatch> matches;
};
// CorruptData naming the file for a malformed line, a config that is neither verified nor planar,
// or a match list cut short.
Result<std::vector<MatchesFilePair>> ReadMatchesFile(const std::string& path);

}  // namespace reconar
