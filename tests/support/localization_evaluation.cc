#include "tests/support/localization_evaluation.h"

#include <sstream>

#include "core/base/json_reader.h"
#include "core/sfm/model_io.h"
#include "tests/support/run_command.h"

namespace reconar::testing {

namespace fs = std::filesystem;

fs::path LinkViews(const fs::path& dir, const std::string& data, const std::vector<std::string>& names) {
  fs::create_directories(dir);
  for (const std::string& name : names) fs::create_symlink(data + "/" + name, dir / name);
  return dir;
}

namespace {

Result<const JsonValue*> Field(const JsonValue& object, const std::string& key, int line) {
  const JsonValue* value = object.Find(key);
  if (value == nullptr) {
    return CorruptData("localize --json line " + std::to_string(line) + ": no \"" + key + "\"");
  }
  return value;
}

// One JSON line; its image name in *image.
Result<Localized> ParseLine(const std::string& text, int line, std::string* image) {
  RECONAR_ASSIGN_OR_RETURN(const JsonValue json, ParseJson(text, "localize --json line " + std::to_string(line)));
  RECONAR_ASSIGN_OR_RETURN(const JsonValue* name, Field(json, "image", line));
  *image = name->string();
  Localized entry;
  RECONAR_ASSIGN_OR_RETURN(const JsonValue* registered, Field(json, "registered", line));
  RECONAR_ASSIGN_OR_RETURN(const JsonValue* reason, Field(json, "reason", line));
  entry.registered = registered->bool_value();
  entry.reason = reason->string();
  if (const JsonValue* inliers = json.Find("inliers")) entry.inliers = static_cast<int>(inliers->number());
  if (const JsonValue* ms = json.Find("ms")) entry.ms = ms->number();
  if (!entry.registered) return entry;
  RECONAR_ASSIGN_OR_RETURN(const JsonValue* pose, Field(json, "cam_from_world", line));
  RECONAR_ASSIGN_OR_RETURN(const JsonValue* R, Field(*pose, "R", line));
  RECONAR_ASSIGN_OR_RETURN(const JsonValue* t, Field(*pose, "t", line));
  for (int i = 0; i < 9; ++i) entry.R(i / 3, i % 3) = (*R)[static_cast<size_t>(i)].number();
  for (int i = 0; i < 3; ++i) entry.t(i) = (*t)[static_cast<size_t>(i)].number();
  RECONAR_ASSIGN_OR_RETURN(const JsonValue* camera, Field(json, "camera", line));
  const std::pair<const char*, double*> intrinsics[] = {{"fx", &entry.fx}, {"fy", &entry.fy}, {"cx", &entry.cx},
                                                        {"cy", &entry.cy}, {"k1", &entry.k1}, {"k2", &entry.k2}};
  for (const auto& [key, value] : intrinsics) {
    RECONAR_ASSIGN_OR_RETURN(const JsonValue* field, Field(*camera, key, line));
    *value = field->number();
  }
  return entry;
}

}  // namespace

Result<std::map<std::string, Localized>> ParseLocalizeJson(const std::string& output) {
  std::map<std::string, Localized> result;
  std::istringstream lines(output);
  std::string line;
  int line_number = 0;
  while (std::getline(lines, line)) {
    ++line_number;
    if (line.empty() || line[0] != '{') continue;
    std::string image;
    RECONAR_ASSIGN_OR_RETURN(Localized entry, ParseLine(line, line_number, &image));
    result[image] = std::move(entry);
  }
  return result;
}

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

Result<std::map<std::string, Localized>> LocalizeWithJson(const std::string& reconar, const fs::path& project,
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
