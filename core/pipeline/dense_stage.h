#pragma once
// Dense stage: reads a project's sparse model (<project>/sparse, COLMAP text) and image list
// (features/images.txt), groups the registered images into view clusters (core/mvs/view_clustering.h),
// undistorts the views of each cluster (core/mvs/undistort.h) and runs the chosen multi-view stereo
// on it (DenseMethod: PMVS, core/mvs/pmvs/patch_mvs.h, or PatchMatch depth maps,
// core/mvs/patchmatch/patchmatch_mvs.h), merges the clusters' points (core/mvs/merge_points.h), drops isolated
// points and small floating pieces (core/mesh/poisson/point_outliers.h) and writes
//   <project>/dense/points.ply     binary PLY: x y z, nx ny nz (float), red green blue alpha (uchar)
//   <project>/dense/report.json    DenseReportJson below
// atomically. Views stay in memory only while a cluster that holds them runs, so memory follows the
// cluster size and the level (core/mvs/dense_memory.h), not the number of images.
#include <cstddef>
#include <string>

#include "core/base/status.h"
#include "core/mesh/poisson/point_outliers.h"
#include "core/mvs/patchmatch/patchmatch_mvs.h"
#include "core/mvs/pmvs/patch_mvs.h"
#include "core/mvs/view_clustering.h"
#include "core/pipeline/project.h"

namespace reconar {

enum class DenseMethod {
  kPmvs,        // patches grown from matched features (Furukawa & Ponce 2010): the paper's method
  kPatchMatch,  // a depth map per view by PatchMatch, fused across views
};

// "pmvs", "patchmatch"; ParseDenseMethod returns InvalidArgument naming the choices.
const char* DenseMethodName(DenseMethod method);
Result<DenseMethod> ParseDenseMethod(const std::string& name);

struct DenseStageOptions {
  // PatchMatch by default (issue 16: on the README's room 0.21 of PMVS's dense time with 3.3 times
  // the points; on the rendered bunny 0.48 mm against PMVS's 1.09 mm; docs/dense.md).
  DenseMethod method = DenseMethod::kPatchMatch;
  int level = -1;  // -1: the finest level 0..2 within max_image_size whose memory estimate fits the budget
  // The automatic level's cap on the longest image side, in pixels (0: none). 2400 is COLMAP's
  // default ("high" quality of its automatic reconstructor; OpenMVS halves every image by
  // default): a 3072 x 2048 photo is matched at level 1. On fountain-P11 level 0 took 4.2 times
  // level 1's dense time (docs/dense.md).
  int max_image_size = 2400;
  size_t memory_budget_bytes = kDefaultMemoryBudgetBytes;
  ViewClusteringOptions clustering;
  PatchMvsOptions mvs;  // its num_threads 0 takes the stage's
  PatchMatchOptions patchmatch;  // likewise
  bool remove_outliers = true;
  OutlierFilterOptions outliers;  // its num_threads 0 takes the stage's
  int num_threads = 0;  // 0: one per core
  bool show_progress = true;

  Status Check() const;
};

struct DensePhase {
  double seconds = 0.0;
  size_t peak_rss_bytes = 0;  // VmHWM over the phase (since process start when resets are refused)
};

struct DenseStageReport {
  DenseMethod method = DenseMethod::kPatchMatch;
  int level = 0;
  bool level_auto = false;
  int finest_level_within_size = 0;  // auto: the finest level within max_image_size (the level is not finer)
  size_t estimated_bytes = 0;     // the memory model's figure for one cluster at that level
  int max_cluster_size = 0;       // as used (below the requested one when the budget demanded it)
  bool cluster_size_reduced = false;
  int images = 0;                 // registered images in the model
  int kept_images = 0, removed_images = 0;
  int clusters = 0;
  int clusters_without_points = 0;  // too small for the method, or no point survived
  bool clusters_from_cameras = false;
  double sparse_points_covered = 0.0;  // fraction, see ViewClustering::covered_fraction
  size_t views_undistorted = 0;   // photos decoded and undistorted: each once while the budget keeps them
  size_t views_in_clusters = 0;   // the clusters' sizes summed (a photo in two clusters counts twice)
  size_t points_before_merge = 0;
  OutlierFilterReport outliers;   // all zero when the filter is off
  size_t points = 0;
  DensePhase load, clustering, undistort, mvs, merge, outlier_filter, write;
  bool peak_rss_resettable = false;
  PatchMvsReport pmvs;          // summed over clusters (PMVS)
  PatchMatchReport patchmatch;  // summed over clusters (PatchMatch; map_bytes: the largest cluster's)
  std::string points_path, report_path;
};

// The settings the dense stage's record holds (core/pipeline/stage_record.h).
std::string DenseStageSettings(const DenseStageOptions& options);

// Errors name the file: a missing or corrupt sparse model or image list, an image missing from the
// list or unreadable, a photo whose size differs from its camera. FailedPrecondition when no
// cluster yields a point; ResourceExhausted when even the smallest useful cluster at the coarsest
// allowed level exceeds the budget.
Result<DenseStageReport> RunDenseStage(const Project& project, const DenseStageOptions& options);

// The report as JSON (what dense/report.json holds).
std::string DenseReportJson(const DenseStageReport& report);

}  // namespace reconar
