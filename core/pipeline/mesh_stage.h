#pragma once
// Mesh stage: PROJECT/dense/points.ply -> screened Poisson (core/mesh/poisson) -> PROJECT/mesh/
// mesh.{ply,obj,glb,wrl} and mesh/report.json, every file atomically, report.json last. A textured
// model of the previous mesh (texture_stage.h) is removed once the new mesh is written.
//
// Depth: at most the requested one, and no finer than the points: the depth whose cells are as
// small as the median distance between neighbouring points (finer cells only add unknowns that
// no sample constrains).
// Memory: Poisson's grids grow about fourfold per depth on a surface. When a budget is given, a
// pilot solve at depth - 2 measures its own peak (VmHWM, reset before it) and the depth used is the
// finest, at most the requested one, whose extrapolated peak (pilot x 4^(depth - pilot depth),
// plus what the process already holds) fits the budget; the report says when it was lowered.
// Size: a mesh of more than max_faces triangles is simplified (core/mesh/simplify.h) before it is
// written, so that a handheld renders it at video rate.
// `reconar mesh` runs the same work (MeshPointsFile) on any oriented points file.
#include <cstddef>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/poisson/point_outliers.h"
#include "core/mesh/poisson/poisson.h"
#include "core/mesh/simplify.h"
#include "core/pipeline/project.h"

namespace reconar {

struct MeshStageOptions {
  PoissonOptions poisson;                                           // depth is the finest allowed
  size_t memory_budget_bytes = 0;                                   // 0: no limit, no pilot
  std::vector<std::string> formats = {"ply", "obj", "glb", "wrl"};  // mesh/mesh.<format>
  size_t max_faces = 0;                                             // 0: no limit
  // The depth no finer than the points' spacing, the trim at most depth - 1; false: as given.
  bool depth_from_spacing = true;
  bool remove_outliers = false;   // drop isolated points and small floating pieces first
  OutlierFilterOptions outliers;  // its num_threads 0 takes poisson.num_threads
  bool estimate_normals = false;  // from the nearest neighbours, replacing the points' own

  Status Check() const;
};

struct MeshStageReport {
  int requested_depth = 0;
  double median_spacing = 0.0;  // of the points (mean distance to 8 nearest, median over a sample)
  int spacing_depth = 0;        // the depth whose cell matches that spacing
  int depth = 0;                // used
  bool depth_lowered_for_budget = false;
  size_t pilot_peak_bytes = 0;      // above the baseline, at the pilot depth
  size_t estimated_peak_bytes = 0;  // for the depth used
  size_t points = 0;                // read
  OutlierFilterReport outliers;     // with remove_outliers
  bool normals_estimated = false;
  PoissonReport poisson;
  bool simplified = false;  // over max_faces: `simplify` says from what to what
  SimplifyReport simplify;
  size_t vertices = 0, faces = 0;  // written
  double seconds = 0.0;
  size_t peak_rss_bytes = 0;
  std::vector<std::string> paths;  // written meshes
  std::string report_path;
};

// The settings the mesh stage's record holds (core/pipeline/stage_record.h).
std::string MeshStageSettings(const MeshStageOptions& options);

// FailedPrecondition without dense points; ResourceExhausted when even depth 5 does not fit.
Result<MeshStageReport> RunMeshStage(const Project& project, const MeshStageOptions& options);

// The stage's work on any file of oriented points (.ply, .obj, .glb), written to each of
// mesh_paths (format by extension; options.formats is not used). InvalidArgument naming the file
// when the points have no normals and estimate_normals is off. Writes no report.
Result<MeshStageReport> MeshPointsFile(const std::string& points_path, const std::vector<std::string>& mesh_paths,
                                       const MeshStageOptions& options,
                                       const MeshFileOptions& file_options = MeshFileOptions());

std::string MeshReportJson(const MeshStageReport& report);

}  // namespace reconar
