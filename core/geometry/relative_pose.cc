#include "core/geometry/relative_pose.h"

#include <string>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "core/geometry/triangulation.h"

namespace reconar {

void DecomposeEssential(const Eigen::Matrix3d& E, std::array<Eigen::Matrix3d, 2>* rotations, Eigen::Vector3d* t) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  Eigen::Matrix3d V = svd.matrixV();
  // E is defined up to sign, so flipping a column sign of U or V (to make them rotations) only
  // changes E by that sign, leaving the solution set unchanged.
  if (U.determinant() < 0.0) U.col(2) *= -1.0;
  if (V.determinant() < 0.0) V.col(2) *= -1.0;
  Eigen::Matrix3d W;
  W << 0.0, -1.0, 0.0,  //
      1.0, 0.0, 0.0,    //
      0.0, 0.0, 1.0;
  (*rotations)[0] = U * W * V.transpose();
  (*rotations)[1] = U * W.transpose() * V.transpose();
  *t = U.col(2);
}

Result<RelativePose> RelativePoseFromEssential(const Eigen::Matrix3d& E, const Correspondence* correspondences,
                                               int count) {
  if (!E.allFinite()) return InvalidArgument("RelativePoseFromEssential: E is not finite");
  if (count < 1 || correspondences == nullptr) {
    return InvalidArgument("RelativePoseFromEssential: no correspondences (count " + std::to_string(count) + ")");
  }
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::Matrix3d>(E).singularValues();
  if (!(singular(1) > 1e-9 * singular(0))) {
    return InvalidArgument("RelativePoseFromEssential: E has rank < 2 (singular values " +
                           std::to_string(singular(0)) + ", " + std::to_string(singular(1)) + ")");
  }

  std::array<Eigen::Matrix3d, 2> rotations;
  Eigen::Vector3d u3;
  DecomposeEssential(E, &rotations, &u3);

  Matrix34d P1 = Matrix34d::Zero();
  P1.leftCols<3>().setIdentity();
  RelativePose best;
  best.num_in_front = -1;
  std::vector<char> mask(static_cast<size_t>(count));
  for (int candidate = 0; candidate < 4; ++candidate) {
    const Eigen::Matrix3d& R = rotations[candidate / 2];
    const Eigen::Vector3d t = (candidate % 2 == 0) ? u3 : Eigen::Vector3d(-u3);
    Matrix34d P2;
    P2 << R, t;
    int in_front = 0;
    for (int i = 0; i < count; ++i) {
      Eigen::Vector3d X;
      const bool ok = TriangulatePoint(P1, P2, correspondences[i].x1, correspondences[i].x2, &X) &&
                      PointDepth(P1, X) > 0.0 && PointDepth(P2, X) > 0.0;
      mask[i] = ok ? 1 : 0;
      in_front += ok ? 1 : 0;
    }
    if (in_front > best.num_in_front) {
      best.R = R;
      best.t = t;
      best.num_in_front = in_front;
      best.in_front_mask = mask;
    }
  }
  if (best.num_in_front <= 0) {
    return NumericFailure("RelativePoseFromEssential: no pose candidate puts any of the " + std::to_string(count) +
                          " correspondences in front of both cameras");
  }
  return best;
}

}  // namespace reconar
