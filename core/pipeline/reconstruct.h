#pragma once
// The whole job (paper Fig. 2), `reconar reconstruct IMAGES_DIR PROJECT_DIR`: features -> matching
// -> tags (AprilTags in the photos, when a tag size is given) -> mapping (incremental SfM with the
// tag corners in bundle adjustment, then metric registration to the world tag) -> dense (CMVS +
// PMVS) -> mesh (screened Poisson, exports). Every stage writes its outputs atomically and is then
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
#include <functional>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/pipeline/dense_stage.h"
#include "core/pipeline/feature_stage.h"
#include "core/pipeline/match_stage.h"
#include "core/pipeline/mesh_stage.h"
#include "core/pipeline/project.h"
#include "core/pipeline/sfm_stage.h"
#include "core/sfm/tag_observations.h"

namespace reconar {

// The default budget suits a 4 GB board: room for the OS, a display and the AR viewer.
inline constexpr size_t kDefaultMemoryBudgetBytes = 2560ull << 20;

// Finds AprilTags in the photos (tracker/photo_tags.h; injected so that core stays free of
// libapriltag). Its result is stored as PROJECT/tags/detections.txt.
using TagDetectorFunction = std::function<Result<TagDetectionsFile>(const std::vector<std::string>& paths)>;

struct ReconstructOptions {
  bool run_sparse = true, run_dense = true, run_mesh = true;  // --stages; a stage needs the ones before
  FeatureStageOptions features;
  MatchStageOptions matching;
  SfmStageOptions sfm;  // sfm.tags.enabled follows tag_size_m > 0
  DenseStageOptions dense;
  MeshStageOptions mesh;
  double tag_size_m = 0.0;  // 0: no tags, the model keeps an arbitrary scale
  std::string tag_family = "tag36h11";
  TagDetectorFunction detect_tags;  // required when tag_size_m > 0
  size_t memory_budget_bytes = kDefaultMemoryBudgetBytes;
  int num_threads = 0;  // 0: one per core
  bool force = false;   // redo every stage
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

struct ReconstructReport {
  std::vector<StageSummary> stages;
  std::string report_path;
  bool metric = false;     // tags.json says the model is in metres
  std::string scale_note;  // why not, when not
};

// image_paths as CollectImagePaths gives them. Errors name the stage and the file.
Result<ReconstructReport> RunReconstruct(const std::vector<std::string>& image_paths, const Project& project,
                                         const ReconstructOptions& options);

}  // namespace reconar
