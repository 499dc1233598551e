#pragma once
// Two-view geometric verification of putative matches. F is estimated by LO-RANSAC around the
// normalised eight-point algorithm (least-squares eight-point for the local optimisation and a
// final refit on all inliers); a homography is then fitted by RANSAC to the F-inliers. When H
// explains most of them the pair has too little parallax for F to be meaningful (a planar
// scene, or a camera that only rotated). Thresholds are fractions of the larger image side:
// 0.6 % for F (Sampson distance) and 0.4 % for H (transfer error), and a pair needs 100 inliers.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/geometry/ransac_options.h"

namespace reconar {

struct TwoViewOptions {
  // Inlier thresholds as fractions of max(width_a, height_a, width_b, height_b).
  double f_threshold_fraction = 0.006;
  double h_threshold_fraction = 0.004;
  // F-inliers a pair needs to count as matched.
  int min_inliers = 100;
  // num_h_inliers / num_f_inliers at or above which the pair is kPlanarOrRotation.
  double max_h_inlier_ratio = 0.8;
  // H-RANSAC draws just enough samples to find, with probability ransac.confidence, a homography
  // explaining at least this fraction of the F-inliers (~270 samples for 0.4). Smaller ratios,
  // far below max_h_inlier_ratio, may be under-estimated. In (0, max_h_inlier_ratio].
  double h_screening_inlier_ratio = 0.4;
  // Iterations of the robust final refit of F on its inliers after RANSAC (Sampson-weighted
  // eight-point with Cauchy weights, kept while the truncated Cauchy cost decreases).
  int final_refinement_iterations = 10;
  // RANSAC settings for both estimations; max_residual is replaced by the thresholds above and
  // the H run uses seed + 1.
  RansacOptions ransac;

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

struct TwoViewGeometry {
  enum class Config {
    kVerified,          // >= min_inliers F-inliers and num_h_inliers / num_f_inliers < max_h_inlier_ratio
    kPlanarOrRotation,  // >= min_inliers F-inliers and num_h_inliers / num_f_inliers >= max_h_inlier_ratio:
                        // H explains most F-inliers, so low parallax; the inliers are still good matches
    kTooFewInliers,     // fewer than min_inliers putative matches, F-RANSAC found no model, or the best F
                        // has fewer than min_inliers inliers (see `reason`)
  };
  Config config = Config::kTooFewInliers;
  std::string reason;                        // human-readable explanation of `config`
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();  // x_b^T F x_a = 0, unit Frobenius norm (zero if none)
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // x_b ~ H x_a, unit Frobenius norm (zero if none)
  std::vector<int> inliers;                  // indices into the input of the F-inliers, ascending
  int num_f_inliers = 0;
  int num_h_inliers = 0;                     // H-inliers among the F-inliers (see h_screening_inlier_ratio)
  double h_to_f_inlier_ratio = 0.0;          // num_h_inliers / num_f_inliers (0 if no F-inliers)
  double f_threshold_px = 0.0;               // thresholds actually used
  double h_threshold_px = 0.0;
  int f_iterations = 0;                      // RANSAC minimal samples drawn
  int h_iterations = 0;
};

const char* TwoViewConfigName(TwoViewGeometry::Config config);

// points_a[i] <-> points_b[i] are putative matches in pixel coordinates of images of the given
// sizes. InvalidArgument if the point vectors differ in length, a size is not positive, or the
// options fail Check(); every other outcome is a TwoViewGeometry whose `config` says what was
// found.
Result<TwoViewGeometry> VerifyTwoView(const std::vector<Eigen::Vector2d>& points_a,
                                      const std::vector<Eigen::Vector2d>& points_b, int width_a, int height_a,
                                      int width_b, int height_b, const TwoViewOptions& options);

}  // namespace reconar
