#include "core/geometry/homography_four_point.h"

#include "core/geometry/normalization.h"
#include "core/geometry/null_space.h"
#include "core/geometry/residuals.h"

namespace reconar {
namespace {

// The two DLT rows of x2 ~ H x1 (cross product x2 x H x1 = 0, first two components, up to sign).
void DltRows(const Eigen::Vector2d& p, const Eigen::Vector2d& q, Eigen::Matrix<double, 1, 9>* row0,
             Eigen::Matrix<double, 1, 9>* row1) {
  *row0 << 0.0, 0.0, 0.0, -p.x(), -p.y(), -1.0, q.y() * p.x(), q.y() * p.y(), q.y();
  *row1 << p.x(), p.y(), 1.0, 0.0, 0.0, 0.0, -q.x() * p.x(), -q.x() * p.y(), -q.x();
}

}  // namespace

int HomographyFourPoint::Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  Eigen::Matrix3d T1, T2;
  if (!HartleyNormalisation(samples, count, &T1, &T2)) return 0;

  Eigen::Matrix<double, 9, 1> h;
  Eigen::Matrix<double, 1, 9> row0, row1;
  if (count == kMinSamples) {
    Eigen::Matrix<double, 2 * kMinSamples, 9> A;
    for (int i = 0; i < kMinSamples; ++i) {
      DltRows(ApplySimilarity(T1, samples[i].x1), ApplySimilarity(T2, samples[i].x2), &row0, &row1);
      A.row(2 * i) = row0;
      A.row(2 * i + 1) = row1;
    }
    h = NullSpaceOfWideMatrix<2 * kMinSamples>(A);
  } else {
    Eigen::Matrix<double, 9, 9> AtA = Eigen::Matrix<double, 9, 9>::Zero();
    for (int i = 0; i < count; ++i) {
      DltRows(ApplySimilarity(T1, samples[i].x1), ApplySimilarity(T2, samples[i].x2), &row0, &row1);
      AtA.selfadjointView<Eigen::Lower>().rankUpdate(row0.transpose());
      AtA.selfadjointView<Eigen::Lower>().rankUpdate(row1.transpose());
    }
    AtA.triangularView<Eigen::StrictlyUpper>() = AtA.transpose();
    h = SmallestEigenvectors<1>(AtA);
  }

  // H = T2^-1 H_normalised T1; T2 is a similarity, so its inverse is closed form.
  const double s2 = T2(0, 0);
  Eigen::Matrix3d T2_inverse;
  T2_inverse << 1.0 / s2, 0.0, -T2(0, 2) / s2,  //
      0.0, 1.0 / s2, -T2(1, 2) / s2,            //
      0.0, 0.0, 1.0;
  const Eigen::Matrix3d H = T2_inverse * Matrix3FromVector(h) * T1;
  const double norm = H.norm();
  if (!(norm > 0.0) || !H.allFinite()) return 0;
  (*models)[0] = H / norm;
  return 1;
}

void HomographyFourPoint::Residuals(const Sample* samples, int count, const Model& H, double* squared_residuals) {
  for (int i = 0; i < count; ++i) squared_residuals[i] = SquaredTransferError(H, samples[i].x1, samples[i].x2);
}

}  // namespace reconar
