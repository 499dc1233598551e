#include "core/mvs/patchmatch/patchmatch_mvs.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

#include "core/base/elapsed.h"
#include "core/base/prng.h"
#include "core/base/thread_pool.h"
#include "core/mvs/patchmatch/view_selection.h"
#include "tests/core/mvs/pmvs/textured_box_scene.h"

namespace reconar {
namespace {

using testing::SceneHit;
using testing::TexturedBoxScene;
using testing::TexturedBoxSceneOptions;

// 12 cameras on the ring (30 degrees apart); the tests take 4 consecutive ones. 160 x 120 keeps
// the run short under qemu; texel * focal is that of the default scene (6), so a texel spans the
// same 1.7 pixels.
TexturedBoxSceneOptions SceneOptions(int width, int height) {
  TexturedBoxSceneOptions o;
  o.num_cameras = 12;
  o.width = width;
  o.height = height;
  o.focal = 150.0 * width / 160.0;
  o.texel = 6.0 / o.focal;
  return o;
}

std::vector<const DenseView*> FirstViews(const TexturedBoxScene& scene, int count) {
  std::vector<const DenseView*> views = scene.view_pointers();
  views.resize(static_cast<size_t>(count));
  return views;
}

Eigen::Vector3d PixelRay(const DenseView& view, double u, double v) {
  return (view.cam_from_world.rotation.transpose() *
          Eigen::Vector3d((u - view.cx) / view.fx, (v - view.cy) / view.fy, 1.0))
      .normalized();
}

// Sparse points: surface points under seeded random pixels of the views.
std::vector<Eigen::Vector3d> SparsePoints(const TexturedBoxScene& scene, const std::vector<const DenseView*>& views,
                                          int count) {
  std::vector<Eigen::Vector3d> points;
  SplitMix64 random(12345);
  auto uniform = [&]() { return random.Uniform01(); };
  while (static_cast<int>(points.size()) < count) {
    const DenseView& view = *views[static_cast<size_t>(uniform() * views.size()) % views.size()];
    const SceneHit hit =
        scene.Intersect(view.Center(), PixelRay(view, uniform() * (view.width() - 1), uniform() * (view.height() - 1)));
    if (hit.hit) points.push_back(hit.point);
  }
  return points;
}

double Quantile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(q * values.size()))];
}

struct Evaluation {
  double footprint = 0.0;        // world size of a pixel at the mean camera-target distance
  double sin_angle = 0.0;        // sine of the angle between adjacent cameras at the target
  double median_distance = 0.0;  // of the fused points to the true surface
  double distance_90 = 0.0;
  double median_normal_degrees = 0.0;
  double completeness = 0.0;  // of the eligible cells (see Evaluate)
  size_t eligible_cells = 0;
  double panel_completeness = 0.0;  // of the eligible cells in blank panels
  size_t panel_cells = 0;
};

