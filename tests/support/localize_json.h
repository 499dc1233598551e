#pragma once
// The lines of `reconar localize --json` (core/pipeline/localize_photos.h), read back for the
// localisation tests and benchmarks. Test support only.
#include <Eigen/Core>
#include <map>
#include <string>

#include "core/base/status.h"
#include "core/math/radial_camera.h"

namespace reconar::testing {

struct LocalizedPhoto {
  bool registered = false;
  // X_cam = R * X_world + t, in the project's world frame; meaningful when registered.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  RadialCamera camera;  // fx, fy, cx, cy, k1, k2 of the line's "camera"; when registered
  int inliers = 0;
  double ms = 0.0;
  std::string reason;

  Eigen::Vector3d Centre() const { return -R.transpose() * t; }
};

// Every line of `output` that starts with '{', keyed by its "image". CorruptData naming the line
// for one that is not JSON or lacks a field of the format.
Result<std::map<std::string, LocalizedPhoto>> ParseLocalizeJson(const std::string& output);

}  // namespace reconar::testing
