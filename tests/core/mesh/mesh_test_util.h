#pragma once
// Test helpers for core/mesh: a seeded random mesh and an exact comparison.
#include <gtest/gtest.h>

#include <random>

#include "core/mesh/mesh.h"

namespace reconar::testing {

// `num_vertices` random positions (and unit normals / colours when asked) and `num_triangles`
// random triangles over them; deterministic for a seed.
inline Mesh RandomMesh(int num_vertices, int num_triangles, bool with_normals, bool with_colors, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coordinate(-2.0f, 2.0f);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<uint32_t> vertex(0, static_cast<uint32_t>(num_vertices - 1));
  Mesh mesh;
  for (int i = 0; i < num_vertices; ++i) {
    mesh.positions.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
    if (with_normals) {
      Eigen::Vector3f n(coordinate(rng), coordinate(rng), coordinate(rng) + 3.0f);
      mesh.normals.push_back(n.normalized());
    }
    if (with_colors) {
      mesh.colors.push_back({static_cast<uint8_t>(byte(rng)), static_cast<uint8_t>(byte(rng)),
                             static_cast<uint8_t>(byte(rng)), static_cast<uint8_t>(byte(rng))});
    }
  }
  for (int t = 0; t < num_triangles; ++t) mesh.triangles.push_back({vertex(rng), vertex(rng), vertex(rng)});
  return mesh;
}

// An n x n grid of square cells `size` wide in the plane z (moved by `offset`), each cell two
// triangles counter-clockwise seen from +z; vertex (i, j) has index j (n + 1) + i.
inline Mesh GridMesh(int n, float size, float z, const Eigen::Vector3f& offset = Eigen::Vector3f::Zero()) {
  Mesh mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) mesh.positions.push_back(Eigen::Vector3f(size * i / n, size * j / n, z) + offset);
  }
  const auto index = [n](int i, int j) { return static_cast<uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      mesh.triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      mesh.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  }
  return mesh;
}

inline void ExpectMeshesEqual(const Mesh& actual, const Mesh& expected) {
  ASSERT_EQ(actual.positions.size(), expected.positions.size());
  for (size_t i = 0; i < expected.positions.size(); ++i) {
    // Bitwise, so -0.0f and +0.0f differ.
    ASSERT_EQ(std::memcmp(actual.positions[i].data(), expected.positions[i].data(), 12), 0)
        << "vertex " << i << ": " << actual.positions[i].transpose() << " vs " << expected.positions[i].transpose();
  }
  ASSERT_EQ(actual.normals.size(), expected.normals.size());
  for (size_t i = 0; i < expected.normals.size(); ++i) {
    ASSERT_EQ(actual.normals[i], expected.normals[i]) << "normal " << i;
  }
  EXPECT_EQ(actual.colors, expected.colors);
  EXPECT_EQ(actual.triangles, expected.triangles);
}

}  // namespace reconar::testing
