#pragma once
// As built against as planned, element by element: each as-built point's signed distance to the
// nearest design surface along its face normal (positive: in front of the surface, outside), the
// element it falls on, and per element the statistics, its own rigid fit to its points (how far it
// was moved or turned) and a verdict.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/compare/design.h"
#include "core/math/sim3.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

struct DeviationOptions {
  double tolerance = 0.01;     // metres: within it an element is as designed
  double max_distance = 0.1;   // metres: an as-built point farther from every design surface is on none
  // A point whose normal is given belongs only to a face turned the same way (within 60 degrees):
  // the ground under a missing box is not its bottom.
  double max_normal_angle_deg = 60.0;
  // An element seen by the photos whose seen faces hold fewer than this share of the points their
  // area should (at the median density of the elements) is missing, or unknown when the photos did
  // not see past it.
  double missing_fraction = 0.1;
  int min_points = 30;         // fewer: no fit of its own, no deviates verdict from statistics alone
  int max_fit_points = 10000;  // an element's own fit uses at most this many of its points (evenly thinned)
  int num_threads = 0;         // 0: one per core
};

struct ElementDeviation {
  std::string name;
  int points = 0;
  // All faces; the part two registered photos face with nothing of the as-built in front of it.
  double area_m2 = 0.0, seen_area_m2 = 0.0;
  double mean_m = 0.0, rms_m = 0.0;          // of the signed distances
  double p95_m = 0.0;                        // of their magnitudes
  double within_tolerance = 0.0;             // share of its points
  // Its own rigid fit to its points, the design element moved onto them: the shift of its points'
  // centre, the turn, and the largest displacement of any of its points.
  Eigen::Vector3d shift_m = Eigen::Vector3d::Zero();
  double turn_deg = 0.0, largest_move_m = 0.0;
  // as_designed; deviates; missing (too few points for its seen area, and the photos saw past
  // it: the as-built behind where it should stand); unknown (too few points, but nothing seen past
  // it either: a surface the reconstruction could not hold, e.g. texture-poor); not_seen.
  std::string verdict;
};

struct DeviationReport {
  std::vector<ElementDeviation> elements;  // in the design's order
  std::vector<int> element_of_point;       // per as-built point; -1 on none
  std::vector<double> signed_distance_m;   // per as-built point; 0 on none
  double density_per_m2 = 0.0;             // the elements' median points per seen square metre
  bool views_used = false;                 // `views` given: seen areas and missing verdicts
};

// `as_built_normals` empty or one per point; `views` (may be null) the registered photos in the
// world frame, for what was looked at.
Result<DeviationReport> ComputeDeviation(const Design& design, const Sim3& world_from_design,
                                         const std::vector<Eigen::Vector3d>& as_built,
                                         const std::vector<Eigen::Vector3d>& as_built_normals,
                                         const Reconstruction* views, const DeviationOptions& options);

}  // namespace reconar
