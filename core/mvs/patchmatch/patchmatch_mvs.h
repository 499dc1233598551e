#pragma once
// Depth-map multi-view stereo by PatchMatch (Bleyer, Rhemann & Rother, "PatchMatch Stereo", BMVC
// 2011; Schoenberger et al., "Pixelwise View Selection for Unstructured Multi-View Stereo", ECCV
// 2016; Xu & Tao, "Multi-Scale Geometric Consistency Guided Multi-View Stereo", CVPR 2019):
// every pixel of a reference view carries a depth and a normal (a plane); planes are propagated
// between neighbours in red-black checkerboard order and perturbed at random, each scored by a
// bilaterally weighted NCC over the best of the selected source views. Depth maps of the views
// are then checked against each other and the consistent pixels fused into oriented points.
//
// Conventions: DenseView (core/mvs/dense_view.h): undistorted pinhole, pixel centres at integers,
// cam_from_world poses; depths along the camera's z axis. Output in world coordinates, normals
// towards the cameras.
#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/mvs/dense_view.h"
#include "core/mvs/oriented_points.h"

namespace reconar {

struct PatchMatchOptions {
  // Source views per reference view: the sparse points both see, triangulation angle at least
  // min_triangulation_angle_deg; at most max_source_views.
  int max_source_views = 8;
  double min_triangulation_angle_deg = 3.0;
  // Photometric cost: 1 - NCC over a (2 window_radius + 1)^2 window sampled every window_step
  // pixels, bilaterally weighted (sigma_spatial in pixels, sigma_color in grey levels), warped by
  // the pixel's plane into each source view; a pixel's cost is the mean over its best
  // `cost_top_k` source views.
  int window_radius = 5;
  int window_step = 2;
  double sigma_spatial = 3.0;
  double sigma_color = 12.0;
  int cost_top_k = 3;
  int iterations = 4;  // red-black sweeps (each sweep: both colours)
  // Fusion: a pixel becomes a point when at least fusion_min_views other views' depth maps agree
  // with it (reprojection within fusion_max_reprojection_px, relative depth within
  // fusion_max_relative_depth, normals within fusion_max_normal_deg) and its cost is below
  // max_cost.
  int fusion_min_views = 2;
  double fusion_max_reprojection_px = 2.0;
  double fusion_max_relative_depth = 0.01;
  double fusion_max_normal_deg = 10.0;
  double max_cost = 0.5;
  int num_threads = 0;  // 0 = all cores
  bool show_progress = false;
  std::string progress_label = "PatchMatch depth maps";

  Status Check() const;  // InvalidArgument naming the first offending field
};

struct PatchMatchReport {
  size_t views = 0;            // reference views given a depth map
  size_t depth_pixels = 0;     // pixels with a depth after the photometric filter, all views
  size_t fused_points = 0;
  double seconds_selection = 0.0;    // source views and depth ranges
  double seconds_propagation = 0.0;  // initialisation, propagation and cost
  double seconds_consistency = 0.0;  // checks between depth maps
  double seconds_fusion = 0.0;
};

// Depth maps for every view of `views` (at least 2), sources among the others, then fused points.
// `sparse_points` (world) give each view its depth range and its source views: a view whose
// range cannot be found from them gets no depth map. InvalidArgument on bad options or null or
// empty views; FailedPrecondition when no point is fused.
Result<OrientedPoints> RunPatchMatchMvs(const std::vector<const DenseView*>& views,
                                        const std::vector<Eigen::Vector3d>& sparse_points,
                                        const PatchMatchOptions& options, PatchMatchReport* report = nullptr);

}  // namespace reconar
