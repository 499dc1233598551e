#pragma once
// The relative pose of a verified pair under the model's current intrinsics: the essential matrix
// by the five-point algorithm in RANSAC over the pair's undistorted matches, then the rotation and
// the baseline direction that put the most matches in front of both cameras. The initial pair
// (initial_pair.h), the registration from a neighbour (neighbour_registration.h) and the join of
// two models by a pair between them (model_merge.h) start from it; the last two fix the
// baseline's length from points with FitBaselineLength.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/math/radial_camera.h"
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

// A baseline's length along a known direction, fitted to points (FitBaselineLength).
struct BaselineFit {
  double length = 0.0;
  std::vector<int> inliers;  // indices into the correspondences
};

// The baseline length s for which cam_from_world = {R, offset + s * direction} puts the most of
// the 2D-3D correspondences within the bound; each correspondence proposes the s that puts its
// point on its ray (least squares on the cross product), and the winner is refined on its inliers.
BaselineFit FitBaselineLength(const RadialCamera& camera, const Eigen::Matrix3d& R, const Eigen::Vector3d& offset,
                              const Eigen::Vector3d& direction, const std::vector<Eigen::Vector2d>& pixels,
                              const std::vector<Eigen::Vector3d>& world, double max_error_px);

}  // namespace reconar
