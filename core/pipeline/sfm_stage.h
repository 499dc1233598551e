#pragma once
// Mapping stage: reads a project's features and verified matches, runs the incremental mapper
// (core/sfm/mapper.h), colours the points from the photos and writes <project>/sparse/:
//   cameras.txt images.txt points3D.txt   COLMAP text model (RADIAL cameras)
//   bundle.out list.txt                   Bundler v0.3 (PMVS, MeshLab)
//   points.ply                            coloured sparse points
#include <string>

#include "core/base/status.h"
#include "core/pipeline/project.h"
#include "core/sfm/mapper.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

struct SfmStageOptions {
  MapperOptions mapper;
  bool show_progress = true;
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
};

// FailedPrecondition when the mapper finds no initial pair (its message says why); errors of
// the project files name the file.
Result<SfmStageReport> RunSfmStage(const Project& project, const SfmStageOptions& options,
                                   Reconstruction* reconstruction_out = nullptr);

}  // namespace reconar
