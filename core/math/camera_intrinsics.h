#pragma once
// The intrinsics record of a live camera (fx, fy, cx, cy, k1, k2 and the image size), as the
// tracker, `reconar calibrate`'s files and the renderer take it. The model is RadialCamera
// (core/math/radial_camera.h); Camera() converts.
// Pixel convention (DESIGN.md): the centre of the top-left pixel is (0, 0), x right, y down.
// A camera point X (z forward) maps to p = X.xy / X.z, d = 1 + k1 |p|^2 + k2 |p|^4,
// u = fx d p.x + cx, v = fy d p.y + cy.
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/math/radial_camera.h"

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

  // The one camera model with these parameters (focal = fx, aspect = fy / fx).
  RadialCamera Camera() const {
    RadialCamera camera;
    camera.focal = fx;
    camera.aspect = fy / fx;
    camera.cx = cx;
    camera.cy = cy;
    camera.k1 = k1;
    camera.k2 = k2;
    return camera;
  }
  Eigen::Vector2d Project(const Eigen::Vector3d& cam_point) const { return Camera().Project(cam_point); }
  // Normalised coordinates of a pixel (RadialCamera::Undistort); NaN when the pixel lies beyond
  // the region where the distortion is invertible.
  Eigen::Vector2d Unproject(const Eigen::Vector2d& pixel) const {
    Eigen::Vector2d normalised;
    if (!Camera().Undistort(pixel, &normalised)) {
      return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    }
    return normalised;
  }
};

// The same camera for images of width x height (a resampled copy of its images): fx, cx scale by
// width / this width, fy, cy by height / this height, pixel centres staying at integer
// coordinates. Unchanged when its own size is unknown (0) or equal.
inline CameraIntrinsics ScaledIntrinsics(const CameraIntrinsics& intrinsics, int width, int height) {
  CameraIntrinsics scaled = intrinsics;
  if (intrinsics.width > 0 && intrinsics.height > 0 && (intrinsics.width != width || intrinsics.height != height)) {
    const double sx = static_cast<double>(width) / intrinsics.width;
    const double sy = static_cast<double>(height) / intrinsics.height;
    scaled.fx = intrinsics.fx * sx;
    scaled.fy = intrinsics.fy * sy;
    scaled.cx = (intrinsics.cx + 0.5) * sx - 0.5;
    scaled.cy = (intrinsics.cy + 0.5) * sy - 0.5;
    scaled.width = width;
    scaled.height = height;
  }
  return scaled;
}

// Whether images of width_a x height_a and width_b x height_b have the same aspect ratio, within 1 %
// (false when the first size is not positive).
inline bool SameAspectRatio(int width_a, int height_a, int width_b, int height_b) {
  return width_a > 0 && height_a > 0 &&
         std::abs(static_cast<double>(width_a) * height_b - static_cast<double>(height_a) * width_b) <=
             0.01 * static_cast<double>(width_a) * height_b;
}

// ScaledIntrinsics for video or photos of another size with the same aspect ratio (a phone's
// video mode); InvalidArgument when the aspect ratios differ by more than 1 %.
inline Result<CameraIntrinsics> ScaleIntrinsicsToFrame(const CameraIntrinsics& photo, int width, int height) {
  if (photo.width == width && photo.height == height) return photo;
  if (!SameAspectRatio(photo.width, photo.height, width, height)) {
    return InvalidArgument("the project's photos are " + std::to_string(photo.width) + "x" +
                           std::to_string(photo.height) + ", the images " + std::to_string(width) + "x" +
                           std::to_string(height) + ": pass --intrinsics for this camera");
  }
  return ScaledIntrinsics(photo, width, height);
}

}  // namespace reconar