// Completeness: a 2 x 2 pixel cell of a view is eligible when the surface point at its centre
// (a) lies on the same face as the surface points under the four corners of the NCC window
// around it (the window sees one plane), (b) is seen by the view within 60 degrees of its normal
// and, so too, at least window_radius pixels inside the image and at a triangulation angle of at
// most max_triangulation_angle_deg (a pair of views beyond it is never matched), by at least
// fusion_min_views of the other views. (The renderer samples the texture at pixel centres without filtering, so under
// grazing views it aliases differently in every view: no matcher can use those pixels.)
// Those are the cells whose pixels can be matched and confirmed; a cell is covered when a fused
// point projects into it no farther than two footprints from the surface along the ray.
Evaluation Evaluate(const TexturedBoxScene& scene, const TexturedBoxSceneOptions& scene_options,
                    const std::vector<const DenseView*>& views, const PatchMatchOptions& options,
                    const OrientedPoints& points) {
  Evaluation e;
  double distance_sum = 0.0;
  for (const DenseView* v : views) distance_sum += (v->Center() - scene_options.target).norm();
  e.footprint = distance_sum / views.size() / scene_options.focal;
  const Eigen::Vector3d a = views[0]->Center() - scene_options.target, b = views[1]->Center() - scene_options.target;
  e.sin_angle = a.cross(b).norm() / (a.norm() * b.norm());

  std::vector<double> distances, angles;
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector3d normal;
    distances.push_back(scene.DistanceToSurface(points.positions[i].cast<double>(), &normal));
    const double c = std::clamp(points.normals[i].cast<double>().dot(normal), -1.0, 1.0);
    angles.push_back(std::acos(c) * 180.0 / M_PI);
  }
  e.median_distance = Quantile(distances, 0.5);
  e.distance_90 = Quantile(distances, 0.9);
  e.median_normal_degrees = Quantile(angles, 0.5);

  const int cell = 2, r = options.window_radius;
  size_t covered = 0, panel_covered = 0;
  for (const DenseView* view : views) {
    const int cols = view->width() / cell, rows = view->height() / cell;
    std::vector<double> nearest(static_cast<size_t>(cols) * rows, std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d x = points.positions[i].cast<double>();
      if (view->Depth(x) <= 0.0) continue;
      const Eigen::Vector2d p = view->Project(x);
      const int cx = static_cast<int>(std::floor((p.x() + 0.5) / cell)),
                cy = static_cast<int>(std::floor((p.y() + 0.5) / cell));
      if (cx < 0 || cy < 0 || cx >= cols || cy >= rows) continue;
      double& n = nearest[static_cast<size_t>(cy) * cols + cx];
      n = std::min(n, view->Depth(x));
    }
    for (int cy = 0; cy < rows; ++cy) {
      for (int cx = 0; cx < cols; ++cx) {
        const double u = (cx + 0.5) * cell - 0.5, v = (cy + 0.5) * cell - 0.5;
        const SceneHit hit = scene.Intersect(view->Center(), PixelRay(*view, u, v));
        if (!hit.hit) continue;
        bool one_plane = true;
        for (int corner = 0; corner < 4 && one_plane; ++corner) {
          const SceneHit c = scene.Intersect(view->Center(),
                                             PixelRay(*view, u + ((corner & 1) ? r : -r), v + ((corner & 2) ? r : -r)));
          one_plane = c.hit && c.face == hit.face;
        }
        if (!one_plane) continue;
        Eigen::Vector3d normal;
        scene.DistanceToSurface(hit.point, &normal);
        if (normal.dot((view->Center() - hit.point).normalized()) <= 0.5) continue;
        int others = 0;
        for (const DenseView* other : views) {
          if (other == view) continue;
          const Eigen::Vector2d q = other->Project(hit.point);
          const Eigen::Vector3d to_view = (view->Center() - hit.point).normalized();
          const Eigen::Vector3d to_other = (other->Center() - hit.point).normalized();
          const double angle = std::acos(std::clamp(to_view.dot(to_other), -1.0, 1.0)) * 180.0 / M_PI;
          if (normal.dot(to_other) > 0.5 && other->Depth(hit.point) > 0.0 &&
              angle <= options.max_triangulation_angle_deg && q.x() >= r && q.y() >= r &&
              q.x() <= other->width() - 1 - r && q.y() <= other->height() - 1 - r && scene.Sees(*other, hit.point)) {
            ++others;
          }
        }
        if (others < options.fusion_min_views) continue;
        ++e.eligible_cells;
        const bool panel = scene.InBlankPanel(hit.face, hit.point);
        e.panel_cells += panel;
        if (nearest[static_cast<size_t>(cy) * cols + cx] <= view->Depth(hit.point) + 2.0 * e.footprint) {
          ++covered;
          panel_covered += panel;
        }
      }
    }
  }
  e.completeness = e.eligible_cells ? static_cast<double>(covered) / e.eligible_cells : 0.0;
  e.panel_completeness = e.panel_cells ? static_cast<double>(panel_covered) / e.panel_cells : 0.0;
  return e;
}

