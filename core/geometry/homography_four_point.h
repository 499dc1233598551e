#pragma once
// HomographyFourPoint: the normalised direct linear transform (Hartley & Zisserman, alg. 4.2).
// Each correspondence x2 ~ H x1 gives two rows of A vec(H) = 0 in Hartley-normalised
// coordinates; vec(H) is the null vector (4 points) or least-squares solution (more), then H is
// denormalised and scaled to unit Frobenius norm.
#include <array>

#include <Eigen/Core>

#include "core/geometry/correspondence.h"

namespace reconar {

struct HomographyFourPoint {
  using Sample = Correspondence;
  using Model = Eigen::Matrix3d;
  static constexpr int kMinSamples = 4;
  static constexpr int kMaxModels = 1;

  // count >= kMinSamples. Returns the number of models (0 for coincident points or a
  // non-finite result).
  static int Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models);

  // Squared transfer error ||x2 - pi(H x1)||^2 of each sample.
  static void Residuals(const Sample* samples, int count, const Model& H, double* squared_residuals);
};

}  // namespace reconar
