#include "tests/support/mesh_distance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tests/core/mesh/mesh_test_util.h"

namespace reconar::testing {
namespace {

// A flat grid of n x n quads on [0, size]^2 at height z, two triangles per quad.
Mesh Square(int n, float size, float z, const Eigen::Vector3f& offset = Eigen::Vector3f::Zero()) {
  return GridMesh(n, size, z, offset);
}

// A latitude-longitude sphere; the largest gap between it and the true sphere is about
// radius * (1 - cos(pi / segments)).
Mesh Sphere(float radius, int segments) {
  Mesh mesh;
  const double pi = std::acos(-1.0);
  mesh.positions.push_back(Eigen::Vector3f(0, 0, radius));
  for (int ring = 1; ring < segments; ++ring) {
    const double theta = pi * ring / segments;
    for (int k = 0; k < 2 * segments; ++k) {
      const double phi = pi * k / segments;
      mesh.positions.push_back(
          (radius * Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)))
              .cast<float>());
    }
  }
  mesh.positions.push_back(Eigen::Vector3f(0, 0, -radius));
  const uint32_t south = static_cast<uint32_t>(mesh.positions.size() - 1);
  const auto ring_vertex = [segments](int ring, int k) {
    return static_cast<uint32_t>(1 + (ring - 1) * 2 * segments + (k % (2 * segments)));
  };
  for (int k = 0; k < 2 * segments; ++k) {
    mesh.triangles.push_back({0, ring_vertex(1, k), ring_vertex(1, k + 1)});
    mesh.triangles.push_back({south, ring_vertex(segments - 1, k + 1), ring_vertex(segments - 1, k)});
    for (int ring = 1; ring + 1 < segments; ++ring) {
      mesh.triangles.push_back({ring_vertex(ring, k), ring_vertex(ring + 1, k), ring_vertex(ring + 1, k + 1)});
      mesh.triangles.push_back({ring_vertex(ring, k), ring_vertex(ring + 1, k + 1), ring_vertex(ring, k + 1)});
    }
  }
  return mesh;
}

MeshComparisonOptions Options(size_t samples, uint64_t seed) {
  MeshComparisonOptions options;
  options.samples = samples;
  options.seed = seed;
  options.num_threads = 2;
  return options;
}

Mesh Octahedron() {
  Mesh mesh;
  mesh.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  mesh.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return mesh;
}

TEST(MeshDistanceFieldTest, OneTriangleEveryVoronoiRegion) {
  Mesh triangle;
  triangle.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  triangle.triangles = {{0, 1, 2}};
  const MeshDistanceField field(triangle);
  EXPECT_DOUBLE_EQ(field.Distance({0.5f, 0.5f, 3.0f}), 3.0);                   // face, above
  EXPECT_DOUBLE_EQ(field.Distance({0.5f, 0.5f, -0.25f}), 0.25);                // face, below
  EXPECT_DOUBLE_EQ(field.Distance({-3.0f, -4.0f, 0.0f}), 5.0);                 // vertex a
  EXPECT_DOUBLE_EQ(field.Distance({5.0f, 0.0f, 4.0f}), 5.0);                   // vertex b
  EXPECT_DOUBLE_EQ(field.Distance({0.0f, 6.0f, 0.0f}), 4.0);                   // vertex c
  EXPECT_DOUBLE_EQ(field.Distance({1.0f, -3.0f, 4.0f}), 5.0);                  // edge ab
  EXPECT_DOUBLE_EQ(field.Distance({-0.5f, 1.0f, 0.0f}), 0.5);                  // edge ac
  EXPECT_NEAR(field.Distance({2.0f, 2.0f, 0.0f}), std::sqrt(2.0), 1e-7);       // edge bc
  const ClosestSurfacePoint closest = field.Closest({2.0f, 2.0f, 1.0f});
  EXPECT_NEAR((closest.point - Eigen::Vector3d(1, 1, 0)).norm(), 0.0, 1e-7);
  EXPECT_EQ(closest.primitive, 0u);
}

TEST(MeshDistanceFieldTest, OctahedronAnalyticDistances) {
  const MeshDistanceField field(Octahedron());
  EXPECT_NEAR(field.Distance({0, 0, 0}), 1.0 / std::sqrt(3.0), 1e-7);  // inradius
  EXPECT_NEAR(field.Distance({3, 0, 0}), 2.0, 1e-7);                   // beyond a vertex
  EXPECT_NEAR(field.Distance({1, 1, 1}), 2.0 / std::sqrt(3.0), 1e-7);  // over the face x+y+z=1
  EXPECT_NEAR(field.Distance({1, 1, 0}), std::sqrt(0.5), 1e-7);        // over the edge (1,0,0)-(0,1,0)
}

