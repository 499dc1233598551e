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
#include <cmath>
#include <cstddef>
#include <cstdint>
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
  // Added: the sparse points carry no visibility, so two views facing each other across an object
  // share points that at most one of them sees; a median angle above this marks such a pair.
  double max_triangulation_angle_deg = 60.0;
  // Added: a view's depth range is [p_low (1 - depth_margin), p_high (1 + depth_margin)] of the
  // depths of the sparse points in it (p_low, p_high: its depth_percentile and 1 - depth_percentile
  // quantiles, robust to a few stray points); views with fewer than min_range_points get no map.
  double depth_percentile = 0.02;
  double depth_margin = 0.25;
  int min_range_points = 8;
  // Photometric cost: 1 - NCC over a (2 window_radius + 1)^2 window sampled every window_step
  // pixels (those within window_radius + window_step / 2 of the centre), bilaterally weighted
  // (sigma_spatial in pixels, sigma_color in grey levels), warped by the pixel's plane into each
  // source view; a pixel's cost is the mean over its best `cost_top_k` source views (2, changed
  // from 3: a window outside a source costs 2, so with k above fusion_min_views a pixel that
  // enough sources see to be fused was dropped wherever a further source missed it; on the test's
  // box scene k = 3 lost 11 % of the completeness).
  int window_radius = 5;
  int window_step = 2;
  double sigma_spatial = 3.0;
  double sigma_color = 12.0;
  int cost_top_k = 2;
  // Added: per-pixel view selection (after ACMM's): a propagation sweep scores a pixel's candidate
  // planes on the source_subset sources that served its current plane best; a plane that wins is
  // then scored on the other sources too, which picks the subset for the next sweep (a finer level
  // starts from the coarse pixel's). 0 scores every candidate on all sources.
  int source_subset = 4;
  // Added: standard deviation of the image noise in grey levels (0..255), as PatchMvsOptions's. It
  // sets the texture floor MinTextureStd() = image_noise_std / sqrt(max_cost): under noise, a true
  // match of texture deviation s correlates at about s^2 / (s^2 + image_noise_std^2), which
  // reaches 1 - max_cost only when the observed deviation is at least that floor. A reference
  // window below it (bilaterally weighted) gets no depth: what would match there is noise (black
  // velvet behind a studio object, a white wall's grain).
  double image_noise_std = 2.0;
  // Added: planes for texture-poor pixels (below that floor: white walls, floors), after the planar
  // prior of ACMP (Xu & Tao, "Planar Prior Assisted PatchMatch Multi-View Stereo", AAAI 2020),
  // taken from reliable neighbours instead of a triangulation. After the sweeps of every level, a
  // texture-poor pixel looks along the 8 directions (up to fill_max_distance of the longer image
  // side) for the first pixel with texture whose cost is below max_cost; the planes of those
  // pixels, intersected with its ray, agree when their depths differ by at most
  // fill_max_relative_depth and their normals by at most fill_max_normal_deg. A plane that at least
  // fill_min_support of them agree on, two of them in opposite directions, fills the pixel (their
  // mean, at their mean cost): a plane fills the inside of its own outline and does not reach past
  // it. Fusion then keeps what the other views' maps confirm. 0 turns it off. (Keeping the coarser
  // level's plane at a texture-poor pixel instead, as multi-scale methods do, fattened templeRing's
  // faces into the black velvet beside them: 0.961 of its points in the box against 0.981.)
  int fill_min_support = 4;
  double fill_max_distance = 0.25;
  double fill_max_relative_depth = 0.02;
  double fill_max_normal_deg = 15.0;
  int iterations = 4;  // red-black sweeps (each sweep: both colours)
  // Added: propagation tests, in each of the four directions, the plane of the cheapest pixel
  // among those 1, 3, ..., 11 pixels away (4 planes); with separate_near_neighbours the adjacent
  // pixel's plane and the cheapest farther one (8 planes, as ACMH). On the test's box scene the
  // 4 planes took 28 % less time for the same completeness and 4 % fewer consistent pixels.
  bool separate_near_neighbours = false;
  // Added: coarse to fine (after Xu & Tao 2019): the `iterations` sweeps run on the views at
  // 1 / 2^coarse_levels resolution (fewer levels where a view would fall below 16 pixels), whose
  // planes then start fine_iterations sweeps at each finer level: most sweeps see a fraction of
  // the pixels, and texture-poor areas are matched at the coarser scale. On the test's box scene
  // at 640 x 480 (4 views, 2 threads) levels 1, 2, 3 took 4.60, 3.42, 3.19 s with 522k, 534k, 509k
  // consistent pixels and the same accuracy and completeness; at 320 x 240 one resolution took
  // 3.11 s (1 thread) against 1.65 s with one level and 1.28 s with two.
  int coarse_levels = 2;
  int fine_iterations = 1;
  // Added: geometric consistency (Schoenberger et al. 2016 sec. 4.2; Xu & Tao 2019): after the
  // photometric sweeps of all views, this many further sweeps per view add to every source view's
  // cost geometric_weight * min(forward-backward reprojection error in px, geometric_max_error_px)
  // against that source's depth map. 0 turns it off.
  int geometric_iterations = 0;
  double geometric_weight = 0.2;
  double geometric_max_error_px = 3.0;
  uint64_t seed = 1;  // Added: the random hypotheses are a function of (seed, view, pixel, sweep)
  // Fusion: a pixel becomes a point when at least fusion_min_views other views' depth maps agree
  // with it (reprojection within fusion_max_reprojection_px, relative depth within
  // fusion_max_relative_depth, normals within fusion_max_normal_deg) and its cost is below
  // max_cost.
  int fusion_min_views = 2;
  // Added: only pixels on a grid of this step start a point (2: at most one per 2 x 2 block, the
  // density of PMVS's cell_size 2), for a lighter point cloud; agreeing pixels anywhere still join.
  // Step 2 lost completeness: on the rendered bunny 0.792 against 0.836 with step 1 (the dense
  // stage's merge thins step 1's points to one per pixel footprint anyway, in 12 s for fountain-P11's
  // 3.0 million at level 1).
  int fusion_pixel_step = 1;
  double fusion_max_reprojection_px = 2.0;
  double fusion_max_relative_depth = 0.01;
  double fusion_max_normal_deg = 10.0;
  double max_cost = 0.5;
  // Added: a pixel's plane joins fusion only when it faces that pixel's camera within this angle
  // (PatchMvsOptions::max_view_angle, PMVS's iota): at grazing angles a window spans a long strip
  // of surface and its match is unreliable. On templeRing the planes past it were the platform
  // under the temple, seen at 63-75 degrees from every camera.
  double max_view_angle_deg = 60.0;
  int num_threads = 0;  // 0 = all cores
  bool show_progress = false;
  std::string progress_label = "PatchMatch depth maps";

  Status Check() const;  // InvalidArgument naming the first offending field
  double MinTextureStd() const { return image_noise_std / std::sqrt(max_cost); }  // grey levels
};

