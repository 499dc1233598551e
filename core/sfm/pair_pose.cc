#include "core/sfm/pair_pose.h"

#include <cmath>

#include "core/geometry/essential_five_point.h"
#include "core/geometry/ransac.h"
#include "core/geometry/relative_pose.h"

namespace reconar {

Result<PairPose> EstimatePairPose(const MapperModel& model, const MapperPair& pair, const MapperOptions& options,
                                  PairPoseSearch search) {
  const Reconstruction& rec = model.rec;
  const int a = pair.matches.image_a, b = pair.matches.image_b;
  const SfmImage& ia = rec.images[static_cast<size_t>(a)];
  const SfmImage& ib = rec.images[static_cast<size_t>(b)];
  const SfmCamera& ca = rec.cameras[static_cast<size_t>(ia.camera_id)];
  const SfmCamera& cb = rec.cameras[static_cast<size_t>(ib.camera_id)];
  std::vector<Correspondence> samples;
  std::vector<int> match_of;
  samples.reserve(pair.matches.matches.size());
  for (size_t i = 0; i < pair.matches.matches.size(); ++i) {
    const FeatureMatch& m = pair.matches.matches[i];
    Eigen::Vector2d xa, xb;
    if (!ca.Undistort(ia.keypoints[static_cast<size_t>(m.index_a)], &xa) ||
        !cb.Undistort(ib.keypoints[static_cast<size_t>(m.index_b)], &xb))
      continue;
    samples.push_back({xa, xb});
    match_of.push_back(static_cast<int>(i));
  }
  RansacOptions ransac;
  ransac.max_residual = options.max_reprojection_error_px / std::sqrt(ca.focal * cb.focal);
  if (search == PairPoseSearch::kQuick) {
    ransac.local_optimisation = false;
    ransac.max_iterations = kQuickPairPoseIterations;
  }
  const auto essential = Ransac<EssentialFivePoint>::Run(samples.data(), static_cast<int>(samples.size()), ransac);
  if (!essential.ok() || essential->status != RansacStatus::kSuccess) {
    return FailedPrecondition("no essential matrix");
  }
  std::vector<Correspondence> inliers;
  std::vector<int> inlier_match;
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!essential->inlier_mask[i]) continue;
    inliers.push_back(samples[i]);
    inlier_match.push_back(match_of[i]);
  }
  const auto relative = RelativePoseFromEssential(essential->model, inliers.data(), static_cast<int>(inliers.size()));
  if (!relative.ok()) return FailedPrecondition(relative.status().message());
  PairPose pose;
  pose.b_from_a.rotation = relative->R;
  pose.b_from_a.translation = relative->t;
  pose.inlier.assign(pair.matches.matches.size(), 0);
  for (size_t i = 0; i < inliers.size(); ++i) {
    if (relative->in_front_mask.empty() || relative->in_front_mask[i]) {
      pose.inlier[static_cast<size_t>(inlier_match[i])] = 1;
      ++pose.num_inliers;
    }
  }
  return pose;
}

}  // namespace reconar
