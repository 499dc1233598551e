#pragma once
// Scoring `reconar localize --json` against ground truth, for the localisation tests: the query
// photos linked into a directory, the JSON lines parsed, the map's own registered cameras aligned
// to the ground truth with a 7-DoF similarity, and that similarity applied to a localised camera.
// Test support only.
#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/sfm/reconstruction.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar::testing {

// The files `names` of directory `data` symlinked into `dir` (created), which is returned.
std::filesystem::path LinkViews(const std::filesystem::path& dir, const std::string& data,
                                const std::vector<std::string>& names);

// One line of `reconar localize --json`; the pose and camera are meaningful when registered.
struct Localized {
  bool registered = false;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // cam_from_world, the map's frame
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double fx = 0, fy = 0, cx = 0, cy = 0, k1 = 0, k2 = 0;
  int inliers = 0;
  double ms = 0.0;
  std::string reason;
};

// The JSON lines of `output` (other lines skipped), keyed by image name. CorruptData naming the
// line for a line that does not parse or lacks a field.
Result<std::map<std::string, Localized>> ParseLocalizeJson(const std::string& output);

// `RECONAR sfm IMAGES PROJECT OPTIONS` (RECONAR the executable), then PROJECT/sparse; Internal with
// the command's output when it fails or leaves no PROJECT/map/map.rmap.
Result<Reconstruction> BuildMapWithSfm(const std::string& reconar, const std::filesystem::path& images,
                                       const std::filesystem::path& project, const std::string& options);

// `RECONAR localize PROJECT QUERIES --json --threads 2`, parsed; Internal with the command's output
// when it fails.
Result<std::map<std::string, Localized>> LocalizeWithJson(const std::string& reconar,
                                                          const std::filesystem::path& project,
                                                          const std::filesystem::path& queries);

// The map's registered cameras aligned to `truth` by their centres (CameraCenterErrors).
struct MapAlignment {
  std::set<std::string> in_map;  // names of the registered images
  CameraPoseErrors errors;       // errors.gt_from_estimate maps the map's frame to the truth's
};
// NotFound for a registered image without ground truth.
Result<MapAlignment> AlignMapToGroundTruth(const Reconstruction& model, const GroundTruthByName& truth);

// A localised camera (cam_from_world R, t in the map's frame) in the ground truth's frame.
CameraPose InTruthFrame(const Similarity3& gt_from_map, const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

}  // namespace reconar::testing
