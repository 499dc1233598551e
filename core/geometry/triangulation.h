#pragma once
// Triangulation: the linear (homogeneous DLT) method of Hartley & Zisserman, sec. 12.2, for two
// views and for N views (then refined by Gauss-Newton), and the triangulation angle used to
// reject low-parallax points.
#include <vector>

#include <Eigen/Core>

#include "core/math/rigid3.h"

namespace reconar {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

// The 3D point X with x1 ~ P1 X and x2 ~ P2 X, minimising the algebraic error of the four
// equations x (P^3 X) - P^1 X = 0, y (P^3 X) - P^2 X = 0: the right singular vector of the 4x4
// system for its smallest singular value. The points are in the units of the P's (pixels with
// P = K [R | t], normalised coordinates with P = [R | t]). Returns false when the solution lies
// at infinity (parallel rays) or is not finite; *point is then unchanged.
bool TriangulatePoint(const Matrix34d& P1, const Matrix34d& P2, const Eigen::Vector2d& x1,
                      const Eigen::Vector2d& x2, Eigen::Vector3d* point);

// One view of a point for TriangulateMultiView: the camera's pose, the undistorted normalised image
// point (RadialCamera::Undistort) and the camera's focal, which scales the residuals to pixels.
struct TriangulationView {
  Rigid3 cam_from_world;
  Eigen::Vector2d normalised = Eigen::Vector2d::Zero();
  double focal = 1.0;
};

// The point seen by all `views` (two or more): the eigenvector of the smallest eigenvalue of the
// normal matrix of the stacked DLT equations (H&Z sec. 12.2), then up to 5 Gauss-Newton steps on
// sum |focal (hnormalized(R X + t) - normalised)|^2. False when the linear solution lies at
// infinity, the point falls behind a view during the refinement, or it is not finite; *point is
// then unchanged.
bool TriangulateMultiView(const std::vector<TriangulationView>& views, Eigen::Vector3d* point);

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