// PATCHMATCH_TEST_WIDTH (e.g. 640) renders the scene larger for a timing; PATCHMATCH_TEST_VIEWS
// takes more of the ring's cameras. The bounds hold at any size: they scale with the footprint.
void ExpectAccurateAndComplete(PatchMatchOptions options) {
  const char* width = std::getenv("PATCHMATCH_TEST_WIDTH");
  const int w = width ? std::max(64, std::atoi(width)) : 160;
  const TexturedBoxSceneOptions scene_options = SceneOptions(w, w * 3 / 4);
  const TexturedBoxScene scene(scene_options);
  const char* num_views = std::getenv("PATCHMATCH_TEST_VIEWS");
  const std::vector<const DenseView*> views =
      FirstViews(scene, num_views ? std::clamp(std::atoi(num_views), 2, 12) : 4);
  const std::vector<Eigen::Vector3d> sparse = SparsePoints(scene, views, 300);
  if (const char* t = std::getenv("PATCHMATCH_TEST_THREADS")) options.num_threads = std::atoi(t);
  if (const char* c = std::getenv("PATCHMATCH_TEST_LEVELS")) options.coarse_levels = std::atoi(c);
  PatchMatchReport report;
  const auto start = std::chrono::steady_clock::now();
  Result<OrientedPoints> result = RunPatchMatchMvs(views, sparse, options, &report);
  const double seconds = SecondsSince(start);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const OrientedPoints& points = result.value();
  const size_t n = points.size();
  ASSERT_TRUE(points.normals.size() == n && points.colors.size() == n && points.scores.size() == n);
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_NEAR(points.normals[i].norm(), 1.0f, 1e-4f);
    ASSERT_GE(points.scores[i], static_cast<float>(1.0 - options.max_cost) - 1e-6f);
  }
  const Evaluation e = Evaluate(scene, scene_options, views, options, points);
  const double bound_scale = e.footprint / e.sin_angle;  // depth error per pixel of matching error
  std::printf(
      "coarse levels %d, geometric sweeps %d: %zu views, %zu depth pixels, %zu consistent, %zu points; %.2f s "
      "(selection %.3f, "
      "propagation %.2f, consistency %.3f, fusion %.3f)\nfootprint %.4f, sin(angle) %.3f, footprint / sin %.4f; "
      "distance median %.4f (%.3f px), 90%% %.4f (%.3f px); normal error median %.2f deg; completeness %.3f of "
      "%zu cells\n",
      options.coarse_levels, options.geometric_iterations, report.views, report.depth_pixels, report.consistent_pixels,
      report.fused_points, seconds, report.seconds_selection, report.seconds_propagation, report.seconds_consistency,
      report.seconds_fusion, e.footprint, e.sin_angle, bound_scale, e.median_distance, e.median_distance / bound_scale,
      e.distance_90, e.distance_90 / bound_scale, e.median_normal_degrees, e.completeness, e.eligible_cells);
  EXPECT_EQ(report.views, views.size());
  EXPECT_EQ(report.fused_points, points.size());
  size_t pixels = 0;
  for (const DenseView* v : views) pixels += static_cast<size_t>(v->width()) * v->height();
  EXPECT_EQ(report.map_bytes, pixels * kPatchMatchBytesPerPixel);
  // Accuracy from the geometry: moving a point along its reference ray by D moves its image in a
  // source view by about D sin(angle) / footprint pixels, so a matching error of d pixels gives a
  // depth error of d footprint / sin(angle), and the distance to the surface is at most that. On
  // noise-free renderings (8-bit quantisation, bilinear texture) the NCC optimum of a 36-sample
  // window localises to well under a pixel: median d <= 0.25 px and 90 % of d <= 0.5 px.
  EXPECT_LT(e.median_distance, 0.25 * bound_scale);
  EXPECT_LT(e.distance_90, 0.5 * bound_scale);
  // A window of 11 px spanning the footprint error of 0.5 px tilts the normal by atan(0.5 / 5.5) =
  // 5 degrees per pixel of height error; the median normal stays within 10 degrees.
  EXPECT_LT(e.median_normal_degrees, 10.0);
  // Every eligible cell can be matched and confirmed; the allowance of 10 % is for sweeps that did
  // not converge in the budget of `iterations` and for cells next to occluding edges in a source.
  EXPECT_GT(e.eligible_cells, 1000u);
  EXPECT_GT(e.completeness, 0.9);
}

TEST(PatchMatchMvsTest, TexturedBoxIsAccurateAndComplete) { ExpectAccurateAndComplete(PatchMatchOptions()); }

