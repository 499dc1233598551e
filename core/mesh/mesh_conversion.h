#pragma once
// `reconar export`: a mesh or point cloud file read, simplified to a face budget when it has more
// triangles, and written in the format its output name asks for (core/mesh/mesh_file.h). A
// textured .glb (its base colour texture a PNG, as `reconar texture` writes it) keeps its texture
// into .glb, and into .obj with the texture beside it (OUTPUT's stem + .png, and stem_1.png, ... for
// further pages, named by the .mtl);
// .ply and .wrl carry no texture (the report says it was dropped); a textured model over the face
// budget is refused rather than simplified (its charts would tear).
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/base/status.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/simplify.h"

namespace reconar {

struct MeshConversionOptions {
  size_t max_faces = 0;  // 0: every triangle kept (SimplifyToFaceBudget)
  MeshFileOptions file;  // ply_ascii: only for a .ply output
};

struct MeshConversionReport {
  size_t vertices_read = 0, triangles_read = 0;
  size_t vertices = 0, triangles = 0;  // as written
  bool normals = false, colors = false;
  bool textured = false;         // the input had a texture
  bool texture_dropped = false;  // ... which the output's format cannot hold
  std::vector<std::string> texture_paths;  // the .obj's texture pages, written beside it
  SimplifyReport simplify;
  uintmax_t bytes = 0;  // of the output file
  double seconds_read = 0.0, seconds_write = 0.0;
};

// Refuses an input format it cannot read, an output name of no known format and --ascii for
// anything but .ply before reading; creates the output's missing parent directories; writes
// atomically.
Result<MeshConversionReport> ConvertMeshFile(const std::string& input, const std::string& output,
                                             const MeshConversionOptions& options);

}  // namespace reconar
