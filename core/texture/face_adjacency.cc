#include "core/texture/face_adjacency.h"

#include <algorithm>
#include <cstdint>

namespace reconar {

std::vector<std::array<int, 3>> FaceNeighbours(const Mesh& mesh) {
  struct EdgeSide {
    uint64_t key;  // the lower vertex index in the high half
    int face;
    int edge;
  };
  std::vector<EdgeSide> sides;
  sides.reserve(3 * mesh.triangles.size());
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    for (int e = 0; e < 3; ++e) {
      const uint64_t a = t[static_cast<size_t>(e)], b = t[static_cast<size_t>((e + 1) % 3)];
      sides.push_back({(std::min(a, b) << 32) | std::max(a, b), static_cast<int>(f), e});
    }
  }
  std::sort(sides.begin(), sides.end(), [](const EdgeSide& x, const EdgeSide& y) {
    return x.key != y.key ? x.key < y.key : x.face < y.face;
  });
  std::vector<std::array<int, 3>> neighbours(mesh.triangles.size(), {-1, -1, -1});
  for (size_t i = 0; i < sides.size();) {
    size_t j = i + 1;
    while (j < sides.size() && sides[j].key == sides[i].key) ++j;
    if (j - i == 2 && sides[i].face != sides[i + 1].face) {
      neighbours[static_cast<size_t>(sides[i].face)][static_cast<size_t>(sides[i].edge)] = sides[i + 1].face;
      neighbours[static_cast<size_t>(sides[i + 1].face)][static_cast<size_t>(sides[i + 1].edge)] = sides[i].face;
    }
    i = j;
  }
  return neighbours;
}

}  // namespace reconar
