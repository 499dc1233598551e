#include "render/ar/ar_project.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "core/base/json_reader.h"
#include "core/io/image_io.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_file.h"
#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"

namespace reconar {

namespace {

// The cameras of the registered images, the one most images use first (ties: sparse/ order).
std::vector<CameraIntrinsics> RegisteredCameras(const Reconstruction& model) {
  std::vector<int> users(model.cameras.size(), 0);
  for (const SfmImage& image : model.images) {
    if (image.registered && image.camera_id >= 0 && static_cast<size_t>(image.camera_id) < users.size()) {
      ++users[static_cast<size_t>(image.camera_id)];
    }
  }
  std::vector<size_t> order;
  for (size_t i = 0; i < users.size(); ++i) {
    if (users[i] > 0) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return users[a] > users[b]; });
  std::vector<CameraIntrinsics> cameras;
  for (size_t i : order) cameras.push_back(model.cameras[i].Intrinsics());
  return cameras;
}

bool Exists(const std::string& path) {
  std::error_code error;
  return std::filesystem::exists(path, error);
}

}  // namespace

std::string ProjectModelPath(const std::string& dir) {
  const Project project(dir);
  const std::string candidates[] = {project.MeshDir() + "/textured.glb", project.MeshDir() + "/mesh.ply",
                                    project.DensePointsPath(), project.SparseDir() + "/points.ply"};
  for (const std::string& path : candidates) {
    if (Exists(path)) return path;
  }
  return candidates[std::size(candidates) - 1];
}

Result<ArProject> LoadArProject(const std::string& dir, const ArProjectOptions& options) {
  const Project project(dir);
  if (!Exists(dir)) return NotFound(dir + ": no such project folder");
  ArProject scene;
  scene.model_path = ProjectModelPath(dir);
  std::string no_tags_reason = "no " + project.TagsJsonPath() + ": reconstructed without --tag-size";
  if (Exists(project.TagsJsonPath())) {
    RECONAR_ASSIGN_OR_RETURN(const JsonValue tags, ReadJsonFile(project.TagsJsonPath()));
    const JsonValue* metric = tags.Find("metric");
    if (metric != nullptr && metric->is_bool() && metric->bool_value()) {
      const JsonValue* size = tags.Find("tag_size_m");
      const JsonValue* family = tags.Find("family");
      if (size == nullptr || !size->is_number() || family == nullptr || !family->is_string()) {
        return FileError(StatusCode::kCorruptData, project.TagsJsonPath(), "no tag_size_m or family");
      }
      scene.has_tags = true;
      scene.tag_size = size->number();
      scene.family = family->string();
      RECONAR_ASSIGN_OR_RETURN(scene.layout, ReadTagLayout(project.TagLayoutPath()));
    } else {
      const JsonValue* reason = tags.Find("reason");
      no_tags_reason = project.TagsJsonPath() + ": the model is not in metres (" +
                       (reason != nullptr && reason->is_string() ? reason->string() : "no tag registered") + ")";
    }
  }
  if (auto model = ReadColmapTextModel(project.SparseDir()); model.ok()) scene.photo_cameras = RegisteredCameras(*model);
  if (!scene.has_tags && !options.load_map) {
    return FailedPrecondition(dir + ": the project has no tags (" + no_tags_reason +
                              "): only its map can pose the frames (--no-map leaves it out)");
  }
  if (options.load_map && Exists(project.MapPath())) {
    RECONAR_ASSIGN_OR_RETURN(LocalizationMap map, ReadLocalizationMap(project.MapPath()));
    if (scene.has_tags && !map.metric) {
      return FailedPrecondition(project.MapPath() + ": the map is not in the tags' metric frame (it is '" + map.frame +
                                "'); rebuild it with `reconar map " + dir + "`");
    }
    scene.map = std::make_shared<const LocalizationMap>(std::move(map));
  }
  if (!scene.has_tags) {
    if (!scene.map) {
      const std::string to_run = Exists(project.SparseDir() + "/points3D.txt")
                                     ? "build it with `reconar map " + dir + "`"
                                     : "no sparse model either: run `reconar reconstruct IMAGES " + dir +
                                           "` (or `reconar sfm`), which writes the map";
      return FileError(StatusCode::kNotFound, project.MapPath(),
                       "no localisation map, and the project has no tags to pose the frames instead (" +
                           no_tags_reason + "): " + to_run);
    }
    scene.no_tags_note = "the project has no tags (" + no_tags_reason + "): posed by its map alone, " +
                         (scene.map->metric ? std::string("in metres (the map's frame)")
                                            : std::string("in the model's own units (its scale is arbitrary, not metres)"));
  }
  return scene;
}

