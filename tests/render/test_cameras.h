#pragma once
// Intrinsics shared by the render tests: a 640 x 480 pinhole with fx != fy and a principal point
// away from the image centre, so that a transposed or centred projection shows.
#include "core/math/camera_intrinsics.h"

namespace reconar {
namespace testing {

inline CameraIntrinsics OffCentreCamera() {
  CameraIntrinsics intrinsics;
  intrinsics.width = 640;
  intrinsics.height = 480;
  intrinsics.fx = 712.25;
  intrinsics.fy = 655.5;
  intrinsics.cx = 301.3;
  intrinsics.cy = 251.7;
  return intrinsics;
}

}  // namespace testing
}  // namespace reconar
