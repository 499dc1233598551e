#include "tests/support/ground_truth.h"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "core/base/atomic_file.h"

namespace reconar::testing {

Result<GroundTruthCamera> ReadStrechaCamera(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::istringstream in(text);
  double v[24];
  for (double& x : v) {
    if (!(in >> x)) return FileError(StatusCode::kCorruptData, path, "expected 24 numbers before the image size");
  }
  GroundTruthCamera camera;
  if (!(in >> camera.width >> camera.height)) return FileError(StatusCode::kCorruptData, path, "missing image size");
  camera.K << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
  Eigen::Matrix3d world_from_cam;
  world_from_cam << v[12], v[13], v[14], v[15], v[16], v[17], v[18], v[19], v[20];
  const Eigen::Vector3d centre(v[21], v[22], v[23]);
  camera.cam_from_world_rotation = world_from_cam.transpose();
  camera.cam_from_world_translation = -camera.cam_from_world_rotation * centre;
  return camera;
}

Eigen::Matrix3d FundamentalFromCameras(const GroundTruthCamera& a, const GroundTruthCamera& b) {
  const Eigen::Matrix3d b_from_a = b.cam_from_world_rotation * a.cam_from_world_rotation.transpose();
  const Eigen::Vector3d t = b.cam_from_world_translation - b_from_a * a.cam_from_world_translation;
  Eigen::Matrix3d t_cross;
  t_cross << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  return b.K.inverse().transpose() * t_cross * b_from_a * a.K.inverse();
}

double SymmetricEpipolarDistance(const Eigen::Matrix3d& F, const Eigen::Vector2d& x_a, const Eigen::Vector2d& x_b) {
  const Eigen::Vector3d a = x_a.homogeneous();
  const Eigen::Vector3d b = x_b.homogeneous();
  const Eigen::Vector3d line_in_b = F * a;
  const Eigen::Vector3d line_in_a = F.transpose() * b;
  const double residual = std::fabs(b.dot(line_in_b));
  return std::max(residual / line_in_b.head<2>().norm(), residual / line_in_a.head<2>().norm());
}

std::string SharedDataPath(const std::string& relative) { return std::string(RECONAR_SHARED_DATA_DIR) + "/" + relative; }

Result<std::map<std::string, std::set<int>>> ReadListedTagIds(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::map<std::string, std::set<int>> listed;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::string image;
    if (!(fields >> image)) continue;
    std::set<int>& ids = listed[image];
    for (int id; fields >> id;) ids.insert(id);
  }
  return listed;
}

}  // namespace reconar::testing