Result<CameraIntrinsics> PhotoCameraForFrame(const std::vector<CameraIntrinsics>& photo_cameras, int width,
                                             int height) {
  for (const CameraIntrinsics& camera : photo_cameras) {
    if (camera.width == width && camera.height == height) return camera;
  }
  for (const CameraIntrinsics& camera : photo_cameras) {
    if (SameAspectRatio(camera.width, camera.height, width, height)) return ScaleIntrinsicsToFrame(camera, width, height);
  }
  if (photo_cameras.empty()) return InvalidArgument("the project has no registered camera: pass --intrinsics");
  std::string sizes;
  for (const CameraIntrinsics& camera : photo_cameras) {
    sizes += (sizes.empty() ? "" : ", ") + std::to_string(camera.width) + "x" + std::to_string(camera.height);
  }
  return InvalidArgument("the project's photos are " + sizes + ", the images " + std::to_string(width) + "x" +
                         std::to_string(height) + ": pass --intrinsics for this camera");
}

namespace {

bool IsGltf(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".glb" || extension == ".gltf";
}

}  // namespace

Result<ArModel> LoadArModel(const std::string& path, size_t max_faces) {
  ArModel model;
  if (const auto format = MeshFileFormatOf(path); format.ok() && *format == MeshFileFormat::kGlb) {
    RECONAR_ASSIGN_OR_RETURN(TexturedGlb textured, ReadTexturedGlb(path));
    if (!textured.pages.empty()) {
      for (size_t k = 0; k < textured.pages.size(); ++k) {
        auto decoded = ReadImageFromMemory(textured.pages[k].image, path + ": base colour texture" +
                                                                        (k > 0 ? " page " + std::to_string(k) : ""));
        if (!decoded.ok()) return decoded.status();
        model.texture.push_back({textured.pages[k].first_triangle, std::move(decoded->rgb)});
      }
      model.mesh = std::move(textured.mesh);
      return model;
    }
  }
  if (IsGltf(path)) {
    RECONAR_ASSIGN_OR_RETURN(const std::vector<NamedMesh> nodes, ReadGltfScene(path));
    model.mesh = JoinMeshes(nodes);
  } else {
    RECONAR_ASSIGN_OR_RETURN(model.mesh, ReadMeshFile(path));
  }
  auto simplified = SimplifyToFaceBudget(max_faces, &model.mesh);
  if (!simplified.ok()) return simplified.status().WithContext(path);
  if (simplified->simplified) model.simplified = *simplified;
  return model;
}

Result<ArDesign> LoadArDesign(const std::string& project_dir, const std::string& design_path) {
  const std::string compare_dir = project_dir + "/compare";
  const std::string run = "run `reconar compare " + project_dir + " " + design_path + "` first";
  std::error_code error;
  if (!std::filesystem::exists(compare_dir + "/report.json", error)) {
    return FailedPrecondition(project_dir + " has no comparison with a design (" + compare_dir + "/report.json): " + run);
  }
  RECONAR_ASSIGN_OR_RETURN(const JsonValue report, ReadJsonFile(compare_dir + "/report.json"));
  const JsonValue* compared = report.Find("design");
  const std::string compared_design = compared != nullptr && compared->is_string() ? compared->string() : "";
  if (std::filesystem::path(compared_design).filename() != std::filesystem::path(design_path).filename()) {
    return FailedPrecondition(compare_dir + " compares " + (compared_design.empty() ? "no design" : compared_design) +
                              ", not " + design_path + ": " + run);
  }
  ArDesign design;
  RECONAR_ASSIGN_OR_RETURN(const std::vector<NamedMesh> elements, ReadGltfScene(compare_dir + "/design_registered.glb"));
  design.design = JoinMeshes(elements);
  RECONAR_ASSIGN_OR_RETURN(design.deviation, ReadMeshFile(compare_dir + "/deviation.ply"));
  return design;
}

}  // namespace reconar
