// Outlier tests of core/mesh/poisson/point_outliers.h on a surface sampled like multi-view stereo
// output (spacing growing elevenfold with depth), with isolated points and a floating piece added.
#include "core/mesh/poisson/point_outliers.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace reconar {
namespace {

struct Cloud {
  std::vector<Eigen::Vector3f> positions;
  size_t surface = 0;   // [0, surface): the plane
  size_t isolated = 0;  // then isolated points, then the floating piece
};

// The plane z = 0 over x in [0, 10], y in [0, 1], spacing 0.01 (1 + x), jittered by a tenth of it.
Cloud PerspectivePlane(int isolated, int piece_side) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  Cloud cloud;
  for (float x = 0.0f; x <= 10.0f; x += 0.01f * (1.0f + x)) {
    const float s = 0.01f * (1.0f + x);
    for (float y = 0.0f; y <= 1.0f; y += s) {
      cloud.positions.emplace_back(x + 0.1f * s * unit(rng), y + 0.1f * s * unit(rng), 0.1f * s * unit(rng));
    }
  }
  cloud.surface = cloud.positions.size();
  // Isolated points anywhere in a box ten times the plane's size, at least 1 away from it.
  std::uniform_real_distribution<float> box(-50.0f, 50.0f);
  for (int i = 0; i < isolated; ++i) {
    const float z = box(rng);
    cloud.positions.emplace_back(box(rng), box(rng), z >= 0.0f ? z + 1.0f : z - 1.0f);
  }
  cloud.isolated = static_cast<size_t>(isolated);
  // A floating piece as densely sampled as the plane below it, 0.3 in front of it.
  for (int i = 0; i < piece_side; ++i) {
    for (int j = 0; j < piece_side; ++j) cloud.positions.emplace_back(1.0f + 0.02f * i, 0.4f + 0.02f * j, 0.3f);
  }
  return cloud;
}

TEST(PointOutliersTest, RemovesIsolatedPointsAndFloatingPiecesKeepsTheSurface) {
  const Cloud cloud = PerspectivePlane(60, 6);
  ASSERT_GT(cloud.surface, 5000u);
  OutlierFilterReport report;
  auto keep = FindInlierPoints(cloud.positions, OutlierFilterOptions(), &report);
  ASSERT_TRUE(keep.ok()) << keep.status().ToString();
  size_t surface_kept = 0, isolated_kept = 0, piece_kept = 0;
  for (size_t i = 0; i < cloud.positions.size(); ++i) {
    if (!(*keep)[i]) continue;
    if (i < cloud.surface) {
      ++surface_kept;
    } else if (i < cloud.surface + cloud.isolated) {
      ++isolated_kept;
    } else {
      ++piece_kept;
    }
  }
  EXPECT_GE(static_cast<double>(surface_kept), 0.999 * static_cast<double>(cloud.surface));
  EXPECT_EQ(isolated_kept, 0u);
  EXPECT_EQ(piece_kept, 0u);
  EXPECT_EQ(report.input_points, cloud.positions.size());
  EXPECT_EQ(report.kept_points(), surface_kept + isolated_kept + piece_kept);
  EXPECT_EQ(report.pieces_kept, 1);
  EXPECT_GT(report.median_spacing, 0.01);
  EXPECT_LT(report.median_spacing, 0.11 * 2.0);
}

TEST(PointOutliersTest, SameResultForAnyThreadCount) {
  const Cloud cloud = PerspectivePlane(20, 5);
  OutlierFilterOptions options;
  options.num_threads = 1;
  auto one = FindInlierPoints(cloud.positions, options);
  options.num_threads = 3;
  auto three = FindInlierPoints(cloud.positions, options);
  ASSERT_TRUE(one.ok() && three.ok());
  EXPECT_EQ(*one, *three);
}

TEST(PointOutliersTest, ZeroFractionKeepsEveryPiece) {
  const Cloud cloud = PerspectivePlane(0, 6);
  OutlierFilterOptions options;
  options.min_component_fraction = 0.0;
  OutlierFilterReport report;
  auto keep = FindInlierPoints(cloud.positions, options, &report);
  ASSERT_TRUE(keep.ok());
  EXPECT_EQ(report.small_piece_removed, 0u);
  EXPECT_GE(report.pieces, 2);
}

TEST(PointOutliersTest, TinyCloudsAreKeptAndBadInputIsRejected) {
  const std::vector<Eigen::Vector3f> few = {{0, 0, 0}, {1, 0, 0}, {100, 0, 0}};
  auto keep = FindInlierPoints(few, OutlierFilterOptions());
  ASSERT_TRUE(keep.ok());
  EXPECT_EQ(*keep, std::vector<uint8_t>(3, 1));

  std::vector<Eigen::Vector3f> bad(20, Eigen::Vector3f::Zero());
  bad[5].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(FindInlierPoints(bad, OutlierFilterOptions()).status().code(), StatusCode::kInvalidArgument);
  OutlierFilterOptions options;
  options.min_component_fraction = 1.0;
  EXPECT_EQ(FindInlierPoints(few, options).status().code(), StatusCode::kInvalidArgument);
}

TEST(PointOutliersTest, CoincidentPointsAreNotOutliers) {
  std::vector<Eigen::Vector3f> grid;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) grid.emplace_back(0.1f * i, 0.1f * j, 0.0f);
  }
  for (int i = 0; i < 20; ++i) grid.push_back(grid[100]);  // a duplicated sample
  auto keep = FindInlierPoints(grid, OutlierFilterOptions());
  ASSERT_TRUE(keep.ok());
  size_t kept = 0;
  for (uint8_t k : *keep) kept += k;
  EXPECT_EQ(kept, grid.size());
}

}  // namespace
}  // namespace reconar
