#include "core/mvs/patchmatch/patchmatch_mvs.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "core/base/elapsed.h"
#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/io/gray.h"
#include "core/mvs/patchmatch/depth_fusion.h"
#include "core/mvs/patchmatch/depth_map.h"
#include "core/mvs/patchmatch/patchmatch_view.h"
#include "core/mvs/patchmatch/view_selection.h"
#include "core/mvs/undistort.h"

namespace reconar {
namespace {

constexpr int kMaxWindowRadius = 16;
constexpr int kMaxSourceViews = 32;
constexpr int kMinCoarseSide = 16;  // the smallest side of a coarse level
constexpr int kMaxCoarseLevels = 4;

Status CheckViews(const std::vector<const DenseView*>& views) {
  if (views.size() < 2) {
    return InvalidArgument("PatchMatch MVS: " + std::to_string(views.size()) + " views, need at least 2");
  }
  for (size_t i = 0; i < views.size(); ++i) {
    const DenseView* v = views[i];
    const std::string name = "PatchMatch MVS: view " + std::to_string(i) + (v ? " (" + v->name + ")" : "");
    if (v == nullptr) return InvalidArgument(name + ": null");
    if (v->gray.empty() || v->gray.channels() != 1) return InvalidArgument(name + ": no single-channel grey image");
    if (v->rgb.width() != v->gray.width() || v->rgb.height() != v->gray.height() || v->rgb.channels() != 3) {
      return InvalidArgument(name + ": the rgb image does not match the grey one");
    }
    if (!(v->fx > 0.0 && v->fy > 0.0) || !std::isfinite(v->fx) || !std::isfinite(v->fy) || !std::isfinite(v->cx) ||
        !std::isfinite(v->cy) || !v->cam_from_world.rotation.allFinite() ||
        !v->cam_from_world.translation.allFinite()) {
      return InvalidArgument(name + ": invalid intrinsics or pose");
    }
  }
  return Status::Ok();
}

// The view at half resolution (core/mvs/undistort.h's level convention: 2 x 2 area average,
// f / 2, c -> (c + 0.5) / 2 - 0.5), grey only.
DenseView HalfResolution(const DenseView& full) {
  DenseView half;
  half.name = full.name;
  half.image_id = full.image_id;
  half.level = full.level + 1;
  half.gray = AreaAverageDown(full.gray, 1);
  half.fx = 0.5 * full.fx;
  half.fy = 0.5 * full.fy;
  half.cx = 0.5 * (full.cx + 0.5) - 0.5;
  half.cy = 0.5 * (full.cy + 0.5) - 0.5;
  half.cam_from_world = full.cam_from_world;
  return half;
}

}  // namespace

Status PatchMatchOptions::Check() const {
  const std::string prefix = "PatchMatch MVS options: ";
  if (max_source_views < 1 || max_source_views > kMaxSourceViews) {
    return InvalidArgument(prefix + "max_source_views must lie in [1, " + std::to_string(kMaxSourceViews) + "]");
  }
  if (!(min_triangulation_angle_deg >= 0.0 && min_triangulation_angle_deg < max_triangulation_angle_deg &&
        max_triangulation_angle_deg <= 180.0)) {
    return InvalidArgument(prefix + "need 0 <= min_triangulation_angle_deg < max_triangulation_angle_deg <= 180");
  }
  if (!(depth_percentile >= 0.0 && depth_percentile < 0.5)) {
    return InvalidArgument(prefix + "depth_percentile must lie in [0, 0.5)");
  }
  if (!(depth_margin >= 0.0 && depth_margin < 1.0)) return InvalidArgument(prefix + "depth_margin must lie in [0, 1)");
  if (min_range_points < 1) return InvalidArgument(prefix + "min_range_points must be positive");
  if (window_radius < 1 || window_radius > kMaxWindowRadius) {
    return InvalidArgument(prefix + "window_radius must lie in [1, " + std::to_string(kMaxWindowRadius) + "]");
  }
  if (window_step < 1 || window_step > window_radius) {
    return InvalidArgument(prefix + "window_step must lie in [1, window_radius]");
  }
  if (!(sigma_spatial > 0.0) || !(sigma_color > 0.0)) {
    return InvalidArgument(prefix + "sigma_spatial and sigma_color must be positive");
  }
  if (cost_top_k < 1 || cost_top_k > max_source_views) {
    return InvalidArgument(prefix + "cost_top_k must lie in [1, max_source_views]");
  }
  if (iterations < 1) return InvalidArgument(prefix + "iterations must be positive");
  if (coarse_levels < 0 || coarse_levels > kMaxCoarseLevels) {
    return InvalidArgument(prefix + "coarse_levels must lie in [0, " + std::to_string(kMaxCoarseLevels) + "]");
  }
  if (fine_iterations < 0) return InvalidArgument(prefix + "fine_iterations must be >= 0");
  if (fill_min_support < 0 || fill_min_support > 8) {
    return InvalidArgument(prefix + "fill_min_support must lie in [0, 8] (of the 8 directions)");
  }
  if (!(fill_max_distance > 0.0 && fill_max_distance <= 1.0) || !(fill_max_relative_depth > 0.0) ||
      !(fill_max_normal_deg > 0.0 && fill_max_normal_deg < 90.0)) {
    return InvalidArgument(prefix +
                           "need fill_max_distance in (0, 1], fill_max_relative_depth > 0 and fill_max_normal_deg "
                           "in (0, 90)");
  }
  if (geometric_iterations < 0) return InvalidArgument(prefix + "geometric_iterations must be >= 0");
  if (!(geometric_weight >= 0.0) || !(geometric_max_error_px > 0.0)) {
    return InvalidArgument(prefix + "geometric_weight must be >= 0 and geometric_max_error_px positive");
  }
  if (fusion_min_views < 1 || fusion_min_views > max_source_views) {
    return InvalidArgument(prefix + "fusion_min_views must lie in [1, max_source_views]");
  }
  if (fusion_pixel_step < 1 || fusion_pixel_step > 16) {
    return InvalidArgument(prefix + "fusion_pixel_step must lie in [1, 16]");
  }
  if (!(fusion_max_reprojection_px > 0.0) || !(fusion_max_relative_depth > 0.0) ||
      !(fusion_max_normal_deg > 0.0 && fusion_max_normal_deg <= 180.0)) {
    return InvalidArgument(prefix + "fusion tolerances must be positive (normal angle at most 180 degrees)");
  }
  if (!(max_cost > 0.0 && max_cost <= 2.0)) return InvalidArgument(prefix + "max_cost must lie in (0, 2]");
  if (source_subset < 0) return InvalidArgument(prefix + "source_subset must be >= 0");
  if (!(max_view_angle_deg > 0.0 && max_view_angle_deg <= 90.0)) {
    return InvalidArgument(prefix + "max_view_angle_deg must lie in (0, 90]");
  }
  if (!(image_noise_std >= 0.0 && image_noise_std < 64.0)) {
    return InvalidArgument(prefix + "image_noise_std must lie in [0, 64) grey levels");
  }
  return Status::Ok();
}

Result<OrientedPoints> RunPatchMatchMvs(const std::vector<const DenseView*>& views,
                                        const std::vector<Eigen::Vector3d>& sparse_points,
                                        const PatchMatchOptions& options, PatchMatchReport* report) {
  if (Status s = options.Check(); !s.ok()) return s;
  if (Status s = CheckViews(views); !s.ok()) return s;
  PatchMatchReport local_report;
  PatchMatchReport& r = report ? *report : local_report;
  r = PatchMatchReport();
  ThreadPool pool(options.num_threads);
  const size_t num_views = views.size();

  auto start = std::chrono::steady_clock::now();
  const std::vector<PatchMatchViewSetup> setups = SetUpPatchMatchViews(views, sparse_points, options, &pool);
  std::vector<Image<float>> greys(num_views);
  pool.ParallelFor(0, num_views, [&](size_t v, int) {
    greys[v] = Image<float>(views[v]->width(), views[v]->height(), 1);
    Gray8ToFloat(views[v]->gray.view(), greys[v].view());
  });
  r.seconds_selection = SecondsSince(start);

  // Inputs per view; the geometric pass reads the sources' maps in place.
  std::vector<DepthMap> maps(num_views);
  std::vector<PatchMatchViewInput> inputs(num_views);
  std::vector<std::vector<int>> sources(num_views);
  size_t views_with_maps = 0;
  for (size_t v = 0; v < num_views; ++v) {
    if (!setups[v].valid) continue;
    ++views_with_maps;
    sources[v] = setups[v].sources;
    PatchMatchViewInput& in = inputs[v];
    in.reference = views[v];
    in.reference_grey = &greys[v];
    for (int s : setups[v].sources) {
      in.sources.push_back(views[static_cast<size_t>(s)]);
      in.source_greys.push_back(&greys[static_cast<size_t>(s)]);
      in.source_depths.push_back(&maps[static_cast<size_t>(s)]);
    }
    in.depth_min = setups[v].depth_min;
    in.depth_max = setups[v].depth_max;
    in.seed = options.seed * 0x9E3779B97F4A7C15ull + v;
  }
  if (views_with_maps == 0) {
    return FailedPrecondition("PatchMatch MVS: no view has a depth range and a source view from the " +
                              std::to_string(sparse_points.size()) + " sparse points");
  }

  start = std::chrono::steady_clock::now();
  const int passes = options.geometric_iterations > 0 ? 2 : 1;
  std::unique_ptr<Progress> progress;
  if (options.show_progress) progress = std::make_unique<Progress>(options.progress_label, views_with_maps * passes);
  // Coarse to fine: levels 1..levels of the views (each half the one before), as many as keep
  // every view at least kMinCoarseSide pixels on each side.
  int levels = options.coarse_levels;
  for (const DenseView* v : views) {
    while (levels > 0 && std::min(v->width(), v->height()) >> levels < kMinCoarseSide) --levels;
  }
  std::vector<std::vector<DenseView>> pyramid(static_cast<size_t>(levels) + 1);
  std::vector<std::vector<Image<float>>> pyramid_greys(static_cast<size_t>(levels) + 1);
  for (size_t l = 1; l <= static_cast<size_t>(levels); ++l) {
    pyramid[l].resize(num_views);
    pyramid_greys[l].resize(num_views);
    pool.ParallelFor(0, num_views, [&](size_t v, int) {
      pyramid[l][v] = HalfResolution(l == 1 ? *views[v] : pyramid[l - 1][v]);
      pyramid_greys[l][v] = Image<float>(pyramid[l][v].width(), pyramid[l][v].height(), 1);
      Gray8ToFloat(pyramid[l][v].gray.view(), pyramid_greys[l][v].view());
    });
  }
  for (size_t v = 0; v < num_views; ++v) {
    if (!setups[v].valid) continue;
    DepthMap coarse_map, finer_map;  // one view's, at two adjacent levels
    for (size_t l = static_cast<size_t>(levels); l >= 1; --l) {
      PatchMatchViewInput in = inputs[v];
      in.reference = &pyramid[l][v];
      in.reference_grey = &pyramid_greys[l][v];
      for (size_t k = 0; k < in.sources.size(); ++k) {
        const size_t s = static_cast<size_t>(setups[v].sources[k]);
        in.sources[k] = &pyramid[l][s];
        in.source_greys[k] = &pyramid_greys[l][s];
        in.source_depths[k] = nullptr;
      }
      if (l == static_cast<size_t>(levels)) {
        RunPhotometricPatchMatch(in, options, &pool, &coarse_map);
      } else {
        RunPatchMatchFromCoarse(in, coarse_map, pyramid[l + 1][v], options, &pool, &finer_map);
        std::swap(coarse_map, finer_map);
      }
    }
    if (levels > 0) {
      RunPatchMatchFromCoarse(inputs[v], coarse_map, pyramid[1][v], options, &pool, &maps[v]);
    } else {
      RunPhotometricPatchMatch(inputs[v], options, &pool, &maps[v]);
    }
    maps[v].source_masks = std::vector<uint32_t>();
    if (progress) progress->Advance();
  }
  pyramid.clear();
  pyramid_greys.clear();
  if (options.geometric_iterations > 0) {
    for (size_t v = 0; v < num_views; ++v) {
      if (!setups[v].valid) continue;
      RunGeometricPatchMatch(inputs[v], options, &pool, &maps[v]);
      maps[v].source_masks = std::vector<uint32_t>();
      if (progress) progress->Advance();
    }
  }
  if (progress) progress->Finish();
  r.views = views_with_maps;
  r.seconds_propagation = SecondsSince(start);

  DepthFusionStats stats;
  OrientedPoints points = FuseDepthMaps(views, maps, sources, options, &pool, &stats);
  r.depth_pixels = stats.depth_pixels;
  r.consistent_pixels = stats.consistent_pixels;
  r.seconds_consistency = stats.seconds_consistency;
  r.seconds_fusion = stats.seconds_fusion;
  r.fused_points = points.size();
  for (size_t v = 0; v < num_views; ++v) {
    r.map_bytes += maps[v].SizeBytes() + greys[v].size_bytes() + 2 * maps[v].depth.size();
  }
  if (points.size() == 0) {
    return FailedPrecondition(
        "PatchMatch MVS: no point fused (" + std::to_string(views_with_maps) + " depth maps, " +
        std::to_string(stats.depth_pixels) + " pixels with cost <= " + std::to_string(options.max_cost) + ", " +
        std::to_string(stats.consistent_pixels) + " consistent); textureless or unrelated views?");
  }
  return points;
}

}  // namespace reconar
