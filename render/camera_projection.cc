#include "render/camera_projection.h"

#include <cmath>
#include <string>

namespace reconar {

Status DepthRange::Check() const {
  if (!(std::isfinite(near_m) && std::isfinite(far_m) && near_m > 0.0 && near_m < far_m)) {
    return InvalidArgument("DepthRange: need 0 < near_m < far_m, got near_m=" + std::to_string(near_m) +
                           " far_m=" + std::to_string(far_m));
  }
  return Status::Ok();
}

CameraIntrinsics IntrinsicsForTarget(const CameraIntrinsics& intrinsics, int target_width, int target_height) {
  return ScaledIntrinsics(intrinsics, target_width, target_height);
}

Eigen::Matrix4d ClipFromCamera(const CameraIntrinsics& intrinsics, int width, int height, const DepthRange& depth) {
  const double w = width;
  const double h = height;
  const double n = depth.near_m;
  const double f = depth.far_m;
  Eigen::Matrix4d clip_from_cam = Eigen::Matrix4d::Zero();
  clip_from_cam(0, 0) = 2.0 * intrinsics.fx / w;
  clip_from_cam(0, 2) = 2.0 * (intrinsics.cx + 0.5) / w - 1.0;
  clip_from_cam(1, 1) = 2.0 * intrinsics.fy / h;
  clip_from_cam(1, 2) = 2.0 * (intrinsics.cy + 0.5) / h - 1.0;
  clip_from_cam(2, 2) = (f + n) / (f - n);
  clip_from_cam(2, 3) = -2.0 * f * n / (f - n);
  clip_from_cam(3, 2) = 1.0;
  return clip_from_cam;
}

}  // namespace reconar
