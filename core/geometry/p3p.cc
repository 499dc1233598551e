// Lambda Twist P3P (P3PEstimator in absolute_pose.h).
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "core/geometry/absolute_pose.h"
#include "core/geometry/polynomial.h"
#include "core/math/adjugate.h"

namespace reconar {
namespace {

// ---------------------------------------------------------------------------------------------
// Lambda Twist P3P.
// Unknowns are the distances lambda_i along the unit bearings y_i to the world points X_i:
// |lambda_i y_i - lambda_j y_j|^2 = a_ij = |X_i - X_j|^2, i.e. Lambda^T M_ij Lambda = a_ij with
// b_ij = y_i . y_j. The homogeneous combinations D1 = a23 M12 - a12 M23 and D2 = a23 M13 - a13 M23
// vanish on every solution; a real root gamma of det(D1 + gamma D2) = 0 makes D0 = D1 + gamma D2 a
// degenerate conic, a pair of planes through its null vector, each of which meets the conic of D2
// in (up to) two solution rays. Their scale follows from the a_ij, then Gauss-Newton polishes the
// three lambdas and R, t follow from the three camera-frame points. Unlike the paper, which
// eliminates lambda_1 on each plane, the two rays on a plane come from the 2x2 restriction of D2
// to it (no division by a possibly vanishing coefficient).

struct P3PSystem {
  double a12, a13, a23;  // squared world distances
  double b12, b13, b23;  // bearing cosines

  Eigen::Vector3d Residual(const Eigen::Vector3d& l) const {
    return Eigen::Vector3d(l(0) * l(0) + l(1) * l(1) - 2.0 * b12 * l(0) * l(1) - a12,
                           l(0) * l(0) + l(2) * l(2) - 2.0 * b13 * l(0) * l(2) - a13,
                           l(1) * l(1) + l(2) * l(2) - 2.0 * b23 * l(1) * l(2) - a23);
  }

  // Gauss-Newton on the three distance equations, kept while the residual decreases.
  void Polish(Eigen::Vector3d* lambda) const {
    Eigen::Vector3d r = Residual(*lambda);
    for (int iteration = 0; iteration < 5; ++iteration) {
      const Eigen::Vector3d& l = *lambda;
      Eigen::Matrix3d J;
      J << 2.0 * (l(0) - b12 * l(1)), 2.0 * (l(1) - b12 * l(0)), 0.0,  //
          2.0 * (l(0) - b13 * l(2)), 0.0, 2.0 * (l(2) - b13 * l(0)),   //
          0.0, 2.0 * (l(1) - b23 * l(2)), 2.0 * (l(2) - b23 * l(1));
      const double det = J.determinant();
      if (!(std::abs(det) > 0.0)) return;
      const Eigen::Vector3d next = l - J.inverse() * r;
      const Eigen::Vector3d r_next = Residual(next);
      if (!(r_next.squaredNorm() < r.squaredNorm())) return;
      *lambda = next;
      r = r_next;
    }
  }
};

// Directions v in the plane span{p, q} (orthonormal) with v^T D v = 0; appends up to two.
int RaysOnPlane(const Eigen::Matrix3d& D, const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                std::array<Eigen::Vector3d, 2>* rays) {
  Eigen::Matrix2d S;
  S(0, 0) = p.dot(D * p);
  S(0, 1) = S(1, 0) = p.dot(D * q);
  S(1, 1) = q.dot(D * q);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(S);
  const double mu1 = eigen.eigenvalues()(0), mu2 = eigen.eigenvalues()(1);
  // mu1 (f1 . v)^2 + mu2 (f2 . v)^2 = 0 needs eigenvalues of opposite sign (or one zero).
  if (mu1 > 0.0 || mu2 < 0.0) return 0;
  const Eigen::Vector2d f1 = eigen.eigenvectors().col(0), f2 = eigen.eigenvectors().col(1);
  const double s1 = std::sqrt(-mu1), s2 = std::sqrt(mu2);
  int count = 0;
  for (double sign : {1.0, -1.0}) {
    const Eigen::Vector2d v = s2 * f1 + sign * s1 * f2;
    (*rays)[count++] = v(0) * p + v(1) * q;
    if (s1 == 0.0 || s2 == 0.0) break;  // a double root
  }
  return count;
}

// R and t with lambda_i y_i = R X_i + t: R maps the world triangle's frame (two edges and their
// cross product) onto the camera's, projected onto the nearest rotation.
bool PoseFromCameraPoints(const std::array<Eigen::Vector3d, 3>& camera_points,
                          const std::array<Eigen::Vector3d, 3>& world, Matrix34d* pose) {
  Eigen::Matrix3d Y, X;
  Y.col(0) = camera_points[0] - camera_points[1];
  Y.col(1) = camera_points[0] - camera_points[2];
  Y.col(2) = Y.col(0).cross(Y.col(1));
  X.col(0) = world[0] - world[1];
  X.col(1) = world[0] - world[2];
  X.col(2) = X.col(0).cross(X.col(1));
  const Eigen::Matrix3d R_raw = Y * X.inverse();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R_raw, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0.0) return false;
  const Eigen::Vector3d t =
      (camera_points[0] + camera_points[1] + camera_points[2] - R * (world[0] + world[1] + world[2])) / 3.0;
  if (!R.allFinite() || !t.allFinite()) return false;
  pose->leftCols<3>() = R;
  pose->col(3) = t;
  return true;
}

}  // namespace

