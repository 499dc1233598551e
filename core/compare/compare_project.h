#pragma once
// `reconar compare PROJECT DESIGN`: the design read, placed in the project's world frame by its
// control tags (PROJECT/tags.layout) and refined against the dense points, compared element by
// element, and written to PROJECT/compare/: report.json, deviation.ply (the as-built points
// coloured by their signed deviation), design_registered.glb (the design in the world frame).
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/compare/design_registration.h"
#include "core/compare/deviation.h"
#include "core/pipeline/project.h"

namespace reconar {

struct CompareOptions {
  std::string control_path;  // empty: the design is drawn in the world frame, in metres
  DesignRegistrationOptions registration;
  DeviationOptions deviation;
};

struct CompareReport {
  std::string design_path;
  std::string as_built_source;  // the file the as-built points came from
  int as_built_points = 0;
  bool metric = false;          // the project is in metres (tags.json)
  int control_tags = 0;
  int control_points = 0;       // picked points in the control
  // A project without metres (no tags) gets them from the design, taken as drawn in metres: its
  // world units per metre from the control's fitted scale (1 for a metric project).
  double world_units_per_metre = 1.0;
  bool units_assumed = false;
  DesignRegistration registration;  // world_from_design in the world frame; lengths in metres
  DeviationReport deviation;
  std::vector<std::string> warnings;  // e.g. a design that barely overlaps the model
  std::string out_dir;
  double seconds = 0.0;
};

// Errors name the file: a design or control file that does not read, a control tag the project
// did not reconstruct, a project without dense points, mesh or sparse model, a design that no
// as-built point lies near (FailedPrecondition, nothing written). Outputs are written atomically.
Result<CompareReport> CompareWithDesign(const Project& project, const std::string& design_path,
                                        const CompareOptions& options);

// compare/report.json: {"design", "as_built": {"source", "points"}, "metric", "tolerance_m",
// "registration": {"world_from_design": 4x4 row-major, "scale", "units", "units_assumed",
// "world_units_per_metre", "control_tags", "control_points",
// "control_rms_m", "control_residuals_m", "refined", "icp_rms_m", "points_used", "overlap",
// "icp_iterations", "icp_turn_deg", "icp_shift_m", "free_directions"}, "density_per_m2",
// "elements": [{"name", "points", "area_m2", "seen_area_m2", "mean_m", "rms_m", "p95_m",
// "within_tolerance", "shift_m": [3], "turn_deg", "largest_move_m", "verdict"}], "warnings": [...],
// "seconds"}.
std::string CompareReportJson(const CompareReport& report, const CompareOptions& options);

}  // namespace reconar