// The other paths: one resolution, the 8-plane propagation, geometric sweeps.
TEST(PatchMatchMvsTest, GeometricConsistencyKeepsAccuracyAndCompleteness) {
  PatchMatchOptions options;
  options.coarse_levels = 0;
  options.separate_near_neighbours = true;
  options.geometric_iterations = 1;
  ExpectAccurateAndComplete(options);
}

// On the ring of 12 cameras 30 degrees apart, the angle at the target between cameras k steps
// apart is 25.6, 50.8, 74.7 degrees for k = 1, 2, 3: with the default [3, 60] degrees every view
// takes the two neighbours on each side as sources (their order, by shared points, is not
// asserted: the sparse points carry no visibility, so the counts of near and far neighbours can
// tie). The depth range holds the true depth of every sparse point the view sees.
TEST(PatchMatchMvsTest, SelectsNeighbouringSourcesAndDepthRange) {
  const TexturedBoxScene scene(SceneOptions(80, 60));
  const std::vector<const DenseView*> views = scene.view_pointers();
  const std::vector<Eigen::Vector3d> sparse = SparsePoints(scene, views, 600);
  ThreadPool pool(2);
  const std::vector<PatchMatchViewSetup> setups = SetUpPatchMatchViews(views, sparse, PatchMatchOptions(), &pool);
  ASSERT_EQ(setups.size(), views.size());
  for (int v = 0; v < 12; ++v) {
    const PatchMatchViewSetup& setup = setups[static_cast<size_t>(v)];
    ASSERT_TRUE(setup.valid) << v;
    std::vector<int> sources = setup.sources;
    ASSERT_EQ(sources.size(), 4u) << v;
    std::sort(sources.begin(), sources.end());
    std::vector<int> all = {(v + 1) % 12, (v + 2) % 12, (v + 10) % 12, (v + 11) % 12};
    std::sort(all.begin(), all.end());
    EXPECT_EQ(sources, all) << v;
    for (const Eigen::Vector3d& x : sparse) {
      const DenseView& view = *views[static_cast<size_t>(v)];
      const Eigen::Vector2d p = view.Project(x);
      if (view.Depth(x) <= 0.0 || p.x() < -0.5 || p.y() < -0.5 || p.x() >= view.width() - 0.5 ||
          p.y() >= view.height() - 0.5 || !scene.Sees(view, x)) {
        continue;
      }
      EXPECT_GE(view.Depth(x), setup.depth_min) << v;
      EXPECT_LE(view.Depth(x), setup.depth_max) << v;
    }
  }
}

TEST(PatchMatchMvsTest, SameResultForAnyThreadCount) {
  const TexturedBoxScene scene(SceneOptions(120, 90));
  const std::vector<const DenseView*> views = FirstViews(scene, 3);
  const std::vector<Eigen::Vector3d> sparse = SparsePoints(scene, views, 200);
  PatchMatchOptions options;
  options.iterations = 2;
  options.num_threads = 1;
  Result<OrientedPoints> one = RunPatchMatchMvs(views, sparse, options);
  options.num_threads = 3;
  Result<OrientedPoints> three = RunPatchMatchMvs(views, sparse, options);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  ASSERT_TRUE(three.ok()) << three.status().ToString();
  ASSERT_EQ(one.value().size(), three.value().size());
  EXPECT_GT(one.value().size(), 100u);  // a non-trivial result to compare
  for (size_t i = 0; i < one.value().size(); ++i) {
    ASSERT_EQ(one.value().positions[i], three.value().positions[i]) << i;
    ASSERT_EQ(one.value().normals[i], three.value().normals[i]) << i;
    ASSERT_EQ(one.value().scores[i], three.value().scores[i]) << i;
  }
  // A fusion grid of step 2 lets a quarter of the pixels start points: fewer points, yet more than
  // an eighth of the step-1 count (a start is lost only when an earlier point used its pixel).
  options.fusion_pixel_step = 2;
  Result<OrientedPoints> sparse_grid = RunPatchMatchMvs(views, sparse, options);
  ASSERT_TRUE(sparse_grid.ok()) << sparse_grid.status().ToString();
  EXPECT_LT(sparse_grid.value().size(), one.value().size());
  EXPECT_GT(sparse_grid.value().size(), one.value().size() / 8);
}

