// Absolute pose from 2D-3D correspondences: LO-RANSAC over P3P (or DLT for an unknown focal),
// then the refinement. The solvers are in p3p.cc and dlt_pose.cc, the local step and the
// refinement in pose_refinement.cc (one translation unit each, so that they compile in parallel
// and the allocation test needs only the refinement).
#include "core/geometry/absolute_pose.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "core/geometry/ransac.h"

namespace reconar {
namespace {

// ---------------------------------------------------------------------------------------------
// High level.

std::string Number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", value);
  return buffer;
}

// Pixel inliers of the pose, ascending, and their mean error.
void PixelInliers(const std::vector<Eigen::Vector2d>& points_px, const std::vector<Eigen::Vector3d>& world_points,
                  const RadialCamera& camera, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                  double max_error_px, std::vector<int>* inliers, double* mean_error) {
  inliers->clear();
  double sum = 0.0;
  const double t2 = max_error_px * max_error_px;
  for (size_t i = 0; i < points_px.size(); ++i) {
    const double squared = SquaredPixelError(camera, R, t, world_points[i], points_px[i]);
    if (squared < t2) {
      inliers->push_back(static_cast<int>(i));
      sum += std::sqrt(squared);
    }
  }
  *mean_error = inliers->empty() ? 0.0 : sum / static_cast<double>(inliers->size());
}

// Refinement (when asked) from the RANSAC pose and its inliers, then the final pixel inliers and
// outcome. The refinement is repeated once on the pixel inliers of the refined pose when they differ.
void FinishPose(const std::vector<Eigen::Vector2d>& points_px, const std::vector<Eigen::Vector3d>& world_points,
                RadialCamera camera, const AbsolutePoseOptions& options, bool refine_focal, Eigen::Matrix3d R,
                Eigen::Vector3d t, std::vector<int> inliers, AbsolutePoseResult* result) {
  PoseRefinementOptions refinement = options.refinement;
  refinement.refine_focal = refine_focal;
  double mean_error = 0.0;
  constexpr int kMaxRefinementRounds = 2;
  for (int round = 0; options.refine && round < kMaxRefinementRounds; ++round) {
    if (static_cast<int>(inliers.size()) < P3PEstimator::kMinSamples + 1) break;
    RadialCamera refined_camera = camera;
    Eigen::Matrix3d refined_R = R;
    Eigen::Vector3d refined_t = t;
    const NormalLmSummary summary =
        RefineAbsolutePoseInPlace(points_px.data(), world_points.data(), inliers.data(),
                                  static_cast<int>(inliers.size()), refinement, &refined_camera, &refined_R,
                                  &refined_t);
    if (summary.termination == NormalLmSummary::Termination::kNumericFailure) break;
    camera = refined_camera;
    R = refined_R;
    t = refined_t;
    result->refined = true;
    result->refinement = summary;
    std::vector<int> refined_inliers;
    PixelInliers(points_px, world_points, camera, R, t, options.max_error_px, &refined_inliers, &mean_error);
    const bool unchanged = refined_inliers == inliers;
    inliers = std::move(refined_inliers);
    if (unchanged) break;
  }
  PixelInliers(points_px, world_points, camera, R, t, options.max_error_px, &inliers, &mean_error);
  result->cam_from_world.rotation = R;
  result->cam_from_world.translation = t;
  result->focal = camera.focal;
  result->num_inliers = static_cast<int>(inliers.size());
  result->inliers = std::move(inliers);
  result->mean_inlier_error_px = mean_error;
  if (result->num_inliers < options.min_inliers) {
    result->outcome = AbsolutePoseResult::Outcome::kTooFewInliers;
    result->reason = "the best pose has " + std::to_string(result->num_inliers) + " inliers within " +
                     Number(options.max_error_px) + " px, need " + std::to_string(options.min_inliers);
    return;
  }
  result->outcome = AbsolutePoseResult::Outcome::kSuccess;
  result->reason.clear();
}

std::vector<int> MaskToIndices(const std::vector<char>& mask, const std::vector<int>& sample_to_input) {
  std::vector<int> indices;
  for (size_t k = 0; k < mask.size(); ++k) {
    if (mask[k]) indices.push_back(sample_to_input[k]);
  }
  return indices;
}

bool TooFewCorrespondences(int usable, int total, int needed, AbsolutePoseResult* result) {
  if (usable >= needed) return false;
  result->outcome = AbsolutePoseResult::Outcome::kTooFewCorrespondences;
  result->reason = std::to_string(usable) + " usable correspondences (of " + std::to_string(total) +
                   "), need at least " + std::to_string(needed);
  return true;
}

void NoModel(const std::string& why, int iterations, AbsolutePoseResult* result) {
  result->outcome = AbsolutePoseResult::Outcome::kNoModel;
  result->reason = "no pose found after " + std::to_string(iterations) + " RANSAC iterations: " + why;
}

// RANSAC on the outliers of the first pose (second_pose_from_outliers): the pose found there,
// finished like the first, replaces it when it has more inliers, else becomes its alternative.
Status TrySecondPose(const std::vector<Eigen::Vector2d>& points_px, const std::vector<Eigen::Vector3d>& world_points,
                     const RadialCamera& camera, const AbsolutePoseOptions& options, const RansacOptions& ransac,
                     const std::vector<PoseCorrespondence>& samples, const std::vector<int>& sample_to_input,
                     const std::vector<char>& first_mask, AbsolutePoseResult* result) {
  std::vector<PoseCorrespondence> outliers;
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!first_mask[i]) outliers.push_back(samples[i]);
  }
  if (static_cast<int>(outliers.size()) <= P3PEstimator::kMinSamples) return Status::Ok();
  RECONAR_ASSIGN_OR_RETURN(const auto report, (Ransac<P3PEstimator, PoseLocalEstimator>::Run(outliers, ransac)));
  result->ransac_iterations += report.iterations;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  if (report.status != RansacStatus::kSuccess || !NearestPose(report.model, &R, &t)) return Status::Ok();
  std::vector<double> residuals(samples.size());
  P3PEstimator::Residuals(samples.data(), static_cast<int>(samples.size()), report.model, residuals.data());
  const double t2 = ransac.max_residual * ransac.max_residual;
  std::vector<char> mask(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) mask[i] = residuals[i] < t2 ? 1 : 0;
  AbsolutePoseResult second;
  FinishPose(points_px, world_points, camera, options, options.refine_focal, R, t,
             MaskToIndices(mask, sample_to_input), &second);
  if (second.num_inliers <= P3PEstimator::kMinSamples) return Status::Ok();
  AlternativePose other;
  if (second.num_inliers > result->num_inliers) {
    second.ransac_iterations = result->ransac_iterations;
    other = {result->cam_from_world, std::move(result->inliers)};
    *result = std::move(second);
  } else {
    other = {second.cam_from_world, std::move(second.inliers)};
  }
  result->alternatives.push_back(std::move(other));
  return Status::Ok();
}

}  // namespace

