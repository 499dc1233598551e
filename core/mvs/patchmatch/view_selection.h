#pragma once
// Per-view setup of PatchMatch MVS from the sparse model: the depth range a reference view's
// hypotheses are drawn from and the source views its photometric cost compares against
// (Schoenberger et al. 2016 sec. 4.1 select by shared points and triangulation angle).
#include <Eigen/Core>
#include <vector>

#include "core/mvs/dense_view.h"
#include "core/mvs/patchmatch/patchmatch_mvs.h"

namespace reconar {

class ThreadPool;

struct PatchMatchViewSetup {
  bool valid = false;      // a depth range and at least one source view were found
  double depth_min = 0.0;  // along the camera's z axis
  double depth_max = 0.0;
  std::vector<int> sources;  // indices into the views, most shared points first
};

// One setup per view. A sparse point belongs to a view when it projects inside the image with
// positive depth. The range comes from the depth quantiles of the view's points; a source view
// shares points with it whose median triangulation angle lies in [min, max]_triangulation_angle_deg.
// A view with too few points (a model imported with known cameras and no points) falls back on the
// cameras' geometry: the range around the point the views' optical axes meet nearest, the sources
// by their angle seen from there.
std::vector<PatchMatchViewSetup> SetUpPatchMatchViews(const std::vector<const DenseView*>& views,
                                                      const std::vector<Eigen::Vector3d>& sparse_points,
                                                      const PatchMatchOptions& options, ThreadPool* pool);

}  // namespace reconar
