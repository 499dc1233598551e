#include "core/geometry/triangulation.h"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
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

bool TriangulateMultiView(const std::vector<TriangulationView>& views, Eigen::Vector3d* point) {
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  for (const TriangulationView& view : views) {
    Eigen::Matrix<double, 3, 4> P;
    P << view.cam_from_world.rotation, view.cam_from_world.translation;
    const Eigen::RowVector4d r1 = view.normalised.x() * P.row(2) - P.row(0);
    const Eigen::RowVector4d r2 = view.normalised.y() * P.row(2) - P.row(1);
    normal += r1.transpose() * r1 + r2.transpose() * r2;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(normal);
  const Eigen::Vector4d X = eigen.eigenvectors().col(0);
  if (!(std::abs(X.w()) > 1e-12 * X.head<3>().norm())) return false;
  Eigen::Vector3d x = X.head<3>() / X.w();
  for (int iteration = 0; iteration < 5; ++iteration) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    for (const TriangulationView& view : views) {
      const double f = view.focal;
      const Eigen::Vector3d c = view.cam_from_world * x;
      if (!(c.z() > 0.0)) return false;
      const double iz = 1.0 / c.z();
      const Eigen::Vector2d r = f * (c.head<2>() * iz - view.normalised);
      Eigen::Matrix<double, 2, 3> dp;
      dp << iz, 0.0, -c.x() * iz * iz, 0.0, iz, -c.y() * iz * iz;
      const Eigen::Matrix<double, 2, 3> J = f * dp * view.cam_from_world.rotation;
      jtj += J.transpose() * J;
      jtr += J.transpose() * r;
    }
    const Eigen::Vector3d dx = jtj.ldlt().solve(-jtr);
    if (!dx.allFinite()) break;
    x += dx;
    if (dx.norm() < 1e-12 * (1.0 + x.norm())) break;
  }
  if (!x.allFinite()) return false;
  *point = x;
  return true;
}

}  // namespace reconar
