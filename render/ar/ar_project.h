#pragma once
// Loading an AR scene: a project of `reconar reconstruct` for AR (its model, its localisation map,
// the photos' cameras, and with --tag-size its tags.layout, tag size and family), the photos'
// camera for the video's size, and the model to draw (simplified to a face budget for the handheld).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/mesh/mesh.h"
#include "core/mesh/simplify.h"
#include "core/sfm/localization_map.h"
#include "core/sfm/tag_layout.h"

namespace reconar {

// What `reconar view --project DIR` brings: the model in its world frame, the localisation map that
// poses the camera in that frame, the photos' cameras, and when the project has tags (reconstructed
// with --tag-size, tags.json metric) where each tag sits in the world and their size and family:
// the world is then the world tag's frame in metres. Without tags the world is the model's own
// frame, in its arbitrary units, and the map alone poses the camera.
struct ArProject {
  // The textured mesh (mesh/textured.glb), else the mesh, else the dense points, else the sparse points.
  std::string model_path;
  bool has_tags = false;   // tags.json says the model is metric: layout, tag_size and family are set
  // Without tags: why not, and what that means for the poses (one line for the commands to print).
  std::string no_tags_note;
  TagLayout layout;        // world_from_tag of every registered tag (PROJECT/tags.layout)
  double tag_size = 0.0;   // metres
  std::string family;
  // The cameras of the registered photos (sparse/), the one most photos use first; empty when the
  // model is unreadable.
  std::vector<CameraIntrinsics> photo_cameras;
  std::shared_ptr<const LocalizationMap> map;  // PROJECT/map/map.rmap; nullptr when absent or not asked for
};

// The model a project shows: mesh/textured.glb, else mesh/mesh.ply, else the dense points, else
// the sparse points (the last when none exists, for the error to name).
std::string ProjectModelPath(const std::string& dir);

struct ArProjectOptions {
  bool load_map = true;
};

// With tags: FailedPrecondition when the map is not in the tags' metric frame (a map built before
// the tags: `reconar map` rebuilds it). Without tags (no tags.json, or one saying the model is not
// in metres) the map is required: NotFound naming the map's path and what to run when there is
// none, FailedPrecondition when it was not asked for. NotFound for a folder that does not exist;
// file errors of tags.json, tags.layout and the map (a damaged file is an error, not ignored).
Result<ArProject> LoadArProject(const std::string& dir, const ArProjectOptions& options = {});

// The photos' camera for frames of width x height: the first of `photo_cameras` (ArProject's
// order) of that size, else the first of that aspect ratio scaled to it (ScaleIntrinsicsToFrame).
// InvalidArgument naming the sizes when none fits (or there is none): --intrinsics is needed.
Result<CameraIntrinsics> PhotoCameraForFrame(const std::vector<CameraIntrinsics>& photo_cameras, int width,
                                             int height);

struct ArModel {
  Mesh mesh;
  std::vector<TexturePage> texture;  // RGB pages of a textured model (mesh.texcoords set); else empty
  std::optional<SimplifyReport> simplified;  // set when the mesh was over the face budget
};

// The model file (core/mesh/mesh_file.h formats; a glTF scene of several nodes whole, each node
// in its place), simplified to at most max_faces triangles (0: as it is). A .glb whose first
// primitive has a base colour texture (mesh/textured.glb) comes with its texture's pages and is not
// simplified (texturing already sized it; simplifying would tear its charts).
Result<ArModel> LoadArModel(const std::string& path, size_t max_faces);

// A registered design and the as-built points coloured by their deviation, in the model's frame.
struct ArDesign {
  Mesh design;
  Mesh deviation;
};

// What `reconar compare PROJECT DESIGN` left in PROJECT/compare for the view: the registered
// design (design_registered.glb, its elements joined) and the as-built points coloured by their
// deviation (deviation.ply), in the project's world frame. FailedPrecondition saying what to run
// when compare/report.json is missing or compared another design (by file name); file errors.
Result<ArDesign> LoadArDesign(const std::string& project_dir, const std::string& design_path);

}  // namespace reconar
