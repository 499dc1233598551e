#pragma once
// Rigid alignment of points to a triangle surface by point-to-plane ICP (Chen & Medioni 1992),
// linearised per step (Low 2004): each point pulled along its nearest surface point's face normal.
// Directions the correspondences do not constrain (a single plane leaves two shifts and a turn
// free) are left where they were instead of drifting.
#include <vector>

#include <Eigen/Core>

#include "core/base/thread_pool.h"
#include "core/math/rigid3.h"
#include "core/mesh/triangle_bvh.h"

namespace reconar {

struct PointToPlaneOptions {
  int max_iterations = 30;
  // Correspondences farther than this from the surface are left out; after the first step the
  // bound follows the residuals (3 x their robust spread), never below min_distance.
  double max_distance = 0.1;
  double min_distance = 0.002;
  double stop_motion = 1e-6;  // metres (and radians times the points' extent): converged
};

struct PointToPlaneReport {
  Rigid3 surface_from_points;  // the fitted motion: points are taken by it onto the surface
  int iterations = 0;
  int inliers = 0;             // correspondences within the final bound
  double rms = 0.0;            // of their point-to-plane residuals
  double final_distance = 0.0; // the final bound
  int free_directions = 0;     // of the 6, those the correspondences left unconstrained
};

// `face_normals[t]`: unit normal of triangle t of the surface the BVH was built on. The nearest
// points are found on `pool` when given; the result does not depend on its size.
PointToPlaneReport AlignPointsToSurface(const std::vector<Eigen::Vector3d>& points, const TriangleBvh& surface,
                                        const std::vector<Eigen::Vector3d>& face_normals,
                                        const PointToPlaneOptions& options, const Rigid3& start = Rigid3(),
                                        ThreadPool* pool = nullptr);

}  // namespace reconar
