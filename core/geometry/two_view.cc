#include "core/geometry/two_view.h"

#include "core/geometry/residuals.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "core/base/median.h"
#include "core/geometry/correspondence.h"
#include "core/geometry/fundamental_eight_point.h"
#include "core/geometry/homography_four_point.h"
#include "core/geometry/ransac.h"

namespace reconar {
namespace {

// Indices i with residual_i < t2.
std::vector<int> InlierIndices(const std::vector<double>& squared_residuals, double t2) {
  std::vector<int> inliers;
  for (size_t i = 0; i < squared_residuals.size(); ++i) {
    if (squared_residuals[i] < t2) inliers.push_back(static_cast<int>(i));
  }
  return inliers;
}

// Least-squares eight-point refits on all inliers while the inlier set does not shrink.
// Iteratively reweighted least squares on the eight-point system. Each row is divided by its
// Sampson denominator, so the algebraic residual approximates the geometric (Sampson) distance
// (Torr & Murray, IJCV 1997), and weighted by Cauchy's function with scale 2.3849 * sigma, sigma
// being 1.4826 * the median inlier residual (MAD; Holland & Welsch's 95 %-efficiency constant).
// A refit is kept only when it lowers the truncated Cauchy cost over all matches, so one gross
// point that slipped under the threshold can no longer pull F towards itself.
void RefineFundamental(const std::vector<Correspondence>& matches, double t2, int iterations, Eigen::Matrix3d* F,
                       std::vector<int>* inliers) {
  if (inliers->size() < static_cast<size_t>(FundamentalEightPoint::kMinSamples)) return;
  std::vector<double> residuals(matches.size());
  FundamentalEightPoint::Residuals(matches.data(), static_cast<int>(matches.size()), *F, residuals.data());
  std::vector<double> inlier_errors;
  inlier_errors.reserve(inliers->size());
  for (int i : *inliers) inlier_errors.push_back(std::sqrt(residuals[i]));
  const double sigma = 1.4826 * MedianInPlace(inlier_errors.data(), inlier_errors.size());
  if (!(sigma > 0.0)) return;
  const double c2 = (2.3849 * sigma) * (2.3849 * sigma);
  const auto robust_cost = [&](const Eigen::Matrix3d& model) {
    FundamentalEightPoint::Residuals(matches.data(), static_cast<int>(matches.size()), model, residuals.data());
    double cost = 0;
    for (double r2 : residuals) cost += std::log1p(std::min(r2, t2) / c2);
    return cost;
  };
  double current_cost = robust_cost(*F);
  std::vector<Correspondence> subset;
  std::vector<double> weights;
  std::array<Eigen::Matrix3d, FundamentalEightPoint::kMaxModels> models;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    subset.clear();
    weights.clear();
    for (int i : *inliers) {
      const SampsonTerms terms = SampsonParts(*F, matches[i].x1, matches[i].x2);
      if (!(terms.denominator > 0.0)) continue;
      subset.push_back(matches[i]);
      weights.push_back(1.0 / ((1.0 + residuals[i] / c2) * terms.denominator));
    }
    if (FundamentalEightPoint::EstimateWeighted(subset.data(), weights.data(), static_cast<int>(subset.size()),
                                                &models) == 0) {
      return;
    }
    const double refined_cost = robust_cost(models[0]);
    if (!(refined_cost <= current_cost)) {
      FundamentalEightPoint::Residuals(matches.data(), static_cast<int>(matches.size()), *F, residuals.data());
      return;
    }
    const bool converged = refined_cost > current_cost * (1.0 - 1e-9);
    current_cost = refined_cost;
    *F = models[0];
    *inliers = InlierIndices(residuals, t2);
    if (converged) return;
  }
}

}  // namespace

Status TwoViewOptions::Check() const {
  if (!(f_threshold_fraction > 0.0 && f_threshold_fraction < 1.0)) {
    return InvalidArgument("TwoViewOptions.f_threshold_fraction must be in (0, 1), got " +
                           std::to_string(f_threshold_fraction));
  }
  if (!(h_threshold_fraction > 0.0 && h_threshold_fraction < 1.0)) {
    return InvalidArgument("TwoViewOptions.h_threshold_fraction must be in (0, 1), got " +
                           std::to_string(h_threshold_fraction));
  }
  if (min_inliers < FundamentalEightPoint::kMinSamples) {
    return InvalidArgument("TwoViewOptions.min_inliers must be >= 8, got " + std::to_string(min_inliers));
  }
  if (!(max_h_inlier_ratio > 0.0) || !std::isfinite(max_h_inlier_ratio)) {
    return InvalidArgument("TwoViewOptions.max_h_inlier_ratio must be positive, got " +
                           std::to_string(max_h_inlier_ratio));
  }
  if (!(h_screening_inlier_ratio > 0.0 && h_screening_inlier_ratio <= max_h_inlier_ratio)) {
    return InvalidArgument("TwoViewOptions.h_screening_inlier_ratio must be in (0, max_h_inlier_ratio], got " +
                           std::to_string(h_screening_inlier_ratio));
  }
  if (final_refinement_iterations < 0) {
    return InvalidArgument("TwoViewOptions.final_refinement_iterations must be >= 0");
  }
  return ransac.Check().WithContext("TwoViewOptions.ransac");
}

