#pragma once
// The relative pose of a verified pair under the model's current intrinsics: the essential matrix
// by the five-point algorithm in RANSAC over the pair's undistorted matches, then the rotation and
// the baseline direction that put the most matches in front of both cameras. The initial pair
// (initial_pair.h) and the registration from a neighbour (neighbour_registration.h) start from it.
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/math/rigid3.h"
#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

struct PairPose {
  Rigid3 b_from_a;           // translation of unit length
  std::vector<char> inlier;  // per match of the pair: an inlier of the essential matrix
  int num_inliers = 0;
};

// kQuick skips RANSAC's local optimisation and stops at kQuickPairPoseIterations: enough to rank
// pairs whose matches are already verified (initial_pair.cc), not to start a model from.
enum class PairPoseSearch { kThorough, kQuick };
constexpr int kQuickPairPoseIterations = 200;

// FailedPrecondition with the reason when RANSAC finds no essential matrix or no decomposition
// puts the matches in front of both cameras.
Result<PairPose> EstimatePairPose(const MapperModel& model, const MapperPair& pair, const MapperOptions& options,
                                  PairPoseSearch search = PairPoseSearch::kThorough);

}  // namespace reconar
