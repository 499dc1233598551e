#include "core/mvs/pmvs/patch_mvs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "tests/core/mvs/pmvs/textured_box_scene.h"

namespace reconar {
namespace {

using testing::TexturedBoxScene;
using testing::TexturedBoxSceneOptions;

struct Evaluation {
  double footprint = 0.0;        // world size of one pixel at the scene centre's distance
  double mean_distance = 0.0;    // of the points to the true surface
  double median_distance = 0.0;
  double median_normal_error_degrees = 0.0;
  double fraction_normals_within_15 = 0.0;
  double fraction_within_footprint = 0.0;  // points closer to the surface than one footprint
  double coverage = 0.0;         // of the cells seen by >= 3 cameras within 60 degrees
};

Evaluation Evaluate(const TexturedBoxScene& scene, const TexturedBoxSceneOptions& scene_options,
                    const OrientedPoints& points, int cell_size) {
  Evaluation e;
  const std::vector<DenseView>& views = scene.views();
  double distance_sum = 0.0;
  for (const DenseView& v : views) distance_sum += (v.Center() - scene_options.target).norm();
  e.footprint = distance_sum / views.size() / scene_options.focal;

  std::vector<double> distances, angles;
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector3d normal;
    const Eigen::Vector3d x = points.positions[i].cast<double>();
    distances.push_back(scene.DistanceToSurface(x, &normal));
    const double c = std::clamp(static_cast<double>(points.normals[i].cast<double>().dot(normal)), -1.0, 1.0);
    angles.push_back(std::acos(c) * 180.0 / M_PI);
  }
  for (double d : distances) {
    e.mean_distance += d / distances.size();
    if (d < e.footprint) e.fraction_within_footprint += 1.0 / distances.size();
  }
  std::sort(distances.begin(), distances.end());
  std::sort(angles.begin(), angles.end());
  e.median_distance = distances[distances.size() / 2];
  e.median_normal_error_degrees = angles[angles.size() / 2];
  e.fraction_normals_within_15 =
      static_cast<double>(std::lower_bound(angles.begin(), angles.end(), 15.0) - angles.begin()) / angles.size();