Status AbsolutePoseOptions::Check() const {
  if (!(max_error_px > 0.0) || !std::isfinite(max_error_px)) {
    return InvalidArgument("AbsolutePoseOptions.max_error_px must be positive and finite, got " +
                           std::to_string(max_error_px));
  }
  if (min_inliers < P3PEstimator::kMinSamples + 1) {
    return InvalidArgument("AbsolutePoseOptions.min_inliers must be >= 4, got " + std::to_string(min_inliers));
  }
  RansacOptions ransac_checked = ransac;
  ransac_checked.max_residual = 1.0;  // replaced by max_error_px / focal
  RECONAR_RETURN_IF_ERROR(ransac_checked.Check());
  return refinement.Check();
}

const char* AbsolutePoseOutcomeName(AbsolutePoseResult::Outcome outcome) {
  switch (outcome) {
    case AbsolutePoseResult::Outcome::kSuccess: return "success";
    case AbsolutePoseResult::Outcome::kTooFewCorrespondences: return "too few correspondences";
    case AbsolutePoseResult::Outcome::kNoModel: return "no model";
    case AbsolutePoseResult::Outcome::kTooFewInliers: return "too few inliers";
  }
  return "unknown";
}

Result<AbsolutePoseResult> EstimateAbsolutePose(const std::vector<Eigen::Vector2d>& points_px,
                                                const std::vector<Eigen::Vector3d>& world_points,
                                                const RadialCamera& camera,
                                                const AbsolutePoseOptions& options) {
  RECONAR_RETURN_IF_ERROR(CheckCamera(camera));
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(CheckPoseInputSizes(points_px, world_points, "EstimateAbsolutePose"));

  std::vector<PoseCorrespondence> samples;
  std::vector<int> sample_to_input;
  samples.reserve(points_px.size());
  sample_to_input.reserve(points_px.size());
  for (size_t i = 0; i < points_px.size(); ++i) {
    Eigen::Vector2d normalised;
    if (!points_px[i].allFinite() || !world_points[i].allFinite() || !camera.Undistort(points_px[i], &normalised)) {
      continue;
    }
    samples.push_back(PoseCorrespondence{normalised, world_points[i]});
    sample_to_input.push_back(static_cast<int>(i));
  }

  AbsolutePoseResult result;
  result.focal = camera.focal;
  const int needed = std::max(options.min_inliers, P3PEstimator::kMinSamples + 1);
  if (TooFewCorrespondences(static_cast<int>(samples.size()), static_cast<int>(points_px.size()), needed, &result)) {
    return result;
  }

  RansacOptions ransac = options.ransac;
  ransac.max_residual = options.max_error_px / camera.focal;
  RECONAR_ASSIGN_OR_RETURN(const auto report, (Ransac<P3PEstimator, PoseLocalEstimator>::Run(samples, ransac)));
  result.ransac_iterations = report.iterations;
  if (report.status != RansacStatus::kSuccess) {
    NoModel("every minimal sample was degenerate (collinear world points?) or gave no pose with the points in front "
            "of the camera",
            report.iterations, &result);
    return result;
  }
  Eigen::Matrix3d R;  // both estimators give poses; this removes the rounding from the rotation
  Eigen::Vector3d t;
  if (!NearestPose(report.model, &R, &t)) {
    NoModel("the best model is not a valid camera", report.iterations, &result);
    return result;
  }
  FinishPose(points_px, world_points, camera, options, options.refine_focal, R, t,
             MaskToIndices(report.inlier_mask, sample_to_input), &result);
  if (options.second_pose_from_outliers) {
    RECONAR_RETURN_IF_ERROR(TrySecondPose(points_px, world_points, camera, options, ransac, samples, sample_to_input,
                                          report.inlier_mask, &result));
  }
  return result;
}

