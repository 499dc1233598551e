#include "core/sfm/pair_pose.h"

#include <cmath>
#include <utility>

#include "core/geometry/absolute_pose.h"
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

BaselineFit FitBaselineLength(const RadialCamera& camera, const Eigen::Matrix3d& R, const Eigen::Vector3d& offset,
                              const Eigen::Vector3d& direction, const std::vector<Eigen::Vector2d>& pixels,
                              const std::vector<Eigen::Vector3d>& world, double max_error_px) {
  const size_t n = pixels.size();
  std::vector<Eigen::Vector3d> rays(n), r_cross_a(n), r_cross_b(n);
  std::vector<char> usable(n, 0);
  for (size_t i = 0; i < n; ++i) {
    Eigen::Vector2d normalised;
    if (!camera.Undistort(pixels[i], &normalised)) continue;
    rays[i] = normalised.homogeneous();
    r_cross_a[i] = rays[i].cross(R * world[i] + offset);
    r_cross_b[i] = rays[i].cross(direction);
    usable[i] = r_cross_b[i].squaredNorm() > 1e-12;
  }
  const double bound = max_error_px * max_error_px;
  const auto inliers_at = [&](double s, double* squared_sum) {
    std::vector<int> inliers;
    *squared_sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const double squared = SquaredPixelError(camera, R, offset + s * direction, world[i], pixels[i]);
      if (squared < bound) {
        inliers.push_back(static_cast<int>(i));
        *squared_sum += squared;
      }
    }
    return inliers;
  };
  BaselineFit best;
  double best_sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!usable[i]) continue;
    const double s = -r_cross_a[i].dot(r_cross_b[i]) / r_cross_b[i].squaredNorm();
    if (!(s > 0.0)) continue;
    double sum = 0.0;
    std::vector<int> inliers = inliers_at(s, &sum);
    if (inliers.size() > best.inliers.size() || (inliers.size() == best.inliers.size() && sum < best_sum)) {
      best.length = s;
      best.inliers = std::move(inliers);
      best_sum = sum;
    }
  }
  if (best.inliers.empty()) return best;
  double numerator = 0.0, denominator = 0.0;
  for (int i : best.inliers) {
    if (!usable[static_cast<size_t>(i)]) continue;
    numerator -= r_cross_a[static_cast<size_t>(i)].dot(r_cross_b[static_cast<size_t>(i)]);
    denominator += r_cross_b[static_cast<size_t>(i)].squaredNorm();
  }
  if (denominator > 0.0 && numerator / denominator > 0.0) {
    double sum = 0.0;
    std::vector<int> refined = inliers_at(numerator / denominator, &sum);
    if (refined.size() >= best.inliers.size()) {
      best.length = numerator / denominator;
      best.inliers = std::move(refined);
    }
  }
  return best;
}


}  // namespace reconar
