#pragma once
// glTF 2.0 binary (.glb) writing and reading for Mesh (https://registry.khronos.org/glTF/specs/2.0/).
//
// WriteGlb writes one scene with one node and one mesh of one primitive:
// - POSITION: float VEC3 with the min/max the specification requires;
// - NORMAL: float VEC3 when the mesh has normals (they must be unit length, as glTF requires);
// - COLOR_0: normalized unsigned byte VEC4 when the mesh has colours. The bytes are stored
//   unchanged: glTF defines COLOR_0 as linear, our colours come from photographs (sRGB), so a
//   viewer shows them somewhat lighter than the photographs;
// - mode TRIANGLES with uint16 indices when every index fits below 65535, uint32 otherwise; a mesh
//   without triangles (a point cloud) is written as mode POINTS without indices;
// - no material (viewers use the default material, modulated by COLOR_0); asset version "2.0",
//   generator "reconar". Each buffer view starts on a 4-byte boundary, the JSON chunk is padded with
//   spaces and the BIN chunk with zeros to 4 bytes. Written atomically.
//
// ReadGlb reads the first primitive of the first mesh: POSITION, NORMAL and COLOR_0 (float, or
// normalized unsigned byte/short; VEC3 colours get alpha 255) and the indices (unsigned
// byte/short/int), in mode TRIANGLES or POINTS, in the mesh's own frame (node transforms are not
// applied). kUnsupported for glTF 1.0, extensionsRequired (e.g. KHR_draco_mesh_compression), a
// draco-compressed primitive, sparse accessors, buffers with a URI (external file or data: URI),
// other primitive modes, indexed POINTS. kCorruptData naming the file and the JSON path (e.g.
// "accessors[3].count") for anything that does not parse or lies outside its buffer.
#include <string>
#include <string_view>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

// The .glb bytes. kInvalidArgument for an inconsistent mesh (ValidateMesh), an empty one, or
// non-finite positions or normals.
Result<std::string> EncodeGlb(const Mesh& mesh);
Status WriteGlb(const std::string& path, const Mesh& mesh);

// `name_for_errors` prefixes every message.
Result<Mesh> DecodeGlb(std::string_view bytes, const std::string& name_for_errors);
Result<Mesh> ReadGlb(const std::string& path);

}  // namespace reconar
