#include "core/geometry/fundamental_seven_point.h"

#include <Eigen/LU>

#include "core/geometry/normalization.h"
#include "core/geometry/null_space.h"
#include "core/geometry/polynomial.h"
#include "core/geometry/residuals.h"
#include "core/math/adjugate.h"

namespace reconar {

int FundamentalSevenPoint::Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  Eigen::Matrix3d T1, T2;
  if (!HartleyNormalisation(samples, count, &T1, &T2)) return 0;

  Eigen::Matrix<double, 9, 2> basis;
  if (count == kMinSamples) {
    Eigen::Matrix<double, kMinSamples, 9> A;
    for (int i = 0; i < kMinSamples; ++i) {
      A.row(i) = EpipolarRow(ApplySimilarity(T1, samples[i].x1), ApplySimilarity(T2, samples[i].x2));
    }
    basis = NullSpaceOfWideMatrix<kMinSamples>(A);
  } else {
    const Eigen::Matrix<double, 9, 9> AtA = EpipolarNormalMatrix(samples, count, T1, T2);
    basis = SmallestEigenvectors<2>(AtA);
  }
  const Eigen::Matrix3d F1 = Matrix3FromVector(basis.col(0));
  const Eigen::Matrix3d F2 = Matrix3FromVector(basis.col(1));

  // F(l) = F2 + l D with D = F1 - F2. For 3x3 matrices
  // det(F2 + l D) = det F2 + l tr(adj(F2) D) + l^2 tr(adj(D) F2) + l^3 det D.
  const Eigen::Matrix3d D = F1 - F2;
  const double c0 = F2.determinant();
  const double c1 = (Adjugate(F2) * D).trace();
  const double c2 = (Adjugate(D) * F2).trace();
  const double c3 = D.determinant();
  double roots[3];
  const int num_roots = SolveCubicReal(c3, c2, c1, c0, roots);

  int num_models = 0;
  for (int i = 0; i < num_roots; ++i) {
    const Eigen::Matrix3d F = T2.transpose() * (F2 + roots[i] * D) * T1;
    const double norm = F.norm();
    if (!(norm > 0.0) || !F.allFinite()) continue;
    (*models)[num_models++] = F / norm;
  }
  return num_models;
}

void FundamentalSevenPoint::Residuals(const Sample* samples, int count, const Model& F,
                                      double* squared_residuals) {
  for (int i = 0; i < count; ++i) squared_residuals[i] = SquaredSampsonError(F, samples[i].x1, samples[i].x2);
}

}  // namespace reconar
