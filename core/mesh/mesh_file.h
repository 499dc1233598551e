#pragma once
// One entry point for every mesh file format, chosen by the file name's extension (any case):
//   .ply  Stanford PLY (core/mesh/mesh_io.h): binary little-endian, or ASCII with ply_ascii; read + write
//   .obj  Wavefront OBJ (core/mesh/obj_io.h); read + write
//   .glb  glTF 2.0 binary (core/mesh/glb_io.h); read + write
//   .wrl  VRML 2.0 (core/mesh/vrml_io.h); write only
// Another extension is kUnsupported naming the file and the extension; reading a .wrl is
// kUnsupported too. The format's own errors pass through unchanged.
#include <string>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

enum class MeshFileFormat { kPly, kObj, kGlb, kVrml };

struct MeshFileOptions {
  bool ply_ascii = false;  // .ply as ASCII instead of binary little-endian
};

// The format of `path` by its extension, or kUnsupported naming the file and the extension.
Result<MeshFileFormat> MeshFileFormatOf(const std::string& path);
// Like MeshFileFormatOf, and also kUnsupported for formats we write but do not read (.wrl).
Result<MeshFileFormat> ReadableMeshFileFormatOf(const std::string& path);

Status WriteMeshFile(const std::string& path, const Mesh& mesh, const MeshFileOptions& options = {});
Result<Mesh> ReadMeshFile(const std::string& path);

}  // namespace reconar
