// SurfaceTrimmer-style trimming on a flat grid whose vertex values are known everywhere.
#include "core/mesh/poisson/surface_trim.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace reconar {
namespace {

// Unit square in the z = 0 plane, (n+1)^2 vertices, two triangles per cell.
Mesh Grid(int n) {
  Mesh mesh;
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= n; ++x) mesh.positions.emplace_back(static_cast<float>(x) / n, static_cast<float>(y) / n, 0.0f);
  }
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const uint32_t a = static_cast<uint32_t>(y * (n + 1) + x), b = a + 1, c = a + n + 1, d = c + 1;
      mesh.triangles.push_back({a, b, d});
      mesh.triangles.push_back({a, d, c});
    }
  }
  return mesh;
}

double Area(const Mesh& mesh) {
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    area += 0.5 * (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]).norm();
  }
  return area;
}

bool HasVertexNear(const Mesh& mesh, const Eigen::Vector3f& p, float radius) {
  for (const Eigen::Vector3f& q : mesh.positions) {
    if ((q - p).norm() < radius) return true;
  }
  return false;
}

TEST(SurfaceTrimTest, CutsAlongTheTrimLineFillsSmallHolesAndDropsSmallIslands) {
  Mesh mesh = Grid(100);
  const Eigen::Vector3f small_hole(0.8f, 0.5f, 0.0f), large_hole(0.75f, 0.25f, 0.0f), island(0.2f, 0.5f, 0.0f);
  std::vector<float> values;
  for (const Eigen::Vector3f& p : mesh.positions) {
    float v = p.x();                                  // the trim line x = 0.5 halves the square
    if ((p - small_hole).norm() < 0.0125f) v = 0.0f;  // ~5e-4 of the area: below --aRatio, kept
    if ((p - large_hole).norm() < 0.08f) v = 0.0f;    // ~2e-2 of the area: cut out
    if ((p - island).norm() < 0.0125f) v = 1.0f;      // a small island in the removed half: dropped
    values.push_back(v);
  }
  poisson::SurfaceTrimOptions options;
  options.trim = 0.5f;
  poisson::TrimSurface(values, options, &mesh);
  for (const Eigen::Vector3f& p : mesh.positions) EXPECT_GE(p.x(), 0.5f - 1e-6f);
  EXPECT_TRUE(HasVertexNear(mesh, small_hole, 1e-4f));
  EXPECT_FALSE(HasVertexNear(mesh, large_hole, 0.06f));
  EXPECT_FALSE(HasVertexNear(mesh, island, 0.05f));
  // Half the square minus the large hole (a disc cut at values interpolated along the edges).
  const double expected = 0.5 - M_PI * 0.08 * 0.08;
  EXPECT_NEAR(Area(mesh), expected, 0.004);
  EXPECT_TRUE(mesh.normals.empty());
}

}  // namespace
}  // namespace reconar
