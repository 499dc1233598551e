#pragma once
// Readers for the ground truth that ships with public datasets in ../shared/data (see each
// SOURCE.txt), and the geometry derived from it. Test support only.
#include <Eigen/Core>
#include <map>
#include <set>
#include <string>

#include "core/base/status.h"

namespace reconar::testing {

// Pinhole camera x ~ K * (cam_from_world_rotation * X + cam_from_world_translation).
struct GroundTruthCamera {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d cam_from_world_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d cam_from_world_translation = Eigen::Vector3d::Zero();
  int width = 0;
  int height = 0;
  Eigen::Vector3d Centre() const { return -cam_from_world_rotation.transpose() * cam_from_world_translation; }
};

// Strecha *.camera: K (3 lines), distortion, R = world_from_cam rotation (3 lines), C, "w h".
Result<GroundTruthCamera> ReadStrechaCamera(const std::string& path);

// F with x_b^T F x_a = 0 for pixel coordinates of cameras a and b.
Eigen::Matrix3d FundamentalFromCameras(const GroundTruthCamera& a, const GroundTruthCamera& b);

// Larger of the distances of x_a to the epipolar line of x_b and of x_b to that of x_a (pixels).
double SymmetricEpipolarDistance(const Eigen::Matrix3d& F, const Eigen::Vector2d& x_a, const Eigen::Vector2d& x_b);

std::string SharedDataPath(const std::string& relative);

// The tag ids listed per photo in a groundtruth.txt of tag photos (apriltag_swatbotics_mapping):
// "<image file> <id> <id> ..." per line.
Result<std::map<std::string, std::set<int>>> ReadListedTagIds(const std::string& path);

}  // namespace reconar::testing