int P3PEstimator::Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  std::array<Eigen::Vector3d, 3> y, X;
  for (int i = 0; i < 3; ++i) {
    y[i] = samples[i].point.homogeneous().normalized();
    X[i] = samples[i].world;
  }
  P3PSystem system;
  system.a12 = (X[0] - X[1]).squaredNorm();
  system.a13 = (X[0] - X[2]).squaredNorm();
  system.a23 = (X[1] - X[2]).squaredNorm();
  system.b12 = y[0].dot(y[1]);
  system.b13 = y[0].dot(y[2]);
  system.b23 = y[1].dot(y[2]);
  // Collinear or coincident world points leave a rotation about their line free.
  const double largest = std::max({system.a12, system.a13, system.a23});
  const double area2 = (X[0] - X[1]).cross(X[0] - X[2]).squaredNorm();
  if (!(area2 > 1e-20 * largest * largest)) return 0;

  const double a12 = system.a12, a13 = system.a13, a23 = system.a23;
  const double b12 = system.b12, b13 = system.b13, b23 = system.b23;
  Eigen::Matrix3d M12, M13, M23;
  M12 << 1.0, -b12, 0.0, -b12, 1.0, 0.0, 0.0, 0.0, 0.0;
  M13 << 1.0, 0.0, -b13, 0.0, 0.0, 0.0, -b13, 0.0, 1.0;
  M23 << 0.0, 0.0, 0.0, 0.0, 1.0, -b23, 0.0, -b23, 1.0;
  const Eigen::Matrix3d D1 = a23 * M12 - a12 * M23;
  const Eigen::Matrix3d D2 = a23 * M13 - a13 * M23;

  // A real root of det(D1 + gamma D2); the smallest in magnitude keeps D1 from being drowned.
  // With no root the leading coefficient det(D2) vanished: D2 itself is the degenerate conic.
  const double c3 = D2.determinant();
  const double c2 = (Adjugate(D2).cwiseProduct(D1)).sum();
  const double c1 = (Adjugate(D1).cwiseProduct(D2)).sum();
  const double c0 = D1.determinant();
  double roots[3];
  const int num_roots = SolveCubicReal(c3, c2, c1, c0, roots);
  Eigen::Matrix3d D0 = D2;
  Eigen::Matrix3d D_other = D1;
  if (num_roots > 0) {
    double gamma = roots[0];
    for (int i = 1; i < num_roots; ++i) {
      if (std::abs(roots[i]) < std::abs(gamma)) gamma = roots[i];
    }
    D0 = D1 + gamma * D2;
    D_other = D2;
  }
  if (!D0.allFinite()) return 0;

  // D0 = sum sigma_k e_k e_k^T with one sigma ~ 0; the other two have opposite signs and
  // Lambda^T D0 Lambda = 0 splits into the planes sqrt|s_i| e_i . Lambda = +-sqrt|s_j| e_j . Lambda.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(D0);
  const Eigen::Vector3d sigma = eigen.eigenvalues();
  int zero = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(sigma(k)) < std::abs(sigma(zero))) zero = k;
  }
  const int i = zero == 0 ? 1 : 0;
  const int j = zero == 2 ? 1 : 2;
  if (!(sigma(i) * sigma(j) < 0.0)) return 0;
  const Eigen::Vector3d e_zero = eigen.eigenvectors().col(zero);
  const Eigen::Vector3d e_i = eigen.eigenvectors().col(i);
  const Eigen::Vector3d e_j = eigen.eigenvectors().col(j);
  const double s_i = std::sqrt(std::abs(sigma(i))), s_j = std::sqrt(std::abs(sigma(j)));

  int num_models = 0;
  for (double sign : {1.0, -1.0}) {
    // The plane (s_i e_i - sign s_j e_j) . Lambda = 0 is spanned by e_zero and s_j e_i + sign s_i e_j.
    const Eigen::Vector3d in_plane = (s_j * e_i + sign * s_i * e_j).normalized();
    std::array<Eigen::Vector3d, 2> rays;
    const int num_rays = RaysOnPlane(D_other, e_zero, in_plane, &rays);
    for (int r = 0; r < num_rays && num_models < kMaxModels; ++r) {
      const Eigen::Vector3d& ray = rays[r];
      // Scale from the sum of the three distance equations (a sum of positive semidefinite forms).
      const double form = ray.dot((M12 + M13 + M23) * ray);
      if (!(form > 0.0)) continue;
      double scale = std::sqrt((a12 + a13 + a23) / form);
      if (ray.sum() < 0.0) scale = -scale;
      Eigen::Vector3d lambda = scale * ray;
      if (!(lambda.minCoeff() > 0.0)) continue;
      system.Polish(&lambda);
      if (!(lambda.minCoeff() > 0.0)) continue;
      const std::array<Eigen::Vector3d, 3> camera_points = {lambda(0) * y[0], lambda(1) * y[1], lambda(2) * y[2]};
      if (PoseFromCameraPoints(camera_points, X, &(*models)[num_models])) ++num_models;
    }
  }
  return num_models;
}

void P3PEstimator::Residuals(const Sample* samples, int count, const Model& cam_from_world, double* squared_residuals) {
  for (int i = 0; i < count; ++i) squared_residuals[i] = SquaredReprojectionError(cam_from_world, samples[i]);
}

}  // namespace reconar
