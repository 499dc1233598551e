#pragma once
// Loading an AR scene: a project of `reconar reconstruct --tag-size` for AR (its model, tags.layout,
// tag size and family, and the photos' camera, scaled to the video), and the model to draw
// (simplified to a face budget for the handheld).
#include <memory>
#include <optional>
#include <string>

#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/mesh/mesh.h"
#include "core/mesh/simplify.h"
#include "core/sfm/localization_map.h"
#include "core/sfm/tag_layout.h"

namespace reconar {

// What `reconar view --project DIR` brings: the model in metres in the world frame, where each tag
// sits in it, the tags' size and family, the photos' camera, and the localisation map that poses
// the camera where no tag is in view.
struct ArProject {
  std::string model_path;  // the mesh, else the dense points, else the sparse points
  TagLayout layout;        // world_from_tag of every registered tag (PROJECT/tags.layout)
  double tag_size = 0.0;   // metres
  std::string family;
  std::optional<CameraIntrinsics> photo_intrinsics;  // the first camera of sparse/, if readable
  std::shared_ptr<const LocalizationMap> map;         // PROJECT/map/map.rmap; nullptr when absent or not asked for
};

struct ArProjectOptions {
  bool load_map = true;
};

// FailedPrecondition when the project's tags.json says the model is not in metres, or when its map
// is not in the tags' metric frame (a map built before the tags: `reconar map` rebuilds it); file
// errors of tags.json, tags.layout and the map (a damaged map is an error, not ignored).
Result<ArProject> LoadArProject(const std::string& dir, const ArProjectOptions& options = {});

struct ArModel {
  Mesh mesh;
  std::optional<SimplifyReport> simplified;  // set when the mesh was over the face budget
};

// The model file (core/mesh/mesh_file.h formats), simplified to at most max_faces triangles
// (0: as it is).
Result<ArModel> LoadArModel(const std::string& path, size_t max_faces);

}  // namespace reconar
