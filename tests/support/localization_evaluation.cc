#include "tests/support/localization_evaluation.h"

#include <sstream>

#include "core/base/json_reader.h"
#include "core/sfm/model_io.h"
#include "tests/support/run_command.h"

namespace reconar::testing {

namespace fs = std::filesystem;

Result<Reconstruction> BuildMapWithSfm(const std::string& reconar, const fs::path& images, const fs::path& project,
                                       const std::string& options) {
  const std::string command = reconar + " sfm " + images.string() + " " + project.string() + " " + options;
  const CommandRun sfm = RunCommand(command);
  if (sfm.exit_code != 0) {
    return Internal(command + ": exit code " + std::to_string(sfm.exit_code) + "\n" + sfm.output);
  }
  if (!fs::exists(project / "map" / "map.rmap")) return Internal(command + ": no map/map.rmap\n" + sfm.output);
  return ReadColmapTextModel((project / "sparse").string());
}

Result<std::map<std::string, LocalizedPhoto>> LocalizeWithJson(const std::string& reconar, const fs::path& project,
                                                               const fs::path& queries) {
  const std::string command =
      reconar + " localize " + project.string() + " " + queries.string() + " --json --threads 2";
  const CommandRun localize = RunCommand(command, StderrMode::kSeparate);
  if (localize.exit_code != 0) {
    return Internal(command + ": exit code " + std::to_string(localize.exit_code) + "\n" + localize.output +
                    localize.error);
  }
  return ParseLocalizeJson(localize.output);
}

Result<MapAlignment> AlignMapToGroundTruth(const Reconstruction& model, const GroundTruthByName& truth) {
  MapAlignment alignment;
  std::vector<CameraPose> estimated, reference;
  for (const SfmImage& image : model.images) {
    if (!image.registered) continue;
    const auto gt = truth.find(image.name);
    if (gt == truth.end()) return NotFound(image.name + ": registered in the map but has no ground truth");
    alignment.in_map.insert(image.name);
    estimated.push_back({image.cam_from_world.rotation, image.Center()});
    reference.push_back(PoseOf(gt->second));
  }
  RECONAR_ASSIGN_OR_RETURN(alignment.errors, CameraCenterErrors(estimated, reference));
  return alignment;
}

CameraPose InTruthFrame(const Similarity3& gt_from_map, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  // X_map = (R_s^T (X_gt - t_s)) / s, so cam_from_gt = R * R_s^T and the centre maps like a point.
  return {R * gt_from_map.rotation.transpose(), gt_from_map.Apply(-R.transpose() * t)};
}

}  // namespace reconar::testing