struct PatchMatchReport {
  size_t views = 0;              // reference views given a depth map
  size_t depth_pixels = 0;       // pixels with a depth after the photometric filter, all views
  size_t consistent_pixels = 0;  // of them, pixels with at least fusion_min_views agreeing sources
  size_t fused_points = 0;
  double seconds_selection = 0.0;    // source views and depth ranges
  double seconds_propagation = 0.0;  // initialisation, propagation and cost
  double seconds_consistency = 0.0;  // checks between depth maps
  double seconds_fusion = 0.0;
  size_t map_bytes = 0;  // held by the depth maps, grey copies and fusion flags of all views
};

// Memory per pixel of every view while RunPatchMatchMvs runs: depth and cost floats, the normal
// (three 16-bit values, core/mvs/patchmatch/depth_map.h), the float grey copy, and the fusion's
// two byte flags (agreeing count, used); the per-thread scratch, the sparse points' visibility
// table and the half-resolution copies of coarse to fine (1.67 bytes per pixel and one coarse
// map, before the fusion flags exist) are small beside it.
inline constexpr size_t kPatchMatchBytesPerPixel = 2 * sizeof(float) + 3 * sizeof(int16_t) + sizeof(float) + 2;

// Depth maps for every view of `views` (at least 2), sources among the others, then fused points.
// `sparse_points` (world) give each view its depth range and its source views: a view whose
// range cannot be found from them gets no depth map. InvalidArgument on bad options or null or
// empty views; FailedPrecondition when no point is fused.
Result<OrientedPoints> RunPatchMatchMvs(const std::vector<const DenseView*>& views,
                                        const std::vector<Eigen::Vector3d>& sparse_points,
                                        const PatchMatchOptions& options, PatchMatchReport* report = nullptr);

}  // namespace reconar
