#pragma once
// Which faces of a triangle mesh share an edge: per face, the face across each of its edges.
#include <array>
#include <vector>

#include "core/mesh/mesh.h"

namespace reconar {

// Per triangle, the triangle across its edges (v0 v1), (v1 v2), (v2 v0); -1 on a border and on an
// edge that more than two triangles share.
std::vector<std::array<int, 3>> FaceNeighbours(const Mesh& mesh);

}  // namespace reconar
