#pragma once
// Helpers shared by the text mesh formats (ASCII PLY, OBJ, VRML); not a public API.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/base/text_fields.h"
#include "core/mesh/mesh.h"

namespace reconar::mesh_internal {

// "x y z", each coordinate as the shortest text that reads back as the same float.
void AppendShortestText(std::string* out, const Eigen::Vector3f& value);
// The colour byte as a channel in 0..1, as the text formats store it (byte / 255).
float ColourChannel(uint8_t byte);
// kInvalidArgument naming `path` and the first vertex with a non-finite position or normal,
// which text formats cannot carry.
Status CheckFiniteVertices(const std::string& path, const Mesh& mesh);

}  // namespace reconar::mesh_internal
