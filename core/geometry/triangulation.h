#pragma once
// Two-view triangulation: the linear (homogeneous DLT) method of Hartley & Zisserman, sec. 12.2,
// and the triangulation angle used to reject low-parallax points.
#include <Eigen/Core>

namespace reconar {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

// The 3D point X with x1 ~ P1 X and x2 ~ P2 X, minimising the algebraic error of the four
// equations x (P^3 X) - P^1 X = 0, y (P^3 X) - P^2 X = 0: the right singular vector of the 4x4
// system for its smallest singular value. The points are in the units of the P's (pixels with
// P = K [R | t], normalised coordinates with P = [R | t]). Returns false when the solution lies
// at infinity (parallel rays) or is not finite; *point is then unchanged.
bool TriangulatePoint(const Matrix34d& P1, const Matrix34d& P2, const Eigen::Vector2d& x1,
                      const Eigen::Vector2d& x2, Eigen::Vector3d* point);

// Angle in radians at `point` between the rays to the projection centres c1 and c2; 0 when the
// point coincides with a centre.
double TriangulationAngle(const Eigen::Vector3d& c1, const Eigen::Vector3d& c2, const Eigen::Vector3d& point);

// Projection centre -R^T t of a camera with world-to-camera pose X_cam = R X + t.
inline Eigen::Vector3d ProjectionCenter(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  return -R.transpose() * t;
}

// Depth of `point` in a camera P = [R | t] (or K [R | t] with K(2,2) = 1): the third coordinate
// of P X, positive in front of the camera.
inline double PointDepth(const Matrix34d& P, const Eigen::Vector3d& point) {
  return P.row(2).head<3>().dot(point) + P(2, 3);
}

}  // namespace reconar
