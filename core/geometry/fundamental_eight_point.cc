#include "core/geometry/fundamental_eight_point.h"

#include <Eigen/SVD>

#include "core/geometry/normalization.h"
#include "core/geometry/null_space.h"
#include "core/geometry/residuals.h"

namespace reconar {

namespace {

// Closest rank-2 matrix in the Frobenius norm (Eckart-Young), taken back to pixel coordinates.
int FinishModel(const Eigen::Matrix<double, 9, 1>& f, const Eigen::Matrix3d& T1, const Eigen::Matrix3d& T2,
                std::array<Eigen::Matrix3d, FundamentalEightPoint::kMaxModels>* models) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(Matrix3FromVector(f), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d singular = svd.singularValues();
  singular(2) = 0.0;
  const Eigen::Matrix3d F_normalised = svd.matrixU() * singular.asDiagonal() * svd.matrixV().transpose();
  Eigen::Matrix3d F = T2.transpose() * F_normalised * T1;
  const double norm = F.norm();
  if (!(norm > 0.0) || !F.allFinite()) return 0;
  (*models)[0] = F / norm;
  return 1;
}

}  // namespace

int FundamentalEightPoint::EstimateWeighted(const Sample* samples, const double* weights, int count,
                                            std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  Eigen::Matrix3d T1, T2;
  if (!HartleyNormalisation(samples, count, &T1, &T2)) return 0;
  return FinishModel(SmallestEigenvectors<1>(EpipolarNormalMatrix(samples, count, T1, T2, weights)), T1, T2, models);
}

int FundamentalEightPoint::Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  Eigen::Matrix3d T1, T2;
  if (!HartleyNormalisation(samples, count, &T1, &T2)) return 0;

  Eigen::Matrix<double, 9, 1> f;
  if (count == kMinSamples) {
    Eigen::Matrix<double, kMinSamples, 9> A;
    for (int i = 0; i < kMinSamples; ++i) {
      A.row(i) = EpipolarRow(ApplySimilarity(T1, samples[i].x1), ApplySimilarity(T2, samples[i].x2));
    }
    f = NullSpaceOfWideMatrix<kMinSamples>(A);
  } else {
    const Eigen::Matrix<double, 9, 9> AtA = EpipolarNormalMatrix(samples, count, T1, T2);
    f = SmallestEigenvectors<1>(AtA);
  }

  return FinishModel(f, T1, T2, models);
}

void FundamentalEightPoint::Residuals(const Sample* samples, int count, const Model& F,
                                      double* squared_residuals) {
  for (int i = 0; i < count; ++i) squared_residuals[i] = SquaredSampsonError(F, samples[i].x1, samples[i].x2);
}

}  // namespace reconar
