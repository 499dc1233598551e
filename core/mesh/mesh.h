#pragma once
// Mesh: the triangle mesh or point cloud that Poisson meshing produces, the exporters write and
// the renderer draws. A mesh without triangles is a point cloud.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"

namespace reconar {

struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;             // empty, or one unit normal per vertex
  std::vector<std::array<uint8_t, 4>> colors;       // empty, or one RGBA colour per vertex
  // Empty, or one texture coordinate per vertex: (0, 0) the texture's top-left corner, u right,
  // v down, (1, 1) its bottom-right corner (glTF's convention), over the texture page of the
  // triangle that uses it (TexturePage). The texture itself travels beside the mesh.
  std::vector<Eigen::Vector2f> texcoords;
  std::vector<std::array<uint32_t, 3>> triangles;   // counter-clockwise seen from outside

  bool is_point_cloud() const { return triangles.empty(); }
};

// One image of a mesh's texture: it textures the triangles from first_triangle up to the next
// page's first triangle (the last page: up to the end). A texture's pages are listed in triangle
// order, the first at triangle 0.
struct TexturePage {
  size_t first_triangle = 0;
  Image<uint8_t> image;  // RGB
};

// The end of page k's triangles in a texture of `pages` over `triangle_count` triangles.
template <typename Page>
size_t PageTrianglesEnd(const std::vector<Page>& pages, size_t k, size_t triangle_count) {
  return k + 1 < pages.size() ? pages[k + 1].first_triangle : triangle_count;
}

// Ok when the pages start at triangle 0, in increasing order, within `triangle_count`;
// kInvalidArgument otherwise.
template <typename Page>
Status ValidateTexturePages(const std::vector<Page>& pages, size_t triangle_count) {
  if (pages.empty()) return InvalidArgument("texture: no page");
  for (size_t k = 0; k < pages.size(); ++k) {
    const size_t first = pages[k].first_triangle;
    if ((k == 0 && first != 0) || (k > 0 && first < pages[k - 1].first_triangle) || first > triangle_count) {
      return InvalidArgument("texture: page " + std::to_string(k) + " starts at triangle " + std::to_string(first) +
                             ", out of order");
    }
  }
  return Status::Ok();
}

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
