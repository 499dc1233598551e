#pragma once
// RadialCamera: reconar's one camera model (projection, undistortion, Jacobians), used by the
// sparse model (SfmCamera), pose estimation (core/geometry/absolute_pose), tag registration, the
// tracker and calibration (CameraIntrinsics converts to it) and dense undistortion.
//
// Bundler's radial model (Snavely et al., "Photo Tourism", 2006, eq. 9) with a principal point and
// a pixel aspect ratio; COLMAP's RADIAL model when aspect = 1, its OPENCV model with p1 = p2 = 0
// otherwise. Conventions (DESIGN.md): camera frame x right, y down, z forward; the centre of the
// top-left pixel is (0, 0). A camera point X maps to
//   p = X.xy / X.z (the "normalised" point),  d(r2) = 1 + k1 r2 + k2 r2^2 with r2 = |p|^2,
//   u = f d p.x + cx,  v = a f d p.y + cy      (fx = f, fy = a f).
// The bundle adjuster projects through this model too (PixelFromNormalised and its Jacobian) over
// its parameter block, in core/optim/radial_camera_model.h.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace reconar {

struct RadialCamera {
  double focal = 0.0;  // fx, pixels (0: not set)
  double cx = 0.0;     // principal point, pixels
  double cy = 0.0;
  double k1 = 0.0;  // radial distortion
  double k2 = 0.0;
  double aspect = 1.0;  // fy / fx

  double fy() const { return aspect * focal; }

  // d(r2) = 1 + k1 r2 + k2 r2^2.
  double Distortion(double r2) const { return 1.0 + r2 * (k1 + k2 * r2); }

  // Pixel of the normalised point p.
  Eigen::Vector2d PixelFromNormalised(const Eigen::Vector2d& p) const {
    const double d = Distortion(p.squaredNorm());
    return Eigen::Vector2d(focal * d * p.x() + cx, aspect * focal * d * p.y() + cy);
  }

  // d pixel / d p at the normalised point p: diag(f, a f) (d I + 2 (k1 + 2 k2 r2) p p^T).
  Eigen::Matrix2d PixelFromNormalisedJacobian(const Eigen::Vector2d& p) const {
    const double r2 = p.squaredNorm();
    const double d = 1.0 + r2 * (k1 + r2 * k2);
    Eigen::Matrix2d jacobian =
        focal * (d * Eigen::Matrix2d::Identity() + 2.0 * (k1 + 2.0 * k2 * r2) * p * p.transpose());
    jacobian.row(1) *= aspect;
    return jacobian;
  }

  // Pixel of a camera point (X.z > 0 assumed).
  Eigen::Vector2d Project(const Eigen::Vector3d& cam_point) const {
    return PixelFromNormalised(cam_point.head<2>() / cam_point.z());
  }

  // The normalised point p whose pixel is `pixel`: |p| solves |q| = |p| d(|p|^2) for the distorted
  // normalised point q = ((u - cx) / f, (v - cy) / (a f)), by Newton's method from |p| = |q|.
  // False when it does not converge to a point where the distortion is still monotonic
  // (d(r^2) r increasing), i.e. beyond the valid image, or the pixel is not finite.
  bool Undistort(const Eigen::Vector2d& pixel, Eigen::Vector2d* normalised) const {
    const Eigen::Vector2d q((pixel.x() - cx) / focal, (pixel.y() - cy) / (aspect * focal));
    return UndistortNormalised(q, normalised);
  }

  // The radial part of Undistort: the undistorted normalised point of the distorted one q.
  bool UndistortNormalised(const Eigen::Vector2d& q, Eigen::Vector2d* normalised) const {
    const double rho_d = q.norm();
    if (!std::isfinite(rho_d)) return false;
    if (rho_d == 0.0 || (k1 == 0.0 && k2 == 0.0)) {
      *normalised = q;
      return true;
    }
    double rho = rho_d;
    constexpr int kMaxIterations = 20;
    for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
      const double r2 = rho * rho;
      const double g = rho * (1.0 + r2 * (k1 + r2 * k2)) - rho_d;
      const double dg = 1.0 + r2 * (3.0 * k1 + 5.0 * r2 * k2);
      if (!(dg > 0.0)) return false;
      const double step = g / dg;
      rho -= step;
      if (!(rho > 0.0)) return false;
      if (std::abs(step) <= 1e-14 * rho) break;
    }
    const double r2 = rho * rho;
    const double residual = rho * (1.0 + r2 * (k1 + r2 * k2)) - rho_d;
    if (!(std::abs(residual) <= 1e-10 * rho_d) || !(1.0 + r2 * (3.0 * k1 + 5.0 * r2 * k2) > 0.0)) return false;
    *normalised = q * (rho / rho_d);
    return true;
  }

  // The squared normalised radius r^2 at which the pixel radius r d(r^2) stops growing with r (the
  // smallest positive root of 1 + 3 k1 r^2 + 5 k2 r^4); infinity when it never stops. Farther off
  // the axis the distortion folds back: a point far outside the field of view projects inside it.
  double FoldRadiusSquared() const {
    const double discriminant = 9.0 * k1 * k1 - 20.0 * k2;
    if (discriminant < 0.0 || (k1 >= 0.0 && k2 >= 0.0)) return INFINITY;
    // Each branch in the form where the square root adds to 3 |k1| rather than cancelling it.
    return k1 < 0.0 ? 2.0 / (std::sqrt(discriminant) - 3.0 * k1) : (3.0 * k1 + std::sqrt(discriminant)) / (-10.0 * k2);
  }

  // The largest squared normalised radius |X.xy / X.z|^2 of a camera point that truly projects into
  // the frame of width x height: the undistorted radius of its farthest corner, within the fold
  // (a corner beyond the fold does not undistort). A point farther off the axis whose pixel lands
  // in the frame got there by the fold.
  double MaxValidRadiusSquared(int width, int height) const {
    double farthest_corner = 0.0;
    for (const Eigen::Vector2d& corner : {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(width - 0.5, -0.5),
                                         Eigen::Vector2d(-0.5, height - 0.5), Eigen::Vector2d(width - 0.5, height - 0.5)}) {
      Eigen::Vector2d normalised;
      farthest_corner = std::max(farthest_corner, Undistort(corner, &normalised) ? normalised.squaredNorm() : INFINITY);
    }
    return std::min(farthest_corner, FoldRadiusSquared());
  }

  // Every parameter finite, focal and aspect positive.
  bool IsValid() const {
    return focal > 0.0 && std::isfinite(focal) && aspect > 0.0 && std::isfinite(aspect) && std::isfinite(cx) &&
           std::isfinite(cy) && std::isfinite(k1) && std::isfinite(k2);
  }
};

}  // namespace reconar
