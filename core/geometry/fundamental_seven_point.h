#pragma once
// FundamentalSevenPoint: the seven-point algorithm (Hartley & Zisserman, sec. 11.1.2). The
// epipolar constraints of 7 (Hartley-normalised) points leave a 2-dimensional null space
// {F1, F2}; det(l F1 + (1 - l) F2) = 0 is a cubic in l whose 1 or 3 real roots give the
// candidate fundamental matrices, all exactly rank 2. Convention: x2^T F x1 = 0, unit Frobenius
// norm.
#include <array>

#include <Eigen/Core>

#include "core/geometry/correspondence.h"

namespace reconar {

struct FundamentalSevenPoint {
  using Sample = Correspondence;
  using Model = Eigen::Matrix3d;
  static constexpr int kMinSamples = 7;
  static constexpr int kMaxModels = 3;

  // count >= kMinSamples; with more than 7 samples the two least-squares null vectors are used.
  // Returns the number of models (0..3; 0 for a degenerate sample).
  static int Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models);

  // Squared Sampson error of each sample.
  static void Residuals(const Sample* samples, int count, const Model& F, double* squared_residuals);
};

}  // namespace reconar
