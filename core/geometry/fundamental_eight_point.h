#pragma once
// FundamentalEightPoint: the normalised eight-point algorithm (Hartley, "In defense of the
// eight-point algorithm", PAMI 1997). Points are Hartley-normalised, vec(F) is the null vector
// (8 points) or least-squares solution (more points) of the stacked epipolar constraints, the
// rank-2 constraint is enforced by zeroing the smallest singular value, and F is denormalised.
// Convention: x2^T F x1 = 0, F scaled to unit Frobenius norm.
#include <array>

#include <Eigen/Core>

#include "core/geometry/correspondence.h"

namespace reconar {

struct FundamentalEightPoint {
  using Sample = Correspondence;
  using Model = Eigen::Matrix3d;
  static constexpr int kMinSamples = 8;
  static constexpr int kMaxModels = 1;

  // count >= kMinSamples; exactly 8 is the minimal solver (allocation-free), more is the least
  // squares fit. Returns the number of models written (0 for a degenerate sample: coincident
  // points or a non-finite result).
  static int Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models);
  // Weighted least squares: minimises sum_i weights[i] * (x2_i^T F x1_i)^2 in Hartley-normalised
  // coordinates (count >= kMinSamples, weights >= 0). Used by iteratively reweighted refinement.
  static int EstimateWeighted(const Sample* samples, const double* weights, int count,
                              std::array<Model, kMaxModels>* models);

  // Squared Sampson error of each sample (pixels^2 for pixel input).
  static void Residuals(const Sample* samples, int count, const Model& F, double* squared_residuals);
};

}  // namespace reconar
