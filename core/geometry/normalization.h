#pragma once
// Hartley normalisation ("In defense of the eight-point algorithm", PAMI 1997): translate each
// image's points to their centroid and scale them so the mean distance from it is sqrt(2). It
// makes the DLT systems of the F and H estimators well conditioned.
#include <Eigen/Core>

#include "core/geometry/correspondence.h"

namespace reconar {

// Similarity transforms T1 (image a) and T2 (image b), x_normalised = T x. Returns false when the
// points of either image all coincide (or are not finite): no normalisation exists then.
bool HartleyNormalisation(const Correspondence* samples, int count, Eigen::Matrix3d* T1,
                          Eigen::Matrix3d* T2);

// Applies a similarity T = [s 0 tx; 0 s ty; 0 0 1] to a point.
// sum_i w_i r_i^T r_i over the epipolar rows r_i of the samples mapped by T1 / T2 (w_i = 1 when
// weights is null): the normal matrix whose smallest eigenvectors are the least-squares F.
Eigen::Matrix<double, 9, 9> EpipolarNormalMatrix(const Correspondence* samples, int count, const Eigen::Matrix3d& T1,
                                                 const Eigen::Matrix3d& T2, const double* weights = nullptr);

inline Eigen::Vector2d ApplySimilarity(const Eigen::Matrix3d& T, const Eigen::Vector2d& x) {
  return Eigen::Vector2d(T(0, 0) * x.x() + T(0, 2), T(1, 1) * x.y() + T(1, 2));
}

}  // namespace reconar
