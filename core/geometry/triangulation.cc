#include "core/geometry/triangulation.h"

#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace reconar {

bool TriangulatePoint(const Matrix34d& P1, const Matrix34d& P2, const Eigen::Vector2d& x1,
                      const Eigen::Vector2d& x2, Eigen::Vector3d* point) {
  Eigen::Matrix4d A;
  A.row(0) = x1.x() * P1.row(2) - P1.row(0);
  A.row(1) = x1.y() * P1.row(2) - P1.row(1);
  A.row(2) = x2.x() * P2.row(2) - P2.row(0);
  A.row(3) = x2.y() * P2.row(2) - P2.row(1);
  // Scaling each row to unit norm does not change the exact solution and balances the equations
  // of the two views (H&Z recommend normalising; this is the cheap, scale-invariant part of it).
  for (int r = 0; r < 4; ++r) {
    const double norm = A.row(r).norm();
    if (norm > 0.0) A.row(r) /= norm;
  }
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  const double scale = X.head<3>().cwiseAbs().maxCoeff();
  if (!(std::abs(X(3)) > 1e-12 * scale) || !X.allFinite()) return false;
  *point = X.head<3>() / X(3);
  return point->allFinite();
}

double TriangulationAngle(const Eigen::Vector3d& c1, const Eigen::Vector3d& c2, const Eigen::Vector3d& point) {
  const Eigen::Vector3d ray1 = c1 - point;
  const Eigen::Vector3d ray2 = c2 - point;
  const double norms = ray1.norm() * ray2.norm();
  if (!(norms > 0.0)) return 0.0;
  // atan2(|a x b|, a . b) is accurate for small angles, unlike acos of the normalised dot product.
  return std::atan2(ray1.cross(ray2).norm(), ray1.dot(ray2));
}

}  // namespace reconar
