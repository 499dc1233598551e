#pragma once
// Mesh: the triangle mesh or point cloud that Poisson meshing produces, the exporters write and
// the renderer draws. A mesh without triangles is a point cloud.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace reconar {

struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;             // empty, or one unit normal per vertex
  std::vector<std::array<uint8_t, 4>> colors;       // empty, or one RGBA colour per vertex
  std::vector<std::array<uint32_t, 3>> triangles;   // counter-clockwise seen from outside

  bool is_point_cloud() const { return triangles.empty(); }
};

}  // namespace reconar