TEST(PatchMatchMvsTest, RejectsBadOptionsAndViews) {
  const TexturedBoxScene scene(SceneOptions(64, 48));
  const std::vector<const DenseView*> views = FirstViews(scene, 3);
  const std::vector<Eigen::Vector3d> sparse = SparsePoints(scene, views, 50);
  EXPECT_TRUE(PatchMatchOptions().Check().ok());
  auto expect_bad_option = [&](auto change) {
    PatchMatchOptions options;
    change(&options);
    EXPECT_EQ(options.Check().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(RunPatchMatchMvs(views, sparse, options).status().code(), StatusCode::kInvalidArgument);
  };
  expect_bad_option([](PatchMatchOptions* o) { o->window_radius = 0; });
  expect_bad_option([](PatchMatchOptions* o) { o->window_step = 7; });
  expect_bad_option([](PatchMatchOptions* o) { o->max_source_views = 0; });
  expect_bad_option([](PatchMatchOptions* o) { o->cost_top_k = 9; });
  expect_bad_option([](PatchMatchOptions* o) { o->iterations = 0; });
  expect_bad_option([](PatchMatchOptions* o) { o->sigma_color = 0.0; });
  expect_bad_option([](PatchMatchOptions* o) { o->max_cost = 2.5; });
  expect_bad_option([](PatchMatchOptions* o) { o->fusion_min_views = 0; });
  expect_bad_option([](PatchMatchOptions* o) { o->min_triangulation_angle_deg = 70.0; });
  expect_bad_option([](PatchMatchOptions* o) { o->depth_margin = std::nan(""); });
  expect_bad_option([](PatchMatchOptions* o) { o->geometric_iterations = -1; });
  expect_bad_option([](PatchMatchOptions* o) { o->coarse_levels = 5; });
  expect_bad_option([](PatchMatchOptions* o) { o->fusion_pixel_step = 0; });
  expect_bad_option([](PatchMatchOptions* o) { o->fine_iterations = -1; });
  expect_bad_option([](PatchMatchOptions* o) { o->fill_min_support = 9; });
  expect_bad_option([](PatchMatchOptions* o) { o->fill_max_distance = 0.0; });
  expect_bad_option([](PatchMatchOptions* o) { o->fill_max_normal_deg = 90.0; });
  expect_bad_option([](PatchMatchOptions* o) { o->fill_max_relative_depth = std::nan(""); });

  const PatchMatchOptions options;
  std::vector<const DenseView*> with_null = views;
  with_null[1] = nullptr;
  EXPECT_EQ(RunPatchMatchMvs(with_null, sparse, options).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(RunPatchMatchMvs({views[0]}, sparse, options).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(RunPatchMatchMvs({}, sparse, options).status().code(), StatusCode::kInvalidArgument);
  DenseView mismatched = *views[1];
  mismatched.rgb = Image<uint8_t>(mismatched.width() + 1, mismatched.height(), 3);
  EXPECT_EQ(RunPatchMatchMvs({views[0], &mismatched}, sparse, options).status().code(), StatusCode::kInvalidArgument);
  DenseView no_focal = *views[1];
  no_focal.fx = 0.0;
  EXPECT_EQ(RunPatchMatchMvs({views[0], &no_focal}, sparse, options).status().code(), StatusCode::kInvalidArgument);
  // No sparse point (a model imported with known cameras): the views' depth ranges and sources
  // come from the cameras' geometry, the point their optical axes meet nearest (the box's centre
  // for this ring), so points are still fused.
  auto from_cameras = RunPatchMatchMvs(views, {}, options);
  ASSERT_TRUE(from_cameras.ok()) << from_cameras.status().ToString();
  EXPECT_GT(from_cameras->size(), 0u);
}

// Non-finite sparse points and a degenerate (zero) rotation: a status or points, never a crash
// or an out-of-bounds read (run under the sanitizers too).
TEST(PatchMatchMvsTest, HostileInputIsHandled) {
  const TexturedBoxScene scene(SceneOptions(64, 48));
  std::vector<DenseView> views;
  for (const DenseView* v : FirstViews(scene, 3)) views.push_back(*v);
  views[2].cam_from_world.rotation.setZero();
  std::vector<const DenseView*> pointers;
  for (const DenseView& v : views) pointers.push_back(&v);
  std::vector<Eigen::Vector3d> sparse = SparsePoints(scene, pointers, 100);
  sparse.push_back(Eigen::Vector3d(std::nan(""), 0.0, 1.0));
  sparse.push_back(Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0.0, 1.0));
  sparse.push_back(views[0].Center());  // at a camera centre: depth 0
  PatchMatchOptions options;
  options.geometric_iterations = 1;
  Result<OrientedPoints> result = RunPatchMatchMvs(pointers, sparse, options);
  if (result.ok()) {
    for (size_t i = 0; i < result.value().size(); ++i) ASSERT_TRUE(result.value().positions[i].allFinite());
  } else {
    EXPECT_EQ(result.status().code(), StatusCode::kFailedPrecondition) << result.status().ToString();
  }
}

// The box's sides are plain grey inside a textured frame (texture-poor panels, like white walls
// between door frames): their pixels have no texture to match, so their planes come from the frame
// (PatchMatchOptions::fill_min_support). The plain background beside the
// ground is never enclosed by one plane, and must stay empty: every point lies on the surface
// within the textured box's accuracy bound.
TEST(PatchMatchMvsTest, TexturePoorPanelsTakeThePlaneOfTheirFrame) {
  TexturedBoxSceneOptions scene_options = SceneOptions(240, 180);
  scene_options.blank_panel_inset = 0.1;
  scene_options.num_cameras = 24;  // 15 degrees apart: 3 or 4 of the first 6 see each of two sides within 60 degrees
  const TexturedBoxScene scene(scene_options);
  const std::vector<const DenseView*> views = FirstViews(scene, 6);
  const std::vector<Eigen::Vector3d> sparse = SparsePoints(scene, views, 300);
  PatchMatchOptions without;
  without.fill_min_support = 0;
  for (const PatchMatchOptions& options : {PatchMatchOptions(), without}) {
    Result<OrientedPoints> result = RunPatchMatchMvs(views, sparse, options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    const Evaluation e = Evaluate(scene, scene_options, views, options, *result);
    const double bound_scale = e.footprint / e.sin_angle;
    std::vector<double> distances;
    for (const Eigen::Vector3f& x : result->positions) distances.push_back(scene.DistanceToSurface(x.cast<double>()));
    const double farthest = *std::max_element(distances.begin(), distances.end());
    std::printf(
        "fill %d: %zu points; completeness %.3f of %zu cells, in panels %.3f of %zu; "
        "distance 90%% %.3f px, farthest %.2f px\n",
        options.fill_min_support, result->size(), e.completeness, e.eligible_cells, e.panel_completeness, e.panel_cells,
        e.distance_90 / bound_scale, farthest / bound_scale);
    ASSERT_GT(e.panel_cells, 500u);
    EXPECT_LT(e.distance_90, 0.5 * bound_scale);
    if (options.fill_min_support > 0) {
      EXPECT_GT(e.panel_completeness, 0.8);
      EXPECT_LT(farthest, 4.0 * bound_scale);
    } else {
      EXPECT_LT(e.panel_completeness, 0.5);  // the panels are texture-poor indeed
    }
  }
}

TEST(PatchMatchMvsTest, TexturelessViewsFailCleanly) {
  const TexturedBoxScene scene(SceneOptions(80, 60));
  std::vector<DenseView> views;
  for (const DenseView* v : FirstViews(scene, 3)) views.push_back(*v);
  std::vector<const DenseView*> pointers;
  for (DenseView& v : views) {
    std::fill(v.gray.data(), v.gray.data() + v.gray.size_bytes(), 128);
    std::fill(v.rgb.data(), v.rgb.data() + v.rgb.size_bytes(), 128);
    pointers.push_back(&v);
  }
  PatchMatchReport report;
  Result<OrientedPoints> result =
      RunPatchMatchMvs(pointers, SparsePoints(scene, pointers, 200), PatchMatchOptions(), &report);
  EXPECT_EQ(result.status().code(), StatusCode::kFailedPrecondition) << result.status().ToString();
  EXPECT_EQ(report.views, 3u);
  EXPECT_EQ(report.depth_pixels, 0u);
}

}  // namespace
}  // namespace reconar