TEST(MeshDistanceFieldTest, DegenerateTrianglesAndPointClouds) {
  Mesh sliver;  // collinear corners: the distance is to the segment [0, 2] on x
  sliver.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  sliver.triangles = {{0, 1, 2}};
  EXPECT_NEAR(MeshDistanceField(sliver).Distance({1.5f, 3.0f, 4.0f}), 5.0, 1e-7);
  EXPECT_NEAR(MeshDistanceField(sliver).Distance({5.0f, 4.0f, 0.0f}), 5.0, 1e-7);

  Mesh cloud;
  cloud.positions = {{0, 0, 0}, {10, 0, 0}};
  const MeshDistanceField cloud_field(cloud);
  EXPECT_NEAR(cloud_field.Distance({7, 4, 0}), 5.0, 1e-7);
  EXPECT_EQ(cloud_field.Closest({7, 4, 0}).primitive, 1u);

  const MeshDistanceField empty{Mesh{}};
  EXPECT_TRUE(std::isinf(empty.Distance({0, 0, 0})));
}

TEST(MeshDistanceFieldTest, HierarchyMatchesBruteForceOnRandomTriangles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f);
  Mesh soup;
  for (uint32_t t = 0; t < 300; ++t) {
    const Eigen::Vector3f centre(coordinate(rng), coordinate(rng), coordinate(rng));
    for (int k = 0; k < 3; ++k) {
      soup.positions.push_back(centre + 0.1f * Eigen::Vector3f(coordinate(rng), coordinate(rng), coordinate(rng)));
    }
    soup.triangles.push_back({3 * t, 3 * t + 1, 3 * t + 2});
  }
  std::vector<MeshDistanceField> single_triangles;
  for (const auto& triangle : soup.triangles) {
    Mesh one;
    for (const uint32_t index : triangle) one.positions.push_back(soup.positions[index]);
    one.triangles = {{0, 1, 2}};
    single_triangles.emplace_back(one);
  }
  const MeshDistanceField field(soup);
  for (int q = 0; q < 500; ++q) {
    const Eigen::Vector3f query(2 * coordinate(rng), 2 * coordinate(rng), 2 * coordinate(rng));
    double brute_force = INFINITY;
    for (const MeshDistanceField& one : single_triangles) brute_force = std::min(brute_force, one.Distance(query));
    ASSERT_EQ(field.Distance(query), brute_force) << "query " << q;
  }
}

TEST(SampleSurfaceTest, AreaUniformDeterministicAndOnTheSurface) {
  Mesh mesh;  // two triangles in z=0, areas 0.5 (x<0) and 1.5 (x>0)
  mesh.positions = {{-1, 0, 0}, {0, 0, 0}, {0, 1, 0}, {3, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}, {1, 3, 4}};
  const std::vector<Eigen::Vector3f> samples = SampleSurface(mesh, 100000, 3);
  ASSERT_EQ(samples.size(), 100000u);
  EXPECT_EQ(samples, SampleSurface(mesh, 100000, 3));
  EXPECT_NE(samples, SampleSurface(mesh, 100000, 4));
  size_t left = 0;
  const MeshDistanceField field(mesh);
  double worst = 0.0;
  for (const Eigen::Vector3f& sample : samples) {
    left += sample.x() < 0.0f;
    worst = std::max(worst, field.Distance(sample));
  }
  EXPECT_LT(worst, 1e-6);
  // Binomial(100000, 0.25): standard deviation 137.
  EXPECT_NEAR(static_cast<double>(left), 25000.0, 700.0);
  EXPECT_TRUE(SampleSurface(Mesh{}, 10).empty());
}

TEST(CompareMeshesTest, SquareLiftedAlongItsNormal) {
  const MeshComparison comparison =
      CompareMeshes(Square(4, 1.0f, 0.1f), Square(4, 1.0f, 0.0f), Options(20000, 1));
  EXPECT_EQ(comparison.samples, 20000u);
  for (const double value : {comparison.mean_mesh_to_reference, comparison.mean_reference_to_mesh,
                             comparison.median_mesh_to_reference, comparison.median_reference_to_mesh,
                             comparison.rms_mesh_to_reference, comparison.rms_reference_to_mesh,
                             comparison.max_mesh_to_reference, comparison.max_reference_to_mesh}) {
    EXPECT_NEAR(value, 0.1, 1e-6);
  }
}