  // Coverage: cells whose surface point is seen by at least 3 cameras within 60 degrees (what PMVS
  // can reconstruct), holding a point no deeper than the surface plus two footprints.
  size_t seen = 0, covered = 0;
  for (const DenseView& view : views) {
    const int cols = view.width() / cell_size, rows = view.height() / cell_size;
    std::vector<double> nearest(static_cast<size_t>(cols) * rows, std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d x = points.positions[i].cast<double>();
      if (view.Depth(x) <= 0.0) continue;
      const Eigen::Vector2d p = view.Project(x);
      const int cx = static_cast<int>(std::floor((p.x() + 0.5) / cell_size));
      const int cy = static_cast<int>(std::floor((p.y() + 0.5) / cell_size));
      if (cx < 0 || cy < 0 || cx >= cols || cy >= rows) continue;
      double& n = nearest[static_cast<size_t>(cy) * cols + cx];
      n = std::min(n, view.Depth(x));
    }
    for (int cy = 0; cy < rows; ++cy) {
      for (int cx = 0; cx < cols; ++cx) {
        const double u = (cx + 0.5) * cell_size - 0.5, v = (cy + 0.5) * cell_size - 0.5;
        const Eigen::Vector3d ray = (view.cam_from_world.rotation.transpose() *
                                     Eigen::Vector3d((u - view.cx) / view.fx, (v - view.cy) / view.fy, 1.0))
                                        .normalized();
        const testing::SceneHit hit = scene.Intersect(view.Center(), ray);
        if (!hit.hit) continue;
        Eigen::Vector3d normal;
        scene.DistanceToSurface(hit.point, &normal);
        int cameras = 0;
        for (const DenseView& other : views) {
          const Eigen::Vector3d to_camera = (other.Center() - hit.point).normalized();
          const Eigen::Vector2d q = other.Project(hit.point);
          if (normal.dot(to_camera) > 0.5 && q.x() >= 4 && q.y() >= 4 && q.x() < other.width() - 5 &&
              q.y() < other.height() - 5 && scene.Sees(other, hit.point)) {
            ++cameras;
          }
        }
        if (cameras < 3) continue;
        ++seen;
        const double depth = view.Depth(hit.point);
        if (nearest[static_cast<size_t>(cy) * cols + cx] <= depth + 2.0 * e.footprint) ++covered;
      }
    }
  }
  e.coverage = seen ? static_cast<double>(covered) / seen : 0.0;
  return e;
}

// A 128 x 96 rendering (fast under qemu too). It keeps the default scene's texel * focal, the
// texels per pixel, so the images carry the same texture at the pixel scale as the default
// 320 x 240 one (which gave the same figures: mean 0.077 px, coverage 0.986).
TexturedBoxSceneOptions AccuracySceneOptions() {
  TexturedBoxSceneOptions scene_options;
  scene_options.width = 128;
  scene_options.height = 96;
  scene_options.focal = 120.0;
  scene_options.texel = 0.05;
  return scene_options;
}

TEST(PatchMvsTest, TexturedBoxIsAccurateAndDense) {
  const TexturedBoxSceneOptions scene_options = AccuracySceneOptions();
  const TexturedBoxScene scene(scene_options);
  PatchMvsOptions options;
  if (const char* t = std::getenv("PMVS_TEST_THREADS")) options.num_threads = std::atoi(t);
  PatchMvsReport report;
  const auto start = std::chrono::steady_clock::now();
  Result<OrientedPoints> result = RunPatchMvs(scene.view_pointers(), options, &report);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const OrientedPoints& points = result.value();
  ASSERT_EQ(points.normals.size(), points.size());
  ASSERT_EQ(points.colors.size(), points.size());
  ASSERT_EQ(points.scores.size(), points.size());
  const Evaluation e = Evaluate(scene, scene_options, points, options.cell_size);
  std::printf(
      "features %zu, initial %zu, expanded %zu, final %zu; %.2f s (features %.2f, matching %.2f, expansion %.2f, "
      "filtering %.2f)\nfootprint %.4f; distance mean %.4f (%.3f px), median %.4f (%.3f px); normal error median "
      "%.2f deg, within 15 deg %.3f; within one footprint %.4f; coverage %.3f\n",
      report.features, report.initial_patches, report.expanded_patches, report.final_patches, seconds,
      report.seconds_features, report.seconds_matching, report.seconds_expansion, report.seconds_filtering,
      e.footprint, e.mean_distance, e.mean_distance / e.footprint, e.median_distance,
      e.median_distance / e.footprint, e.median_normal_error_degrees, e.fraction_normals_within_15, e.fraction_within_footprint, e.coverage);
  EXPECT_GT(report.initial_patches, 0u);
  EXPECT_GT(report.expanded_patches, report.initial_patches);
  EXPECT_EQ(report.final_patches, points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_NEAR(points.normals[i].norm(), 1.0f, 1e-4f);
    ASSERT_GE(points.scores[i], static_cast<float>(options.min_ncc));
  }
  // Bars from the geometry: with exact images the NCC optimum localises a patch to a fraction of a
  // pixel, so the mean error stays below a quarter of the pixel footprint and nearly every point
  // lies within one footprint; a 5x5 patch spans 5 footprints, so a one-footprint height error
  // across it would tilt the normal by atan(1/5) = 11 degrees: the median stays below 10.
  EXPECT_LT(e.mean_distance, 0.25 * e.footprint);
  EXPECT_GT(e.fraction_within_footprint, 0.98);
  EXPECT_LT(e.median_normal_error_degrees, 10.0);
  EXPECT_GT(e.fraction_normals_within_15, 0.8);
  // Expansion reaches most of the surface that at least gamma = 3 cameras see within iota.
  EXPECT_GT(e.coverage, 0.8);
}

TEST(PatchMvsTest, SameResultForAnyThreadCount) {
  TexturedBoxSceneOptions scene_options;
  scene_options.width = 96;
  scene_options.height = 72;
  scene_options.focal = 90.0;
  scene_options.texel = 0.0667;  // the same texels per pixel as the default scene
  const TexturedBoxScene scene(scene_options);
  PatchMvsOptions options;
  options.expansion_iterations = 1;
  options.num_threads = 1;
  Result<OrientedPoints> one = RunPatchMvs(scene.view_pointers(), options);
  options.num_threads = 3;
  Result<OrientedPoints> three = RunPatchMvs(scene.view_pointers(), options);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  ASSERT_TRUE(three.ok()) << three.status().ToString();
  ASSERT_EQ(one.value().size(), three.value().size());
  EXPECT_GT(one.value().size(), 500u);
  for (size_t i = 0; i < one.value().size(); ++i) {
    ASSERT_EQ(one.value().positions[i], three.value().positions[i]) << i;
    ASSERT_EQ(one.value().normals[i], three.value().normals[i]) << i;
  }
}

TEST(PatchMvsTest, RejectsBadOptionsAndViews) {
  TexturedBoxSceneOptions scene_options;
  scene_options.num_cameras = 3;
  scene_options.width = 64;
  scene_options.height = 48;
  const TexturedBoxScene scene(scene_options);
  PatchMvsOptions options;
  options.patch_size = 4;
  EXPECT_EQ(RunPatchMvs(scene.view_pointers(), options).status().code(), StatusCode::kInvalidArgument);
  options = PatchMvsOptions();
  options.max_view_angle = 2.0;
  EXPECT_EQ(RunPatchMvs(scene.view_pointers(), options).status().code(), StatusCode::kInvalidArgument);
  options = PatchMvsOptions();
  options.image_noise_std = -1.0;
  EXPECT_EQ(RunPatchMvs(scene.view_pointers(), options).status().code(), StatusCode::kInvalidArgument);
  options = PatchMvsOptions();
  EXPECT_NEAR(options.MinTextureStd(), 2.0 / std::sqrt(0.3), 1e-12);  // sigma_n / sqrt(1 - min_ncc)
  std::vector<const DenseView*> views = scene.view_pointers();
  views[1] = nullptr;
  EXPECT_EQ(RunPatchMvs(views, options).status().code(), StatusCode::kInvalidArgument);
  views.resize(2);
  EXPECT_EQ(RunPatchMvs(views, options).status().code(), StatusCode::kFailedPrecondition);
}

TEST(PatchMvsTest, Textureless3ViewsFailCleanly) {
  std::vector<DenseView> views(3);
  std::vector<const DenseView*> pointers;
  for (int i = 0; i < 3; ++i) {
    views[i].gray = Image<uint8_t>(80, 60, 1);
    views[i].rgb = Image<uint8_t>(80, 60, 3);
    std::fill(views[i].gray.data(), views[i].gray.data() + 80 * 60, 128);
    views[i].fx = views[i].fy = 80.0;
    views[i].cx = 39.5;
    views[i].cy = 29.5;
    views[i].cam_from_world.translation = Eigen::Vector3d(0.1 * i, 0.0, 2.0);
    pointers.push_back(&views[i]);
  }
  Result<OrientedPoints> result = RunPatchMvs(pointers, PatchMvsOptions());
  EXPECT_EQ(result.status().code(), StatusCode::kFailedPrecondition) << result.status().ToString();
}

}  // namespace
}  // namespace reconar
