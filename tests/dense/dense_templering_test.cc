// The dense stage on Middlebury templeRing with its ground-truth cameras. Middlebury keeps the
// reference mesh private, so what can be checked honestly is where the points are: inside the
// README's tight bounding box of the temple, and how many there are.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "tests/dense/dense_runs.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace testing {
namespace {

const std::string kParPath = std::string(RECONAR_SHARED_DATA_DIR) + "/middlebury_templeRing/templeR_par.txt";

// The share of points inside the box enlarged by TempleRingDenseOptions::box_margin_m (2 mm, one
// 5 x 5 patch at full resolution). Without PMVS's texture floor (PatchMvsOptions::image_noise_std)
// it was 0.85 with 12 views: near-black windows (grey std < 4, mean < 32) 16-64 mm from the box,
// noise and quantisation patterns that passed the NCC test. With the floor, what lies outside,
// projected into the images, is mostly the black velvet over the stand and backdrop next to the
// temple's base (grey std 4-8, a real texture seen consistently from several views): a genuine
// surface that the README's box of the temple excludes, plus sparse floaters. So the share cannot
// approach 1 on this data; the bar asks for nine points in ten on the object, which unfiltered
// background matching fails.
constexpr double kMinInBoxFraction = 0.9;
// Point count floor: patches are wanted one per beta x beta = 2 x 2 pixel cell; the temple covers
// roughly a third of each frame, so one view alone is worth 0.33 * W * H / 4 patches at the level
// used. The ring sees front, back and sides, so the union holds several views' worth; we ask for
// one view's worth.
constexpr double kForegroundShareOfFrame = 0.33;

// Unlike tests/tools/dense_cli_test.cc (templeSparseRing), this box check does not exclude the
// textured floor the temple stands on. Through the dense stage at level 1 with 24 views the share
// was 0.838 (49,221 points) before the stage removed isolated points and small floating pieces
// (core/mesh/poisson/point_outliers.h); with that filter it is 0.903 (44,235 points).
TEST(DenseTempleRingTest, PointsLieInTheTemplesBoundingBox) {
  const std::string dir = MakeTestDirectory("reconar_dense_templering");
  TempleRingDenseOptions options;
  options.level = 1;
  options.num_threads = 2;
  options.import.view_stride = 2;  // 24 of the 47 views, about 15 degrees apart on the ring
  auto figures = RunTempleRingDense(kParPath, dir, options);
  ASSERT_TRUE(figures.ok()) << figures.status().ToString();
  std::printf("templeRing: %d views, level %d, %d clusters, %zu points, %.3f in the box (+%.1f mm), dense %.1f s\n",
              figures->import.views, figures->dense.level, figures->dense.clusters, figures->points,
              figures->in_box_fraction, 1e3 * options.box_margin_m, figures->seconds_dense);
  EXPECT_GE(figures->in_box_fraction, kMinInBoxFraction);
  const double pixels_at_level = 640.0 * 480.0 / (1 << (2 * figures->dense.level));
  EXPECT_GE(static_cast<double>(figures->points), kForegroundShareOfFrame * pixels_at_level / 4.0);
}

// PatchMatch (issue 16) on the same 24 views, with the bar: 0.95 of the points in the box.
// Its fusion keeps only planes that face their camera within 60 degrees: without that the
// platform under the temple, seen at 63-75 degrees from every camera, was 30 % of the points.
constexpr double kPatchMatchMinInBoxFraction = 0.95;

TEST(DenseTempleRingTest, PatchMatchPointsLieInTheTemplesBoundingBox) {
  const std::string dir = MakeTestDirectory("reconar_dense_templering_patchmatch");
  TempleRingDenseOptions options;
  options.method = DenseMethod::kPatchMatch;
  options.level = 1;
  options.num_threads = 2;
  options.import.view_stride = 2;
  auto figures = RunTempleRingDense(kParPath, dir, options);
  ASSERT_TRUE(figures.ok()) << figures.status().ToString();
  std::printf("templeRing PatchMatch: %d views, level %d, %zu points, %.3f in the box (+%.1f mm), dense %.1f s\n",
              figures->import.views, figures->dense.level, figures->points, figures->in_box_fraction,
              1e3 * options.box_margin_m, figures->seconds_dense);
  EXPECT_EQ(figures->dense.method, DenseMethod::kPatchMatch);
  EXPECT_GE(figures->in_box_fraction, kPatchMatchMinInBoxFraction);
  const double pixels_at_level = 640.0 * 480.0 / (1 << (2 * figures->dense.level));
  EXPECT_GE(static_cast<double>(figures->points), kForegroundShareOfFrame * pixels_at_level / 4.0);
}

}  // namespace
}  // namespace testing
}  // namespace reconar
