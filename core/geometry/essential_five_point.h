#pragma once
// EssentialFivePoint: the calibrated five-point relative-pose solver (Nister, "An efficient
// solution to the five-point relative pose problem", PAMI 2004), in the Groebner-basis /
// action-matrix form of Stewenius, Engels & Nister ("Recent developments on direct relative
// orientation", ISPRS 2006). Inputs are normalised image coordinates (K^-1 x). The five
// epipolar constraints leave a 4-dimensional null space E = x X + y Y + z Z + W; the cubic
// constraints det(E) = 0 and 2 E E^T E - tr(E E^T) E = 0 give 10 equations in the 20 monomials
// of degree <= 3 in (x, y, z). Eliminating the 10 cubic monomials expresses multiplication by x
// on the quotient-ring basis {x^2, xy, xz, y^2, yz, z^2, x, y, z, 1} as a 10x10 action matrix
// whose real eigenvalues/eigenvectors are the (up to 10) solutions.
// Convention: x2^T E x1 = 0, E = [t]x R for X2 = R X1 + t, unit Frobenius norm.
#include <array>

#include <Eigen/Core>

#include "core/geometry/correspondence.h"

namespace reconar {

struct EssentialFivePoint {
  using Sample = Correspondence;
  using Model = Eigen::Matrix3d;
  static constexpr int kMinSamples = 5;
  static constexpr int kMaxModels = 10;

  // count >= kMinSamples; with more than 5 samples the 4 least-squares null vectors are used.
  // Returns the number of real solutions (0..10; 0 for a degenerate sample).
  static int Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models);

  // Squared Sampson error of each sample (normalised-coordinate units squared: divide a pixel
  // threshold by the focal length before comparing).
  static void Residuals(const Sample* samples, int count, const Model& E, double* squared_residuals);
};

}  // namespace reconar