const char* TwoViewConfigName(TwoViewGeometry::Config config) {
  switch (config) {
    case TwoViewGeometry::Config::kVerified: return "verified";
    case TwoViewGeometry::Config::kPlanarOrRotation: return "planar or rotation";
    case TwoViewGeometry::Config::kTooFewInliers: return "too few inliers";
  }
  return "unknown";
}

Result<TwoViewGeometry> VerifyTwoView(const std::vector<Eigen::Vector2d>& points_a,
                                      const std::vector<Eigen::Vector2d>& points_b, int width_a, int height_a,
                                      int width_b, int height_b, const TwoViewOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (points_a.size() != points_b.size()) {
    return InvalidArgument("VerifyTwoView: " + std::to_string(points_a.size()) + " points in image a but " +
                           std::to_string(points_b.size()) + " in image b");
  }
  if (width_a <= 0 || height_a <= 0 || width_b <= 0 || height_b <= 0) {
    return InvalidArgument("VerifyTwoView: image sizes must be positive, got " + std::to_string(width_a) + "x" +
                           std::to_string(height_a) + " and " + std::to_string(width_b) + "x" +
                           std::to_string(height_b));
  }

  TwoViewGeometry geometry;
  const double max_side = std::max({width_a, height_a, width_b, height_b});
  geometry.f_threshold_px = options.f_threshold_fraction * max_side;
  geometry.h_threshold_px = options.h_threshold_fraction * max_side;
  const int num_matches = static_cast<int>(points_a.size());
  if (num_matches < options.min_inliers) {
    geometry.reason = std::to_string(num_matches) + " putative matches, fewer than the " +
                      std::to_string(options.min_inliers) + " inliers required";
    return geometry;
  }

  std::vector<Correspondence> matches(points_a.size());
  for (size_t i = 0; i < matches.size(); ++i) matches[i] = Correspondence{points_a[i], points_b[i]};

  // F: LO-RANSAC with the minimal and least-squares eight-point algorithm.
  RansacOptions f_options = options.ransac;
  f_options.max_residual = geometry.f_threshold_px;
  Result<RansacReport<Eigen::Matrix3d>> f_report = Ransac<FundamentalEightPoint>::Run(matches, f_options);
  RECONAR_RETURN_IF_ERROR(f_report.status());
  geometry.f_iterations = f_report->iterations;
  if (f_report->status != RansacStatus::kSuccess) {
    geometry.reason = std::string("F-RANSAC found no model (") + RansacStatusName(f_report->status) + ") in " +
                      std::to_string(num_matches) + " putative matches";
    return geometry;
  }
  Eigen::Matrix3d F = f_report->model;
  std::vector<int> inliers;
  for (int i = 0; i < num_matches; ++i) {
    if (f_report->inlier_mask[i]) inliers.push_back(i);
  }
  RefineFundamental(matches, f_options.max_residual * f_options.max_residual, options.final_refinement_iterations,
                    &F, &inliers);
  geometry.F = F;
  geometry.num_f_inliers = static_cast<int>(inliers.size());
  if (geometry.num_f_inliers < options.min_inliers) {
    geometry.reason = std::to_string(geometry.num_f_inliers) + " F-inliers of " + std::to_string(num_matches) +
                      " putative matches, fewer than the " + std::to_string(options.min_inliers) + " required";
    return geometry;
  }
  geometry.inliers = std::move(inliers);

  // H screening on the F-inliers.
  std::vector<Correspondence> f_inliers;
  f_inliers.reserve(geometry.inliers.size());
  for (int i : geometry.inliers) f_inliers.push_back(matches[i]);
  RansacOptions h_options = options.ransac;
  h_options.max_residual = geometry.h_threshold_px;
  h_options.seed = options.ransac.seed + 1;
  h_options.max_iterations = std::max(
      1, ransac_internal::RequiredIterationsForRatio(options.h_screening_inlier_ratio, HomographyFourPoint::kMinSamples,
                                                     h_options.confidence, options.ransac.max_iterations));
  h_options.min_iterations = std::min(h_options.min_iterations, h_options.max_iterations);
  Result<RansacReport<Eigen::Matrix3d>> h_report = Ransac<HomographyFourPoint>::Run(f_inliers, h_options);
  RECONAR_RETURN_IF_ERROR(h_report.status());
  geometry.h_iterations = h_report->iterations;
  if (h_report->status == RansacStatus::kSuccess) {
    geometry.H = h_report->model;
    geometry.num_h_inliers = h_report->num_inliers;
  }
  geometry.h_to_f_inlier_ratio = static_cast<double>(geometry.num_h_inliers) / geometry.num_f_inliers;

  const std::string counts = std::to_string(geometry.num_f_inliers) + " F-inliers of " +
                             std::to_string(num_matches) + " matches, " + std::to_string(geometry.num_h_inliers) +
                             " of them H-inliers (ratio " + std::to_string(geometry.h_to_f_inlier_ratio) + ")";
  if (geometry.h_to_f_inlier_ratio >= options.max_h_inlier_ratio) {
    geometry.config = TwoViewGeometry::Config::kPlanarOrRotation;
    geometry.reason = counts + ": a homography explains most inliers (planar scene or pure rotation)";
  } else {
    geometry.config = TwoViewGeometry::Config::kVerified;
    geometry.reason = counts;
  }
  return geometry;
}

}  // namespace reconar
