// Normal estimation (PCA + MST orientation) on analytic surfaces whose true normals are known.
#include "core/mesh/poisson/point_normals.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "core/mesh/poisson/point_kdtree.h"
#include "tests/core/mesh/poisson/poisson_test_util.h"

namespace reconar {
namespace {

// Largest angle (degrees) between estimated and true normals, and the number pointing against them.
struct NormalErrors {
  double mean_degrees = 0.0;
  double worst_degrees = 0.0;
  int flipped = 0;
};

NormalErrors Compare(const Mesh& estimated, const Mesh& truth) {
  NormalErrors errors;
  for (size_t i = 0; i < truth.normals.size(); ++i) {
    const double cosine = std::min(1.0f, std::abs(estimated.normals[i].dot(truth.normals[i])));
    const double degrees = std::acos(cosine) * 180.0 / M_PI;
    errors.mean_degrees += degrees / static_cast<double>(truth.normals.size());
    errors.worst_degrees = std::max(errors.worst_degrees, degrees);
    if (estimated.normals[i].dot(truth.normals[i]) < 0.0f) ++errors.flipped;
    EXPECT_NEAR(estimated.normals[i].norm(), 1.0f, 1e-5f);
  }
  std::printf("normals: mean %.2f, worst %.2f degrees, %d flipped\n", errors.mean_degrees, errors.worst_degrees,
              errors.flipped);
  return errors;
}

TEST(PointNormalsTest, SphereNormalsAreRadialAndOutward) {
  const Mesh truth = testing::SphereSamples(Eigen::Vector3f(0.3f, -0.2f, 1.0f), 0.5f, 4000);
  Mesh points;
  points.positions = truth.positions;
  ASSERT_TRUE(EstimateNormals(&points, NormalEstimationOptions()).ok());
  ASSERT_EQ(points.normals.size(), truth.normals.size());
  const NormalErrors errors = Compare(points, truth);
  // The 10 nearest of 4000 random points on the sphere lie within ~0.1 rad (6 degrees) of the
  // centre point; PCA tilts towards a lopsided neighbourhood by at most about that.
  EXPECT_LT(errors.mean_degrees, 1.5);
  EXPECT_LT(errors.worst_degrees, 6.0);
  EXPECT_EQ(errors.flipped, 0);
}

TEST(PointNormalsTest, TorusAndSeparateComponentsAreOrientedOutward) {
  // A torus (genus 1, saddle regions) and, far away, a second sphere: two graph components, each
  // seeded at its own highest point.
  Mesh truth = testing::TorusSamples(1.0f, 0.35f, 6000);
  const Mesh sphere = testing::SphereSamples(Eigen::Vector3f(5.0f, 0.0f, -3.0f), 0.4f, 2000);
  truth.positions.insert(truth.positions.end(), sphere.positions.begin(), sphere.positions.end());
  truth.normals.insert(truth.normals.end(), sphere.normals.begin(), sphere.normals.end());
  Mesh points;
  points.positions = truth.positions;
  NormalEstimationOptions options;
  options.neighbors = 12;
  ASSERT_TRUE(EstimateNormals(&points, options).ok());
  const NormalErrors errors = Compare(points, truth);
  // 12 neighbours among 6000 torus points reach ~0.09 from the centre point, 15 degrees of the
  // tube's curvature (radius 0.35): the tilt bound as for the sphere.
  EXPECT_LT(errors.mean_degrees, 3.0);
  EXPECT_LT(errors.worst_degrees, 15.0);
  EXPECT_EQ(errors.flipped, 0);
}

TEST(PointNormalsTest, KdTreeFindsTheExactNearestNeighbours) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f);
  std::vector<Eigen::Vector3f> points(3000);
  for (auto& p : points) p = Eigen::Vector3f(coordinate(rng), coordinate(rng), 0.1f * coordinate(rng));
  for (int i = 0; i < 200; ++i) points.push_back(points[static_cast<size_t>(i)]);  // duplicates
  const poisson::PointKdTree tree(points);
  std::vector<std::pair<float, uint32_t>> found;
  for (int q = 0; q < 50; ++q) {
    const Eigen::Vector3f query(coordinate(rng), coordinate(rng), coordinate(rng));
    tree.Nearest(query, 7, &found);
    std::vector<std::pair<float, uint32_t>> brute;
    for (uint32_t i = 0; i < points.size(); ++i) brute.emplace_back((points[i] - query).squaredNorm(), i);
    std::sort(brute.begin(), brute.end());
    brute.resize(7);
    EXPECT_EQ(found, brute);
  }
  tree.Nearest(points[0], 10000, &found);
  EXPECT_EQ(found.size(), points.size());
}

TEST(PointNormalsTest, RejectsBadInput) {
  Mesh points;
  points.positions = {Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitX()};
  EXPECT_EQ(EstimateNormals(&points, NormalEstimationOptions()).code(), StatusCode::kInvalidArgument);
  points.positions.push_back(Eigen::Vector3f(0.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f));
  EXPECT_EQ(EstimateNormals(&points, NormalEstimationOptions()).code(), StatusCode::kInvalidArgument);
  points.positions.back() = Eigen::Vector3f::UnitY();
  NormalEstimationOptions options;
  options.neighbors = 2;
  EXPECT_EQ(EstimateNormals(&points, options).code(), StatusCode::kInvalidArgument);
  // Three points: one plane, normal +z; coincident points get their tree parent's normal.
  points.positions.push_back(Eigen::Vector3f::UnitY());
  ASSERT_TRUE(EstimateNormals(&points, NormalEstimationOptions()).ok());
  for (const Eigen::Vector3f& normal : points.normals) EXPECT_NEAR(normal.z(), 1.0f, 1e-6f);
}

}  // namespace
}  // namespace reconar
