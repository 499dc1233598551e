#pragma once
// Where a design stands in the project's world frame: first from control (design coordinates of
// tags the project holds), its units recognised from their scale, then refined by point-to-plane
// ICP against the as-built points where the two overlap.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/compare/design.h"
#include "core/math/sim3.h"

namespace reconar {

// One control point: the same point in design units and in the world (metres).
struct ControlPair {
  int tag = -1;
  Eigen::Vector3d design = Eigen::Vector3d::Zero();
  Eigen::Vector3d world = Eigen::Vector3d::Zero();
};

struct DesignRegistrationOptions {
  // A similarity (the scale fitted, not recognised as a unit): for a project that is not metric.
  bool similarity = false;
  bool refine = true;             // point-to-plane ICP after the control fit
  double max_distance = 0.1;      // metres: as-built points farther from the design take no part
  int max_points = 200000;        // as-built points used by the ICP (evenly thinned)
  int max_iterations = 40;
  int num_threads = 0;            // 0: one per core
};

struct DesignRegistration {
  Sim3 world_from_design;
  std::string units = "m";   // what the control's scale says the design is drawn in: m, cm, mm, in, ft
  double metres_per_unit = 1.0;
  double control_scale = 1.0;  // the scale the control points alone fit (metres per design unit)
  std::vector<double> control_residuals_m;  // per control pair, after the final registration
  double control_rms_m = 0.0;
  bool refined = false;
  // Why the ICP's placement was not taken (empty when it was, or did not run): it moved the control
  // points more than twice their RMS plus 5 mm.
  std::string icp_rejected;
  double icp_rms_m = 0.0;
  int points_used = 0;       // as-built points within the ICP's final bound of the design
  double overlap = 0.0;      // the share of the points the ICP looked at within max_distance of it
  int icp_iterations = 0;
  int free_directions = 0;   // motions the as-built surface could not fix (left at the control's)
  double icp_turn_deg = 0.0, icp_shift_m = 0.0;  // what the ICP changed (the shift at the points' centre)
};

// The control's units: the fitted scale within 3 % of a metre, centimetre, millimetre, inch or
// foot per unit (kInvalidArgument naming the scale otherwise, unless options.similarity). With no
// control pairs the design is taken as drawn in the world frame, in metres. Fewer than 3 pairs, or
// pairs on one line, are kInvalidArgument (4 corners of one tag are enough).
Result<DesignRegistration> RegisterDesign(const Design& design, const std::vector<ControlPair>& control,
                                          const std::vector<Eigen::Vector3d>& as_built,
                                          const DesignRegistrationOptions& options);

// The design's elements in the world frame: each element's positions moved, its name and triangles
// kept (no normals or colours).
std::vector<NamedMesh> PlacedElements(const Design& design, const Sim3& world_from_design);

// The design's elements joined into one mesh in the world frame, and the element of each triangle.
struct DesignSurface {
  Mesh mesh;
  std::vector<int> element_of_triangle;
  std::vector<Eigen::Vector3d> face_normals;  // unit, per triangle (zero for a degenerate one)
};
DesignSurface PlaceDesign(const Design& design, const Sim3& world_from_design);

}  // namespace reconar
