#include "core/mesh/mesh.h"

#include <unordered_map>

#include <Eigen/Geometry>

#include <cmath>
#include <string>

namespace reconar {

Status ValidateMesh(const Mesh& mesh) {
  const size_t num_vertices = mesh.positions.size();
  if (!mesh.normals.empty() && mesh.normals.size() != num_vertices) {
    return InvalidArgument("mesh: " + std::to_string(mesh.normals.size()) + " normals for " +
                           std::to_string(num_vertices) + " vertices");
  }
  if (!mesh.colors.empty() && mesh.colors.size() != num_vertices) {
    return InvalidArgument("mesh: " + std::to_string(mesh.colors.size()) + " colours for " +
                           std::to_string(num_vertices) + " vertices");
  }
  if (!mesh.texcoords.empty() && mesh.texcoords.size() != num_vertices) {
    return InvalidArgument("mesh: " + std::to_string(mesh.texcoords.size()) + " texture coordinates for " +
                           std::to_string(num_vertices) + " vertices");
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const uint32_t index : mesh.triangles[t]) {
      if (index >= num_vertices) {
        return InvalidArgument("mesh: triangle " + std::to_string(t) + " has vertex index " + std::to_string(index) +
                               " out of range [0, " + std::to_string(num_vertices) + ")");
      }
    }
  }
  return Status::Ok();
}

void ComputeVertexNormals(Mesh* mesh) {
  std::vector<Eigen::Vector3f>& normals = mesh->normals;
  normals.assign(mesh->positions.size(), Eigen::Vector3f::Zero());
  for (const std::array<uint32_t, 3>& triangle : mesh->triangles) {
    const Eigen::Vector3f& a = mesh->positions[triangle[0]];
    // The cross product's length is twice the triangle's area: the weight comes for free.
    const Eigen::Vector3f weighted = (mesh->positions[triangle[1]] - a).cross(mesh->positions[triangle[2]] - a);
    for (const uint32_t index : triangle) normals[index] += weighted;
  }
  for (Eigen::Vector3f& normal : normals) {
    const float length = normal.norm();
    normal = length > 1e-30f && std::isfinite(length) ? Eigen::Vector3f(normal / length) : Eigen::Vector3f::UnitZ();
  }
}

Mesh SubMesh(const Mesh& mesh, const std::vector<size_t>& triangles) {
  Mesh part;
  std::unordered_map<uint32_t, uint32_t> new_index;
  part.triangles.reserve(triangles.size());
  for (size_t t : triangles) {
    std::array<uint32_t, 3> triangle = mesh.triangles[t];
    for (uint32_t& vertex : triangle) {
      const auto [it, added] = new_index.emplace(vertex, static_cast<uint32_t>(part.positions.size()));
      if (added) {
        part.positions.push_back(mesh.positions[vertex]);
        if (!mesh.normals.empty()) part.normals.push_back(mesh.normals[vertex]);
        if (!mesh.colors.empty()) part.colors.push_back(mesh.colors[vertex]);
        if (!mesh.texcoords.empty()) part.texcoords.push_back(mesh.texcoords[vertex]);
      }
      vertex = it->second;
    }
    part.triangles.push_back(triangle);
  }
  return part;
}

Mesh JoinMeshes(const std::vector<NamedMesh>& parts) {
  Mesh joined;
  bool normals = true, colours = true, texcoords = true;
  for (const NamedMesh& part : parts) {
    if (part.mesh.positions.empty()) continue;
    normals = normals && part.mesh.normals.size() == part.mesh.positions.size();
    colours = colours && part.mesh.colors.size() == part.mesh.positions.size();
    texcoords = texcoords && part.mesh.texcoords.size() == part.mesh.positions.size();
  }
  for (const NamedMesh& part : parts) {
    const uint32_t offset = static_cast<uint32_t>(joined.positions.size());
    joined.positions.insert(joined.positions.end(), part.mesh.positions.begin(), part.mesh.positions.end());
    if (normals) joined.normals.insert(joined.normals.end(), part.mesh.normals.begin(), part.mesh.normals.end());
    if (colours) joined.colors.insert(joined.colors.end(), part.mesh.colors.begin(), part.mesh.colors.end());
    if (texcoords) {
      joined.texcoords.insert(joined.texcoords.end(), part.mesh.texcoords.begin(), part.mesh.texcoords.end());
    }
    for (const std::array<uint32_t, 3>& t : part.mesh.triangles) {
      joined.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    }
  }
  return joined;
}

}  // namespace reconar
