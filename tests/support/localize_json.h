#pragma once
// The lines of `reconar localize --json` (core/pipeline/localize_photos.h) and of `reconar track
// --json` / `reconar view --json` (tools/ar_output.h), read back for the localisation and tracking
// tests and benchmarks. Test support only.
#include <Eigen/Core>
#include <array>
#include <map>
#include <string>
#include <vector>

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

// One frame of `reconar track --json` / `reconar view --json`.
struct TrackedFrameTag {
  int id = -1;
  std::array<Eigen::Vector2d, 4> corners;  // libapriltag's order, pixels
};
struct TrackedFrame {
  std::string frame;
  std::vector<TrackedFrameTag> tags;  // measured in this frame
  // With --project: the pose's source ("tags", "map", "tags+map", "none"), the map tracker's state,
  // the world pose (when has_pose), the map's inliers. Empty source without --project.
  std::string source;
  std::string state;
  bool has_pose = false;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  int map_inliers = 0;
  // With --project: "metres", or "model" for a project without tags (its own arbitrary units).
  std::string units;
  double ms = 0.0;
};

// Every line of `output` that starts with '{', in order. CorruptData naming the line for one that
// is not JSON or lacks a field of the format.
Result<std::vector<TrackedFrame>> ParseTrackJson(const std::string& output);

}  // namespace reconar::testing
