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
#include "tests/support/localize_json.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar::testing {

// `RECONAR sfm IMAGES PROJECT OPTIONS` (RECONAR the executable), then PROJECT/sparse; Internal with
// the command's output when it fails or leaves no PROJECT/map/map.rmap.
Result<Reconstruction> BuildMapWithSfm(const std::string& reconar, const std::filesystem::path& images,
                                       const std::filesystem::path& project, const std::string& options);

// `RECONAR localize PROJECT QUERIES --json --threads 2`, parsed (localize_json.h); Internal with the command's output
// when it fails.
Result<std::map<std::string, LocalizedPhoto>> LocalizeWithJson(const std::string& reconar,
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
