#pragma once
// Triangle mesh simplification by edge collapse under quadric error metrics (Garland & Heckbert,
// "Surface Simplification Using Quadric Error Metrics", SIGGRAPH 1997): every vertex carries the
// sum of the squared-distance quadrics of its faces' planes, the cheapest edge collapses first to
// the point that minimises the summed quadric, and border edges carry heavily weighted planes
// perpendicular to their face so that open borders (Poisson meshes trimmed by density) stay where
// they are (their sec. 6). A collapse is refused when it would make the mesh non-manifold (the
// link condition) or turn a face over. Colours follow the new vertex along its edge; normals, when
// the mesh has them, are recomputed. Deterministic: ties break by vertex index.
#include <cstddef>
#include <limits>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

// Triangles a handheld GPU (GLES, llvmpipe or a Mali-class part) draws at video rate: the face
// budget `reconar reconstruct` writes and `reconar view` draws by default.
inline constexpr size_t kHandheldMaxFaces = 500000;

struct SimplifyOptions {
  size_t target_faces = 0;  // stop once at most this many triangles remain (> 0)
  // Also stop before a collapse whose quadric error (squared distance, model units squared)
  // exceeds this; infinity: only target_faces stops it.
  double max_error = std::numeric_limits<double>::infinity();
  double border_weight = 1000.0;  // weight of the planes that hold border edges
  // A collapse is refused when a surviving face's normal would turn by more than acos of this.
  double min_normal_cosine = 0.2;

  Status Check() const;
};

struct SimplifyReport {
  size_t vertices_before = 0, faces_before = 0;
  size_t vertices_after = 0, faces_after = 0;
  size_t collapses = 0;
  bool simplified = false;          // the mesh was over target_faces and went through the collapses
  double max_collapse_error = 0.0;  // largest quadric error of a collapse done
  double seconds = 0.0;
};

// Simplifies *mesh in place (dropping unused vertices). A mesh already within target_faces is
// left as it is. InvalidArgument for bad options or a mesh that fails ValidateMesh.
Result<SimplifyReport> SimplifyMesh(const SimplifyOptions& options, Mesh* mesh);

// The face budget of `reconar reconstruct`, `view` and `export` (--max-faces): a mesh of more
// than max_faces triangles is simplified to at most max_faces with the default options; a mesh
// within the budget, or max_faces 0 (no budget), is left as it is, unread, and the report is all
// zero (simplified false).
Result<SimplifyReport> SimplifyToFaceBudget(size_t max_faces, Mesh* mesh);

}  // namespace reconar
