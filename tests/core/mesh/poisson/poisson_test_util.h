#pragma once
// Helpers for the Poisson tests: analytic oriented samples and mesh topology checks.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <utility>

#include "core/mesh/mesh.h"

namespace reconar::testing {

// `count` points uniformly distributed on a sphere, outward normals. Seeded.
inline Mesh SphereSamples(const Eigen::Vector3f& centre, float radius, int count, uint32_t seed = 7) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  Mesh points;
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3f d(gauss(rng), gauss(rng), gauss(rng));
    d.normalize();
    points.positions.push_back(centre + radius * d);
    points.normals.push_back(d);
  }
  return points;
}

// Torus around the z axis (ring radius R, tube radius r), area-uniform samples, outward normals.
inline Mesh TorusSamples(float ring_radius, float tube_radius, int count, uint32_t seed = 11) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> angle(0.0f, 2.0f * static_cast<float>(M_PI));
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  Mesh points;
  while (static_cast<int>(points.positions.size()) < count) {
    const float u = angle(rng), v = angle(rng);
    // Area element is proportional to (R + r cos v): rejection sampling.
    if (unit(rng) * (ring_radius + tube_radius) > ring_radius + tube_radius * std::cos(v)) continue;
    const Eigen::Vector3f ring(std::cos(u), std::sin(u), 0.0f);
    const Eigen::Vector3f normal = std::cos(v) * ring + std::sin(v) * Eigen::Vector3f::UnitZ();
    points.positions.push_back(ring_radius * ring + tube_radius * normal);
    points.normals.push_back(normal);
  }
  return points;
}

// Number of undirected edges not shared by exactly two triangles, plus directed edges used twice
// (inconsistent orientation).
inline size_t CountBadEdges(const Mesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  size_t bad = 0;
  for (const auto& [edge, count] : directed) {
    if (count != 1) ++bad;
    const auto reverse = directed.find({edge.second, edge.first});
    if (reverse == directed.end() || reverse->second != 1) ++bad;
  }
  return bad;
}

// Signed volume (divergence theorem); positive for a closed mesh oriented outwards.
inline double SignedVolume(const Mesh& mesh) {
  double volume = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                          c = mesh.positions[t[2]].cast<double>();
    volume += a.dot(b.cross(c)) / 6.0;
  }
  return volume;
}

}  // namespace reconar::testing
