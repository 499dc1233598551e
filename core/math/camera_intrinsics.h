#pragma once
// Pinhole intrinsics with optional radial distortion (k1, k2), as live cameras use them: the
// tracker's pose estimation, `reconar calibrate`'s output and the renderer's projection.
// Pixel convention (DESIGN.md): the centre of the top-left pixel is (0, 0), x right, y down.
// A camera point X (z forward) maps to p = X.xy / X.z, d = 1 + k1 |p|^2 + k2 |p|^4,
// u = fx d p.x + cx, v = fy d p.y + cy.
#include <Eigen/Core>

namespace reconar {

struct CameraIntrinsics {
  int width = 0;  // 0 when unknown (e.g. given only as fx,fy,cx,cy on the command line)
  int height = 0;
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
  double k1 = 0.0;
  double k2 = 0.0;

  bool valid() const { return fx > 0.0 && fy > 0.0; }

  Eigen::Vector2d Distort(const Eigen::Vector2d& normalized) const {
    const double r2 = normalized.squaredNorm();
    return normalized * (1.0 + r2 * (k1 + k2 * r2));
  }
  Eigen::Vector2d Project(const Eigen::Vector3d& cam_point) const {
    const Eigen::Vector2d p = Distort(cam_point.head<2>() / cam_point.z());
    return Eigen::Vector2d(fx * p.x() + cx, fy * p.y() + cy);
  }
  // Normalised coordinates of a pixel; inverts the distortion by fixed-point iteration
  // (converges for the mild k1, k2 of real lenses).
  Eigen::Vector2d Unproject(const Eigen::Vector2d& pixel) const {
    const Eigen::Vector2d distorted((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
    Eigen::Vector2d p = distorted;
    if (k1 == 0.0 && k2 == 0.0) return p;
    for (int i = 0; i < 20; ++i) {
      const double r2 = p.squaredNorm();
      p = distorted / (1.0 + r2 * (k1 + k2 * r2));
    }
    return p;
  }
};

}  // namespace reconar
