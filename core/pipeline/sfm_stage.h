#pragma once
// Mapping stage: reads a project's features and verified matches, runs the incremental mapper
// (core/sfm/mapper.h), colours the points from the photos and writes <project>/sparse/:
//   cameras.txt images.txt points3D.txt   COLMAP text model (RADIAL cameras)
//   bundle.out list.txt                   Bundler v0.3 (PMVS, MeshLab)
//   points.ply                            coloured sparse points
// With tags enabled the model is in metres in the world tag's frame, and PROJECT/tags.json says
// where each tag is (TagRegistrationJson); without a complete tag it stays in arbitrary scale.
#include <string>

#include "core/base/json_writer.h"
#include "core/base/status.h"
#include "core/features/sift/sift.h"
#include "core/pipeline/project.h"
#include "core/sfm/mapper.h"
#include "core/sfm/reconstruction.h"
#include "core/sfm/tag_registration.h"

namespace reconar {

// Metric registration by AprilTags (core/sfm/tag_registration.h) from PROJECT/tags/detections.txt.
struct SfmTagOptions {
  bool enabled = false;
  // The corners join the mapper's tracks and bundle adjustment; false: they are only triangulated
  // from the final cameras (to measure what the constraints bring).
  bool in_adjustment = true;
  TagRegistrationOptions registration;
};

struct SfmStageOptions {
  MapperOptions mapper;
  SfmTagOptions tags;
  bool show_progress = true;
  // When PROJECT/live/ holds the model a capture grew (live_reconstruction.h), the mapper continues
  // from it (ContinueIncrementalMapper: its poses and cameras, every track triangulated again, the
  // other photos registered, the tags added, the final adjustment) instead of starting over. Its
  // photos the project no longer holds are left out. It is passed over, with the reason in the
  // report, when it cannot be read, holds fewer than two of the photos, or has one of another size;
  // and when the continued model holds under half the photos, the mapper also runs from scratch and
  // the larger model is kept.
  bool continue_from_live = true;
};

struct SfmStageReport {
  MapperReport mapper;
  // Paper Table 1: focal ratio = focal / max(width, height) over the registered images, its
  // mean and root-mean-square deviation, and the 35 mm-equivalent focal of the mean ratio.
  double mean_focal_ratio = 0.0;
  double rmse_focal_ratio = 0.0;
  double focal_35mm_equivalent = 0.0;
  double seconds_load = 0.0;
  double seconds_mapping = 0.0;
  double seconds_colour = 0.0;
  double seconds_write = 0.0;
  // The capture's live model (PROJECT/live/): none there, continued by the mapper, or there but not
  // used (live_model_reason says why: unreadable, too few of the photos, the mapper from scratch
  // registered more).
  enum class LiveModel { kNone, kContinued, kNotUsed };
  LiveModel live_model = LiveModel::kNone;
  std::string live_model_reason;
  bool tags_used = false;             // options.tags.enabled
  TagRegistrationReport tags;         // also written to PROJECT/tags.json
};

// The report's members as JSON keys of the object `json` has open: images, registered, points,
// focal statistics (paper Table 1), initial pair, refinement choices, unregistered images with
// reasons, and with tags their registration summary.
void WriteSfmReportFields(const SfmStageReport& report, JsonWriter* json);

// The mapper's view of a project image with its keypoints, and of a verified pair.
MapperImage ToMapperImage(const ProjectImage& image, const std::vector<SiftKeypoint>& keypoints);
MapperPair ToMapperPair(int image_a, int image_b, const std::vector<FeatureMatch>& matches, bool planar);

// The settings the mapping stage's record holds (core/pipeline/stage_record.h): a change to any of
// them maps again.
std::string SfmStageSettings(const SfmStageOptions& options);

// FailedPrecondition when the mapper finds no initial pair (its message says why); errors of
// the project files name the file.
Result<SfmStageReport> RunSfmStage(const Project& project, const SfmStageOptions& options,
                                   Reconstruction* reconstruction_out = nullptr);

}  // namespace reconar
