#pragma once
// The GL clip transform of a pinhole camera, so that what the renderer draws lands exactly where
// CameraIntrinsics::Project puts it.
//
// Frames and pixels: camera frame x right, y down, z forward (COLMAP); pixel (u, v) with the centre
// of the top-left pixel at (0, 0) (core/math/camera_intrinsics.h). The renderer's framebuffers are
// stored top row first: GL window row y_w = v + 0.5 (not the usual bottom-up), so glReadPixels
// returns image rows in order and a texture uploaded row 0 first is sampled upright. Triangles
// facing the camera therefore wind clockwise in GL window coordinates.
//
//   x_clip = 2 fx / W * X + (2 (cx + 0.5) / W - 1) * Z
//   y_clip = 2 fy / H * Y + (2 (cy + 0.5) / H - 1) * Z
//   z_clip = (f + n) / (f - n) * Z - 2 f n / (f - n),   w_clip = Z
//
// Radial distortion (k1, k2) is not applied: straight lines stay straight. Draw on undistorted
// frames, or accept the error of the lens's distortion at the image border.
#include <Eigen/Core>

#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"

namespace reconar {

struct DepthRange {
  double near_m = 0.01;  // camera-frame depths outside [near_m, far_m] are clipped
  double far_m = 100.0;

  // InvalidArgument unless 0 < near_m < far_m and both are finite.
  Status Check() const;
};

// Intrinsics for a target of target_width x target_height pixels. When intrinsics.width/height are
// set and differ from the target, the pinhole is rescaled (pixel edges map to pixel edges:
// u' = (u + 0.5) * target_width / width - 0.5); with width/height 0 they are used as they are.
CameraIntrinsics IntrinsicsForTarget(const CameraIntrinsics& intrinsics, int target_width, int target_height);

// clip_from_cam for a target of `width` x `height` pixels (the formula above, in double).
Eigen::Matrix4d ClipFromCamera(const CameraIntrinsics& intrinsics, int width, int height, const DepthRange& depth);

}  // namespace reconar
