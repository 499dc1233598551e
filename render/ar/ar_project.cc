#include "render/ar/ar_project.h"

#include <cmath>
#include <filesystem>
#include <system_error>

#include "core/base/json_reader.h"
#include "core/mesh/mesh_file.h"
#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"

namespace reconar {

Result<ArProject> LoadArProject(const std::string& dir, const ArProjectOptions& options) {
  const Project project(dir);
  ArProject scene;
  for (const std::string& path :
       {project.MeshDir() + "/mesh.ply", project.DensePointsPath(), project.SparseDir() + "/points.ply"}) {
    scene.model_path = path;
    std::error_code error;
    if (std::filesystem::exists(path, error)) break;
  }
  RECONAR_ASSIGN_OR_RETURN(const JsonValue tags, ReadJsonFile(project.TagsJsonPath()));
  const JsonValue* metric = tags.Find("metric");
  if (metric == nullptr || !metric->is_bool() || !metric->bool_value()) {
    const JsonValue* reason = tags.Find("reason");
    return FailedPrecondition(project.TagsJsonPath() + ": the model is not in metres (" +
                              (reason != nullptr && reason->is_string() ? reason->string() : "no tag registered") +
                              "); show it with --model and --model-height");
  }
  const JsonValue* size = tags.Find("tag_size_m");
  const JsonValue* family = tags.Find("family");
  if (size == nullptr || !size->is_number() || family == nullptr || !family->is_string()) {
    return FileError(StatusCode::kCorruptData, project.TagsJsonPath(), "no tag_size_m or family");
  }
  scene.tag_size = size->number();
  scene.family = family->string();
  RECONAR_ASSIGN_OR_RETURN(scene.layout, ReadTagLayout(project.TagLayoutPath()));
  if (auto model = ReadColmapTextModel(project.SparseDir()); model.ok() && !model->cameras.empty()) {
    scene.photo_intrinsics = model->cameras.front().Intrinsics();
  }
  std::error_code error;
  if (options.load_map && std::filesystem::exists(project.MapPath(), error)) {
    RECONAR_ASSIGN_OR_RETURN(LocalizationMap map, ReadLocalizationMap(project.MapPath()));
    if (!map.metric) {
      return FailedPrecondition(project.MapPath() + ": the map is not in the tags' metric frame (it is '" + map.frame +
                                "'); rebuild it with `reconar map " + dir + "`");
    }
    scene.map = std::make_shared<const LocalizationMap>(std::move(map));
  }
  return scene;
}

Result<ArModel> LoadArModel(const std::string& path, size_t max_faces) {
  ArModel model;
  RECONAR_ASSIGN_OR_RETURN(model.mesh, ReadMeshFile(path));
  auto simplified = SimplifyToFaceBudget(max_faces, &model.mesh);
  if (!simplified.ok()) return simplified.status().WithContext(path);
  if (simplified->simplified) model.simplified = *simplified;
  return model;
}

}  // namespace reconar
