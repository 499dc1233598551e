#pragma once
// Mesh: the triangle mesh or point cloud that Poisson meshing produces, the exporters write and
// the renderer draws. A mesh without triangles is a point cloud.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace reconar {

struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;             // empty, or one unit normal per vertex
  std::vector<std::array<uint8_t, 4>> colors;       // empty, or one RGBA colour per vertex
  // Empty, or one texture coordinate per vertex: (0, 0) the texture's top-left corner, u right,
  // v down, (1, 1) its bottom-right corner (glTF's convention). The texture itself travels beside
  // the mesh (core/texture/texture_mesh.h's TexturedMesh).
  std::vector<Eigen::Vector2f> texcoords;
  std::vector<std::array<uint32_t, 3>> triangles;   // counter-clockwise seen from outside

  bool is_point_cloud() const { return triangles.empty(); }
};

// A mesh with a name: an element of a design (a glTF node, an OBJ group).
struct NamedMesh {
  std::string name;
  Mesh mesh;
};

// Ok when `normals`, `colors` and `texcoords` are empty or hold one entry per position and every triangle index
// is below positions.size(); otherwise kInvalidArgument naming the first problem. The writers
// (core/mesh/mesh_io.h, glb_io.h) check this before writing anything.
Status ValidateMesh(const Mesh& mesh);

// Sets mesh->normals to the area-weighted average of the adjacent triangles' normals, oriented
// by the counter-clockwise winding. Vertices without a non-degenerate triangle get (0, 0, 1) so
// that every normal is unit length (glTF requires it). The mesh must pass ValidateMesh.
void ComputeVertexNormals(Mesh* mesh);

// The given triangles of `mesh` (indices into mesh.triangles, each at most once, all valid) with
// only the vertices they use, in their first-use order, and those vertices' normals, colours and
// texture coordinates.
Mesh SubMesh(const Mesh& mesh, const std::vector<size_t>& triangles);

// The meshes as one, in order: normals, colours and texture coordinates kept when every part with
// vertices has them.
Mesh JoinMeshes(const std::vector<NamedMesh>& parts);

}  // namespace reconar
