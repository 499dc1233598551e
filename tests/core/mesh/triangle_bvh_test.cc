// TriangleBvh against testing every triangle, on a random soup and on a closed mesh.
#include "core/mesh/triangle_bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace reconar {
namespace {

// The nearest hit by testing every triangle (Moller-Trumbore), t in (0, inf).
RayHit BruteForce(const Mesh& mesh, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  RayHit best;
  best.distance = INFINITY;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    if (std::max({mesh.triangles[i][0], mesh.triangles[i][1], mesh.triangles[i][2]}) >= mesh.positions.size()) continue;
    const Eigen::Vector3d a = mesh.positions[mesh.triangles[i][0]].cast<double>();
    const Eigen::Vector3d e1 = mesh.positions[mesh.triangles[i][1]].cast<double>() - a;
    const Eigen::Vector3d e2 = mesh.positions[mesh.triangles[i][2]].cast<double>() - a;
    const Eigen::Matrix3d system = (Eigen::Matrix3d() << -direction, e1, e2).finished();
    const Eigen::Vector3d tuv = system.colPivHouseholderQr().solve(origin - a);
    if (tuv(1) < 0 || tuv(2) < 0 || tuv(1) + tuv(2) > 1 || tuv(0) <= 0 || tuv(0) >= best.distance) continue;
    best.triangle = static_cast<int>(i);
    best.distance = tuv(0);
  }
  return best;
}

TEST(TriangleBvhTest, FindsTheNearestTriangleAsTestingEveryOneDoes) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f);
  Mesh mesh;
  for (int t = 0; t < 2000; ++t) {
    const Eigen::Vector3f centre(coordinate(random), coordinate(random), coordinate(random));
    for (int k = 0; k < 3; ++k) {
      mesh.positions.push_back(centre + 0.1f * Eigen::Vector3f(coordinate(random), coordinate(random), coordinate(random)));
    }
    mesh.triangles.push_back({uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)});
  }
  mesh.triangles.push_back({0, 1, 999999});  // out of range: left out, not a crash
  const TriangleBvh bvh(mesh);
  EXPECT_EQ(bvh.num_triangles(), 2000);
  int hits = 0;
  for (int r = 0; r < 500; ++r) {
    const Eigen::Vector3d origin = 3.0 * Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d target = 0.5 * Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d direction = target - origin;
    const RayHit expected = BruteForce(mesh, origin, direction);
    const RayHit hit = bvh.Intersect(origin, direction);
    ASSERT_EQ(hit.triangle, expected.triangle) << "ray " << r;
    if (hit.triangle < 0) continue;
    ++hits;
    EXPECT_NEAR(hit.distance, expected.distance, 1e-9);
    EXPECT_LT((hit.point - (origin + expected.distance * direction)).norm(), 1e-9);
    // Limited short of the hit, the ray meets nothing: it was the nearest.
    EXPECT_EQ(bvh.Intersect(origin, direction, 0.0, 0.999 * hit.distance).triangle, -1);
  }
  EXPECT_GT(hits, 100);
}

TEST(TriangleBvhTest, AnEmptyMeshMeetsNothing) {
  const TriangleBvh bvh{Mesh()};
  EXPECT_EQ(bvh.Intersect(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()).triangle, -1);
  EXPECT_EQ(bvh.Nearest(Eigen::Vector3d::Zero()).triangle, -1);
}

