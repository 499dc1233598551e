#pragma once
// The whole job (paper Fig. 2), `reconar reconstruct IMAGES_DIR PROJECT_DIR`: features -> matching
// -> tags (AprilTags in the photos, when a tag size is given) -> mapping (incremental SfM with the
// tag corners in bundle adjustment, then metric registration to the world tag) -> map (the
// localisation map for markerless AR, map_stage.h; part of the sparse stages) -> dense (CMVS +
// PMVS) -> mesh (screened Poisson, exports) -> texture (the mesh textured from the photos). Every stage writes its outputs atomically and is then
// recorded in PROJECT/stages.txt (stage_record.h) with its settings, so a re-run after an
// interruption (even SIGKILL) redoes only the stages that had not finished, and gives the same
// files: every stage is deterministic for any thread count.
//
// PROJECT/report.json (ReconstructReportJson) holds the paper's Table 1 quantities (images,
// registered, points, focal ratio mean and RMSE, 35 mm equivalent, dense points, mesh faces), the
// tag registration, and per stage whether it was reused, its seconds and its peak RSS.
//
// Memory: `memory_budget_bytes` bounds every stage: the number of photos decoded at once by the
// feature stage and its SIFT arena, the dense level and cluster size (dense_stage.h), the Poisson
// depth (mesh_stage.h). What a stage lowered to fit is said in the report.
//
// `reconar sfm` is this runner with the sparse stages only, so that `sfm` and `reconstruct` reuse
// each other's stages.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/pipeline/dense_stage.h"
#include "core/pipeline/feature_stage.h"
#include "core/pipeline/match_stage.h"
#include "core/pipeline/map_stage.h"
#include "core/pipeline/mesh_stage.h"
#include "core/pipeline/project.h"
#include "core/pipeline/sfm_stage.h"
#include "core/pipeline/texture_stage.h"
#include "core/sfm/tag_observations.h"

namespace reconar {

// Finds AprilTags in the photos (tracker/photo_tags.h; injected so that core stays free of
// libapriltag). Its result is stored as PROJECT/tags/detections.txt.
using TagDetectorFunction = std::function<Result<TagDetectionsFile>(const std::vector<std::string>& paths)>;

// Renders PROJECT/preview.png from a model file seen around `up` (render/ar/photo_render.h's
// WriteModelPreview; injected so that core stays free of the renderer).
using PreviewFunction =
    std::function<Status(const std::string& model_path, const Eigen::Vector3d& up, const std::string& png_path)>;

struct ReconstructOptions {
  // The product's defaults, where they differ from the stages' own (the building blocks that
  // `reconar match` and `reconar mesh` run with their library defaults):
  //  - matching: Lowe's ratio 0.8 (his paper's recommendation, and COLMAP's) rather than the
  //    stricter 0.6: mapping wants the extra matches, and RANSAC plus track triangulation remove
  //    the extra outliers; pairs count from 30 inliers, since wide-baseline pairs with few matches
  //    still tie tracks together (COLMAP keeps pairs from 15).
  //  - mesh: Poisson depth 10 (never finer than the points' spacing, lowered for the budget),
  //    density trim 7, at most kHandheldMaxFaces triangles.
  ReconstructOptions();

  bool run_sparse = true, run_dense = true, run_mesh = true;  // --stages; a stage needs the ones before
  // After the mesh: the textured model (texture_stage.h). A run that cannot texture (no photo sees
  // the mesh, a photo that does not decode) says why in the stage's note and keeps the untextured
  // mesh; it does not fail the run.
  bool run_texture = true;
  FeatureStageOptions features;
  MatchStageOptions matching;
  // mapper.principal_point, refine_distortion and max_reprojection_error_px (with the equal
  // registration_max_error_px) are `--principal-point`, `--fixed-distortion` and `--max-error`.
  SfmStageOptions sfm;  // sfm.tags.enabled follows tag_size_m > 0
  MapStageOptions map;  // part of the sparse stages
  DenseStageOptions dense;
  MeshStageOptions mesh;
  TextureStageOptions texture;
  double tag_size_m = 0.0;  // 0: no tags, the model keeps an arbitrary scale
  std::string tag_family = "tag36h11";
  TagDetectorFunction detect_tags;  // required when tag_size_m > 0
  PreviewFunction render_preview;   // empty: no PROJECT/preview.png
  size_t memory_budget_bytes = kDefaultMemoryBudgetBytes;
  int num_threads = 0;  // 0: one per core
  bool force = false;   // redo every stage
  // The photos the mapper registers only provisionally or not at all, and their partners, are
  // extracted again at the lower contrast threshold, matched again and mapped again, once
  // (weak_registrations.h). `--no-reextraction` turns it off, with the match stage's own rule.
  bool extract_weak_photos_again = true;
  bool show_progress = true;

  Status Check() const;
};

struct StageSummary {
  std::string name;
  bool reused = false;
  double seconds = 0.0;
  size_t peak_rss_bytes = 0;  // VmHWM over the stage (reset before it)
  std::string note;           // what the stage changed to fit the budget, or why it was skipped
};

// The paper's Table 1 columns (report.json "table1"), from the stages' own reports: zero for a
// stage that has not run.
struct Table1 {
  int images = 0, registered = 0, sparse_points = 0;
  double mean_focal_ratio = 0.0, rmse_focal_ratio = 0.0, focal_35mm_equivalent_mm = 0.0;
  long long dense_points = 0, mesh_vertices = 0, mesh_faces = 0;
};

struct ReconstructReport {
  std::vector<StageSummary> stages;
  Table1 table1;
  std::string report_path;
  bool metric = false;     // tags.json says the model is in metres
  std::string scale_note;  // why not, when not
  // PROJECT/preview.png of what the run made last (the textured model, else the mesh, else the
  // dense points, else the sparse points), seen around the cameras' mean up direction; empty when not rendered, and then
  // preview_error says why (a missing renderer or display does not fail the run).
  std::string preview_path, preview_error;
};

// image_paths as CollectImagePaths gives them. Errors name the stage and the file.
Result<ReconstructReport> RunReconstruct(const std::vector<std::string>& image_paths, const Project& project,
                                         const ReconstructOptions& options);

// The mean of the registered cameras' up (-y) directions in PROJECT/sparse (people hold cameras
// upright); -y of the world when there is no model.
Eigen::Vector3d UpFromCameras(const Project& project);

}  // namespace reconar
