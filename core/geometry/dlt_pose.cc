// The normalised DLT for a projection matrix, the nearest pose to one and its RQ decomposition
// (DltPoseEstimator, NearestPose, DecomposeProjection in absolute_pose.h).
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>

#include "core/geometry/absolute_pose.h"

namespace reconar {

int DltPoseEstimator::Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  // Hartley normalisation: image points to mean distance sqrt(2), world points to sqrt(3) from
  // their centroids (H&Z algorithm 7.1).
  Eigen::Vector2d image_centroid = Eigen::Vector2d::Zero();
  Eigen::Vector3d world_centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) {
    image_centroid += samples[i].point;
    world_centroid += samples[i].world;
  }
  image_centroid /= count;
  world_centroid /= count;
  double image_spread = 0.0, world_spread = 0.0;
  for (int i = 0; i < count; ++i) {
    image_spread += (samples[i].point - image_centroid).norm();
    world_spread += (samples[i].world - world_centroid).norm();
  }
  if (!(image_spread > 0.0) || !(world_spread > 0.0) || !std::isfinite(image_spread + world_spread)) return 0;
  const double image_scale = std::sqrt(2.0) * count / image_spread;
  const double world_scale = std::sqrt(3.0) * count / world_spread;

  // Each point gives p1 . X - u p3 . X = 0 and p2 . X - v p3 . X = 0 on vec(P) (row-major).
  Eigen::Matrix<double, 12, 12> AtA = Eigen::Matrix<double, 12, 12>::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d x = image_scale * (samples[i].point - image_centroid);
    const Eigen::Vector4d Xh = (world_scale * (samples[i].world - world_centroid)).homogeneous();
    Eigen::Matrix<double, 12, 1> row_u = Eigen::Matrix<double, 12, 1>::Zero();
    Eigen::Matrix<double, 12, 1> row_v = Eigen::Matrix<double, 12, 1>::Zero();
    row_u.head<4>() = Xh;
    row_u.tail<4>() = -x.x() * Xh;
    row_v.segment<4>(4) = Xh;
    row_v.tail<4>() = -x.y() * Xh;
    AtA.selfadjointView<Eigen::Lower>().rankUpdate(row_u);
    AtA.selfadjointView<Eigen::Lower>().rankUpdate(row_v);
  }
  AtA.triangularView<Eigen::StrictlyUpper>() = AtA.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> eigen(AtA);
  if (eigen.info() != Eigen::Success) return 0;
  // A second (near) null vector: coplanar world points (P + v pi^T fits as well as P).
  if (!(eigen.eigenvalues()(1) > 1e-10 * eigen.eigenvalues()(11))) return 0;
  const Eigen::Matrix<double, 12, 1> p = eigen.eigenvectors().col(0);
  Matrix34d P_normalised;
  P_normalised << p(0), p(1), p(2), p(3), p(4), p(5), p(6), p(7), p(8), p(9), p(10), p(11);

  Eigen::Matrix3d T_inverse = Eigen::Matrix3d::Identity();
  T_inverse(0, 0) = T_inverse(1, 1) = 1.0 / image_scale;
  T_inverse.topRightCorner<2, 1>() = image_centroid;
  Eigen::Matrix4d U = Eigen::Matrix4d::Identity();
  U.topLeftCorner<3, 3>() *= world_scale;
  U.topRightCorner<3, 1>() = -world_scale * world_centroid;
  Matrix34d P = T_inverse * P_normalised * U;
  const double det = P.leftCols<3>().determinant();
  const double row_norm = P.block<1, 3>(2, 0).norm();
  if (!(det != 0.0) || !(row_norm > 0.0) || !P.allFinite()) return 0;
  P *= (det > 0.0 ? 1.0 : -1.0) / row_norm;
  (*models)[0] = P;
  return 1;
}

void DltPoseEstimator::Residuals(const Sample* samples, int count, const Model& P, double* squared_residuals) {
  for (int i = 0; i < count; ++i) squared_residuals[i] = SquaredReprojectionError(P, samples[i]);
}

// GCC 12 inlines JacobiSVD::compute here (its only use in this file) and then reports the singular
// values as maybe uninitialised; compute always sets all three.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
bool NearestPose(const Matrix34d& P, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  if (!P.allFinite() || !(P.leftCols<3>().determinant() > 0.0)) return false;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(P.leftCols<3>(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double scale = svd.singularValues().mean();
  if (!(scale > 0.0)) return false;
  *R = svd.matrixU() * svd.matrixV().transpose();
  *t = P.col(3) / scale;
  return R->allFinite() && t->allFinite();
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

bool DecomposeProjection(const Matrix34d& P, Eigen::Matrix3d* K, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  const Eigen::Matrix3d M = P.leftCols<3>();
  if (!P.allFinite() || !(M.determinant() > 0.0)) return false;
  // RQ from QR: with the exchange matrix E, (E M)^T = Q U gives M = (E U^T E)(E Q^T), where
  // E U^T E is upper triangular and E Q^T orthogonal.
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
  E(0, 2) = E(1, 1) = E(2, 0) = 1.0;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((E * M).transpose());
  const Eigen::Matrix3d Q = qr.householderQ();
  const Eigen::Matrix3d upper = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d K_raw = E * upper.transpose() * E;
  Eigen::Matrix3d R_raw = E * Q.transpose();
  for (int k = 0; k < 3; ++k) {
    if (K_raw(k, k) < 0.0) {
      K_raw.col(k) = -K_raw.col(k);
      R_raw.row(k) = -R_raw.row(k);
    }
  }
  if (!(K_raw(2, 2) > 0.0) || !(R_raw.determinant() > 0.0)) return false;
  *t = K_raw.triangularView<Eigen::Upper>().solve(P.col(3));
  *K = K_raw / K_raw(2, 2);
  *R = R_raw;
  return K->allFinite() && R->allFinite() && t->allFinite();
}

}  // namespace reconar
