#include "core/mesh/text_format.h"

#include <string>

#include "core/base/number_format.h"

namespace reconar::mesh_internal {

void AppendShortestText(std::string* out, const Eigen::Vector3f& value) {
  for (int axis = 0; axis < 3; ++axis) {
    if (axis > 0) out->push_back(' ');
    AppendShortest(out, value[axis]);
  }
}

float ColourChannel(uint8_t byte) { return static_cast<float>(byte) / 255.0f; }

Status CheckFiniteVertices(const std::string& path, const Mesh& mesh) {
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    if (!mesh.positions[i].allFinite()) {
      return FileError(StatusCode::kInvalidArgument, path, "vertex " + std::to_string(i) + " has a non-finite position");
    }
  }
  for (size_t i = 0; i < mesh.normals.size(); ++i) {
    if (!mesh.normals[i].allFinite()) {
      return FileError(StatusCode::kInvalidArgument, path, "vertex " + std::to_string(i) + " has a non-finite normal");
    }
  }
  return Status::Ok();
}

}  // namespace reconar::mesh_internal
