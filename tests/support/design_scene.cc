#include "tests/support/design_scene.h"

#include <Eigen/Geometry>

namespace reconar::testing {

Mesh BoxMesh(const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  Mesh mesh;
  for (int k = 0; k < 8; ++k) {
    mesh.positions.emplace_back(static_cast<float>(k & 1 ? max.x() : min.x()), static_cast<float>(k & 2 ? max.y() : min.y()),
                                static_cast<float>(k & 4 ? max.z() : min.z()));
  }
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  }
  return mesh;
}

Mesh MovedMesh(const Mesh& mesh, const Rigid3& motion) {
  Mesh moved = mesh;
  for (Eigen::Vector3f& p : moved.positions) p = (motion * p.cast<double>()).cast<float>();
  return moved;
}

void SampleMeshFaces(const Mesh& mesh, double spacing, double noise, std::mt19937* random,
                     std::vector<Eigen::Vector3d>* points, std::vector<Eigen::Vector3d>* normals) {
  std::normal_distribution<double> offset(0.0, noise);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                          c = mesh.positions[t[2]].cast<double>();
    const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
    if (normal.z() < -0.9) continue;
    const double area = 0.5 * (b - a).cross(c - a).norm();
    const int count = static_cast<int>(area / (spacing * spacing));
    for (int k = 0; k < count; ++k) {
      double u = unit(*random), v = unit(*random);
      if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
      points->push_back(a + u * (b - a) + v * (c - a) + (noise > 0.0 ? offset(*random) : 0.0) * normal);
      normals->push_back(normal);
    }
  }
}

}  // namespace reconar::testing