Result<AbsolutePoseResult> EstimateAbsolutePoseUnknownFocal(const std::vector<Eigen::Vector2d>& points_px,
                                                            const std::vector<Eigen::Vector3d>& world_points,
                                                            const RadialCamera& camera,
                                                            const AbsolutePoseOptions& options) {
  RECONAR_RETURN_IF_ERROR(CheckCamera(camera));
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(CheckPoseInputSizes(points_px, world_points, "EstimateAbsolutePoseUnknownFocal"));

  // Centred pixels scaled by the prior focal: P = K' [R | t] with K' ~ diag(f / prior, f / prior, 1).
  std::vector<PoseCorrespondence> samples;
  std::vector<int> sample_to_input;
  samples.reserve(points_px.size());
  sample_to_input.reserve(points_px.size());
  const Eigen::Vector2d centre(camera.cx, camera.cy);
  for (size_t i = 0; i < points_px.size(); ++i) {
    if (!points_px[i].allFinite() || !world_points[i].allFinite()) continue;
    const Eigen::Vector2d centred = points_px[i] - centre;
    samples.push_back(PoseCorrespondence{Eigen::Vector2d(centred.x() / camera.focal, centred.y() / camera.fy()),
                                         world_points[i]});
    sample_to_input.push_back(static_cast<int>(i));
  }

  AbsolutePoseResult result;
  result.focal = camera.focal;
  const int needed = std::max(options.min_inliers, DltPoseEstimator::kMinSamples + 1);
  if (TooFewCorrespondences(static_cast<int>(samples.size()), static_cast<int>(points_px.size()), needed, &result)) {
    return result;
  }

  RansacOptions ransac = options.ransac;
  ransac.max_residual = options.max_error_px / camera.focal;
  RECONAR_ASSIGN_OR_RETURN(const auto report, Ransac<DltPoseEstimator>::Run(samples, ransac));
  result.ransac_iterations = report.iterations;
  if (report.status != RansacStatus::kSuccess) {
    NoModel("every minimal sample was degenerate (coplanar or collinear world points?) or gave no camera with the "
            "points in front of it",
            report.iterations, &result);
    return result;
  }
  Eigen::Matrix3d K, R;
  Eigen::Vector3d t;
  if (!DecomposeProjection(report.model, &K, &R, &t)) {
    NoModel("the best projection matrix is not a finite camera", report.iterations, &result);
    return result;
  }
  RadialCamera estimated = camera;
  estimated.focal = camera.focal * 0.5 * (K(0, 0) + K(1, 1));
  if (!(estimated.focal > 0.0) || !std::isfinite(estimated.focal)) {
    NoModel("the decomposed focal length is not positive", report.iterations, &result);
    return result;
  }
  FinishPose(points_px, world_points, estimated, options, /*refine_focal=*/true, R, t,
             MaskToIndices(report.inlier_mask, sample_to_input), &result);
  return result;
}

}  // namespace reconar