// The distance from p to triangle abc the long way: to its plane when the foot falls inside (by
// the signs of the three edge normals), else to the nearest of its edges as segments.
double DistanceToTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c) {
  const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
  const Eigen::Vector3d foot = p - (p - a).dot(normal) * normal;
  const bool inside = ((b - a).cross(foot - a)).dot(normal) >= 0 && ((c - b).cross(foot - b)).dot(normal) >= 0 &&
                      ((a - c).cross(foot - c)).dot(normal) >= 0;
  if (inside) return (p - foot).norm();
  const auto segment = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    const double t = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
    return (p - (u + t * (v - u))).norm();
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

TEST(TriangleBvhTest, FindsTheNearestSurfacePointAsTestingEveryTriangleDoes) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  Mesh mesh;
  for (int t = 0; t < 1500; ++t) {
    const Eigen::Vector3d centre(coordinate(random), coordinate(random), coordinate(random));
    for (int k = 0; k < 3; ++k) {
      mesh.positions.push_back(
          (centre + 0.1 * Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random))).cast<float>());
    }
    mesh.triangles.push_back({uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)});
  }
  const TriangleBvh bvh(mesh);
  for (int q = 0; q < 400; ++q) {
    const Eigen::Vector3d query = 1.5 * Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random));
    double expected = INFINITY;
    for (const auto& t : mesh.triangles) {
      expected = std::min(expected, DistanceToTriangle(query, mesh.positions[t[0]].cast<double>(),
                                                       mesh.positions[t[1]].cast<double>(),
                                                       mesh.positions[t[2]].cast<double>()));
    }
    const NearestSurfacePoint nearest = bvh.Nearest(query);
    ASSERT_GE(nearest.triangle, 0);
    EXPECT_NEAR(nearest.distance, expected, 1e-9) << "query " << q;
    EXPECT_NEAR((nearest.point - query).norm(), nearest.distance, 1e-12);
    // Bounded below the distance, nothing is found.
    EXPECT_EQ(bvh.Nearest(query, 0.999 * expected).triangle, -1);
    // A hint changes nothing but the work: any triangle, one out of range, the answer itself.
    for (const int hint : {static_cast<int>(q) % 1500, -7, 1500, 1 << 30, nearest.triangle}) {
      const NearestSurfacePoint hinted = bvh.Nearest(query, 1e300, hint);
      EXPECT_NEAR(hinted.distance, expected, 1e-9) << "query " << q << " hint " << hint;
      EXPECT_EQ(bvh.Nearest(query, 0.999 * expected, hint).triangle, -1) << "query " << q << " hint " << hint;
    }
  }
}

// The batch gives each query the distance Nearest gives it, for queries clustered (the groups
// share their candidates), scattered (they search one by one) and bounded.
TEST(TriangleBvhTest, NearestBatchAgreesWithNearest) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  Mesh mesh;
  for (int t = 0; t < 3000; ++t) {
    const Eigen::Vector3d centre(coordinate(random), coordinate(random), 0.2 * coordinate(random));
    for (int k = 0; k < 3; ++k) {
      mesh.positions.push_back(
          (centre + 0.05 * Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random))).cast<float>());
    }
    mesh.triangles.push_back({uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)});
  }
  const TriangleBvh bvh(mesh);
  std::vector<Eigen::Vector3d> queries;
  for (int cluster = 0; cluster < 40; ++cluster) {
    const Eigen::Vector3d centre(coordinate(random), coordinate(random), 0.3 * coordinate(random));
    for (int k = 0; k < 20; ++k) queries.push_back(centre + 0.01 * Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random)));
  }
  for (int k = 0; k < 300; ++k) queries.push_back(1.5 * Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random)));
  std::vector<int> candidates;
  for (const double bound : {1e300, 0.05}) {
    std::vector<NearestSurfacePoint> batch(queries.size());
    bvh.NearestBatch(queries.data(), queries.size(), bound, batch.data(), &candidates);
    for (size_t q = 0; q < queries.size(); ++q) {
      const NearestSurfacePoint alone = bvh.Nearest(queries[q], bound);
      ASSERT_EQ(batch[q].triangle >= 0, alone.triangle >= 0) << "query " << q << " bound " << bound;
      if (alone.triangle >= 0) EXPECT_EQ(batch[q].distance, alone.distance) << "query " << q << " bound " << bound;
    }
  }
}

TEST(TriangleBvhTest, NearestSkipsUnusableTrianglesEvenAsHints) {
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {NAN, 0, 0}, {0, 0, 5}, {1, 0, 5}, {0, 1, 5}};
  mesh.triangles = {{0, 1, 2}, {3, 1, 2}, {0, 1, 99}, {4, 5, 6}};
  const TriangleBvh bvh(mesh);
  EXPECT_EQ(bvh.num_triangles(), 2);
  for (const int hint : {-1, 0, 1, 2, 3, 4}) {
    const NearestSurfacePoint nearest = bvh.Nearest({0.2, 0.2, 4.0}, 1e300, hint);
    EXPECT_EQ(nearest.triangle, 3) << "hint " << hint;
    EXPECT_NEAR(nearest.distance, 1.0, 1e-12) << "hint " << hint;
  }
}

}  // namespace
}  // namespace reconar
