// Screened Poisson reconstruction of analytic surfaces: distance of the output to the true
// surface, watertightness, orientation, volume, and the input errors.
#include "core/mesh/poisson/poisson.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/core/mesh/poisson/poisson_test_util.h"

namespace reconar {
namespace {

using testing::CountBadEdges;
using testing::SignedVolume;

// Mean of distance(vertex) over the mesh Poisson makes of `points` with first-order elements: the
// baseline the default second-order ones must beat.
template <typename Distance>
double FirstOrderMeanDistance(const Mesh& points, PoissonOptions options, Distance distance) {
  options.degree = 1;
  Result<Mesh> mesh = ReconstructPoissonSurface(points, options);
  EXPECT_TRUE(mesh.ok()) << mesh.status().ToString();
  if (!mesh.ok() || mesh->positions.empty()) return 0.0;
  double mean = 0.0;
  for (const Eigen::Vector3f& p : mesh->positions) mean += distance(p);
  return mean / static_cast<double>(mesh->positions.size());
}

TEST(PoissonTest, SphereIsClosedOrientedAndOnTheSurface) {
  const Eigen::Vector3f centre(0.3f, -0.2f, 1.0f);
  const float radius = 0.5f;
  const Mesh points = testing::SphereSamples(centre, radius, 20000);
  PoissonOptions options;
  options.depth = 6;
  PoissonReport report;
  Result<Mesh> mesh = ReconstructPoissonSurface(points, options, &report);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  ASSERT_GT(mesh->triangles.size(), 1000u);
  EXPECT_EQ(report.cells_skipped, 0u);
  EXPECT_EQ(CountBadEdges(*mesh), 0u);
  // Cell size at depth 6: 1.1 / 64 = 0.017.
  auto distance = [&](const Eigen::Vector3f& p) { return std::abs((p - centre).norm() - radius); };
  double mean = 0.0, worst = 0.0;
  for (const Eigen::Vector3f& p : mesh->positions) {
    const double d = distance(p);
    mean += d;
    worst = std::max(worst, d);
  }
  mean /= static_cast<double>(mesh->positions.size());
  EXPECT_LT(mean, 0.002);
  EXPECT_LT(worst, 0.01);
  // Second-order B-splines (the default) against first-order ones: ~0.54x here.
  const double first_order = FirstOrderMeanDistance(points, options, distance);
  std::printf("sphere depth 6: mean distance %.6f (degree 2), %.6f (degree 1)\n", mean, first_order);
  EXPECT_LT(mean, 0.75 * first_order);
  const double volume = 4.0 / 3.0 * M_PI * radius * radius * radius;
  EXPECT_NEAR(SignedVolume(*mesh), volume, 0.02 * volume);
  ASSERT_EQ(mesh->normals.size(), mesh->positions.size());
}

TEST(PoissonTest, TorusIsClosedAndOnTheSurface) {
  const float ring = 1.0f, tube = 0.35f;
  const Mesh points = testing::TorusSamples(ring, tube, 40000);
  PoissonOptions options;
  options.depth = 7;
  PoissonReport report;
  Result<Mesh> mesh = ReconstructPoissonSurface(points, options, &report);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(report.cells_skipped, 0u);
  EXPECT_EQ(CountBadEdges(*mesh), 0u);
  double mean = 0.0;
  for (const Eigen::Vector3f& p : mesh->positions) {
    const float q = std::hypot(p.x(), p.y()) - ring;
    mean += std::abs(std::hypot(q, p.z()) - tube);
  }
  mean /= static_cast<double>(mesh->positions.size());
  // Cell: 2.77 / 128 = 0.022. Measured 0.000147 (degree 1: 0.000283, not rerun here to keep the
  // test fast under qemu; the sphere test compares the degrees).
  EXPECT_LT(mean, 0.004);
  const double volume = 2.0 * M_PI * M_PI * ring * tube * tube;
  EXPECT_NEAR(SignedVolume(*mesh), volume, 0.02 * volume);
}

TEST(PoissonTest, TrimDropsTheSurfaceBridgingAHole) {
  // A hemisphere's samples only: Poisson closes the open side, the density trim removes it.
  Mesh all = testing::SphereSamples(Eigen::Vector3f::Zero(), 1.0f, 20000);
  Mesh half;
  for (size_t i = 0; i < all.positions.size(); ++i) {
    if (all.positions[i].z() > 0.0f) {
      half.positions.push_back(all.positions[i]);
      half.normals.push_back(all.normals[i]);
    }
  }
  PoissonOptions options;
  options.depth = 6;
  Result<Mesh> closed = ReconstructPoissonSurface(half, options);
  ASSERT_TRUE(closed.ok());
  options.trim = options.depth - 1;
  Result<Mesh> trimmed = ReconstructPoissonSurface(half, options);
  ASSERT_TRUE(trimmed.ok());
  ASSERT_GT(trimmed->triangles.size(), 100u);
  float lowest_closed = 1.0f, lowest_trimmed = 1.0f;
  for (const Eigen::Vector3f& p : closed->positions) lowest_closed = std::min(lowest_closed, p.z());
  for (const Eigen::Vector3f& p : trimmed->positions) lowest_trimmed = std::min(lowest_trimmed, p.z());
  EXPECT_LT(lowest_closed, -0.2f);   // the bridge bulges below the samples
  EXPECT_GT(lowest_trimmed, -0.15f);  // and is gone after trimming (up to a kernel cell, 0.14)
}

TEST(PoissonTest, ColoursAreInterpolatedFromTheSamples) {
  Mesh points = testing::SphereSamples(Eigen::Vector3f::Zero(), 1.0f, 10000);
  for (const Eigen::Vector3f& p : points.positions) {
    points.colors.push_back({static_cast<uint8_t>(p.x() > 0 ? 250 : 10), 128, 0, 255});
  }
  PoissonOptions options;
  options.depth = 5;
  Result<Mesh> mesh = ReconstructPoissonSurface(points, options);
  ASSERT_TRUE(mesh.ok());
  ASSERT_EQ(mesh->colors.size(), mesh->positions.size());
  for (size_t i = 0; i < mesh->positions.size(); ++i) {
    const float x = mesh->positions[i].x();
    if (x > 0.2f) {
      EXPECT_GT(mesh->colors[i][0], 200);
    }
    if (x < -0.2f) {
      EXPECT_LT(mesh->colors[i][0], 60);
    }
    EXPECT_NEAR(mesh->colors[i][1], 128, 2);
  }
}

TEST(PoissonTest, ThreadCountDoesNotChangeTheResult) {
  // Depth 6 has band levels (depth > 5) as well as the complete coarsest grid.
  const Mesh points = testing::TorusSamples(0.6f, 0.25f, 4000);
  PoissonOptions options;
  options.depth = 6;
  Result<Mesh> one = ReconstructPoissonSurface(points, options);
  options.num_threads = 2;
  Result<Mesh> two = ReconstructPoissonSurface(points, options);
  ASSERT_TRUE(one.ok() && two.ok());
  ASSERT_GT(one->triangles.size(), 1000u);
  ASSERT_EQ(one->positions.size(), two->positions.size());
  ASSERT_EQ(one->triangles, two->triangles);
  for (size_t i = 0; i < one->positions.size(); ++i) ASSERT_EQ(one->positions[i], two->positions[i]) << i;
}

TEST(PoissonTest, ShallowDepthsGiveClosedSurfacesWithEitherDegree) {
  // Depths below the band levels: the complete grids are small enough for the boundary rows of
  // every stencil to matter. The cube is 1.5 x the sphere's diameter: with the default 1.1 the
  // blurrier shallow solutions reach the cube's faces, where the surface is cut open.
  const Mesh points = testing::SphereSamples(Eigen::Vector3f::Zero(), 1.0f, 2000);
  for (int degree = 1; degree <= 2; ++degree) {
    for (int depth = 2; depth <= 4; ++depth) {
      PoissonOptions options;
      options.depth = depth;
      options.degree = degree;
      options.scale = 1.5;
      Result<Mesh> mesh = ReconstructPoissonSurface(points, options);
      ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
      double worst = 0.0;
      for (const Eigen::Vector3f& p : mesh->positions) worst = std::max(worst, std::abs(p.norm() - 1.0));
      std::printf("degree %d depth %d: %zu triangles, worst distance %.3f cells\n", degree, depth,
                  mesh->triangles.size(), worst / (3.0 / (1 << depth)));
      EXPECT_GT(mesh->triangles.size(), 8u) << "degree " << degree << " depth " << depth;
      EXPECT_EQ(CountBadEdges(*mesh), 0u) << "degree " << degree << " depth " << depth;
      const double cell = 3.0 / (1 << depth);
      for (const Eigen::Vector3f& p : mesh->positions) {
        EXPECT_NEAR(p.norm(), 1.0, 0.5 * cell) << "degree " << degree << " depth " << depth;
      }
    }
  }
}

TEST(PoissonTest, RejectsBadInput) {
  Mesh points = testing::SphereSamples(Eigen::Vector3f::Zero(), 1.0f, 100);
  Mesh no_normals = points;
  no_normals.normals.clear();
  Result<Mesh> r = ReconstructPoissonSurface(no_normals, PoissonOptions());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("normal"), std::string::npos);

  Mesh two;
  two.positions = {Eigen::Vector3f::Zero(), Eigen::Vector3f::Ones()};
  two.normals = {Eigen::Vector3f::UnitZ(), Eigen::Vector3f::UnitZ()};
  r = ReconstructPoissonSurface(two, PoissonOptions());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("at least 3"), std::string::npos);

  Mesh nan = points;
  nan.positions[5].x() = std::nanf("");
  r = ReconstructPoissonSurface(nan, PoissonOptions());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("non-finite"), std::string::npos);

  PoissonOptions bad;
  bad.depth = 40;
  r = ReconstructPoissonSurface(points, bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("depth"), std::string::npos);

  bad = PoissonOptions();
  bad.degree = 3;
  r = ReconstructPoissonSurface(points, bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("degree"), std::string::npos);
}

}  // namespace
}  // namespace reconar