TEST(CompareMeshesTest, SquareShiftedInItsPlane) {
  // Half of each square overlaps the other (distance 0); over the other half the distance grows
  // linearly from 0 to 0.5: mean 0.125, median 0, rms sqrt(0.5 * 0.25 / 3), 90th percentile 0.4.
  const MeshComparison comparison = CompareMeshes(Square(8, 1.0f, 0.0f, {0.5f, 0.0f, 0.0f}), Square(8, 1.0f, 0.0f),
                                                  Options(50000, 5));
  // 50000 samples: the standard error of the mean is 0.17 / sqrt(50000) = 8e-4.
  EXPECT_NEAR(comparison.mean_mesh_to_reference, 0.125, 3e-3);
  EXPECT_NEAR(comparison.mean_reference_to_mesh, 0.125, 3e-3);
  EXPECT_NEAR(comparison.median_mesh_to_reference, 0.0, 1e-6);
  EXPECT_NEAR(comparison.rms_mesh_to_reference, std::sqrt(0.5 * 0.25 / 3.0), 3e-3);
  EXPECT_NEAR(comparison.p90_reference_to_mesh, 0.4, 5e-3);
  EXPECT_NEAR(comparison.max_mesh_to_reference, 0.5, 1e-3);
}

TEST(CompareMeshesTest, ConcentricSpheres) {
  // Radii 1 and 1.02; each tessellation lies within 1 - cos(pi / 120) = 3.4e-4 of its sphere.
  const MeshComparison comparison =
      CompareMeshes(Sphere(1.02f, 120), Sphere(1.0f, 120), Options(20000, 2));
  EXPECT_NEAR(comparison.mean_mesh_to_reference, 0.02, 4e-4);
  EXPECT_NEAR(comparison.mean_reference_to_mesh, 0.02, 4e-4);
  EXPECT_NEAR(comparison.max_reference_to_mesh, 0.02, 8e-4);
}

TEST(CompareMeshesTest, NoSurfaceGivesNaN) {
  const MeshComparison comparison = CompareMeshes(Mesh{}, Square(1, 1.0f, 0.0f), Options(10, 1));
  EXPECT_EQ(comparison.samples, 0u);
  EXPECT_TRUE(std::isnan(comparison.mean_mesh_to_reference));
}

TEST(ScoreMiddleburyTest, AccuracyQuantileAndCompletenessShare) {
  const Mesh reference = Square(10, 0.1f, 0.0f);  // 121 vertices 1 cm apart
  std::vector<Eigen::Vector3f> points;
  // Accuracy: 90 points 1 mm above the surface, 10 outliers 50 mm above: the 90 % distance is 1 mm.
  for (int i = 0; i < 90; ++i) points.push_back({0.055f, 0.055f, 0.001f});
  for (int i = 0; i < 10; ++i) points.push_back({0.055f, 0.055f, 0.05f});
  // Completeness: a point 1 mm above every reference vertex with x < 0.045 (5 of 11 columns);
  // 1.5 mm above those with x in (0.045, 0.075) (3 columns, out of the 1.25 mm reach).
  size_t expected_covered = 0;
  for (const Eigen::Vector3f& vertex : reference.positions) {
    if (vertex.x() < 0.045f) {
      points.push_back(vertex + Eigen::Vector3f(0, 0, 0.001f));
      ++expected_covered;
    } else if (vertex.x() < 0.075f) {
      points.push_back(vertex + Eigen::Vector3f(0, 0, 0.0015f));
    }
  }
  // Their distances to the surface (1 and 1.5 mm) keep the accuracy within [1, 1.5] mm.
  const MiddleburyScores scores = ScoreMiddlebury(points, reference);
  EXPECT_EQ(scores.points, points.size());
  EXPECT_EQ(scores.reference_samples, 121u);
  EXPECT_EQ(expected_covered, 55u);
  EXPECT_DOUBLE_EQ(scores.completeness, 55.0 / 121.0);
  // 90 + 55 points at 1 mm, 33 at 1.5 mm, 10 at 50 mm: the 90 % quantile (rank 170 of 188) is 1.5 mm.
  EXPECT_NEAR(scores.accuracy, 0.0015, 1e-7);

  const std::vector<Eigen::Vector3f> first_hundred(points.begin(), points.begin() + 100);
  EXPECT_NEAR(ScoreMiddlebury(first_hundred, reference).accuracy, 0.001, 1e-7);
  EXPECT_NEAR(ScoreMiddlebury(first_hundred, reference, 0.95).accuracy, 0.05, 1e-7);

  const MiddleburyScores none = ScoreMiddlebury({}, reference);
  EXPECT_TRUE(std::isinf(none.accuracy));
  EXPECT_EQ(none.completeness, 0.0);
}

}  // namespace
}  // namespace reconar::testing
