#include "core/mesh/poisson/marching_cubes.h"

#include <cmath>
#include <limits>

namespace reconar::poisson {
namespace {

// Corner c of a cube sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1). Edge e joins corner
// kEdgeCorner[e] to the corner one step along kEdgeAxis[e].
struct CubeTables {
  int edge_corner[12];
  int edge_axis[12];
  // polygons[case]: edge cycles, each terminated by -1; the list ends with an extra -1.
  std::array<std::array<int8_t, 32>, 256> polygons;
};

int EdgeId(const CubeTables& t, int corner_a, int corner_b) {
  const int lo = corner_a < corner_b ? corner_a : corner_b;
  const int axis = (corner_a ^ corner_b) == 1 ? 0 : ((corner_a ^ corner_b) == 2 ? 1 : 2);
  for (int e = 0; e < 12; ++e) {
    if (t.edge_corner[e] == lo && t.edge_axis[e] == axis) return e;
  }
  return -1;
}

CubeTables BuildTables() {
  CubeTables t{};
  int count = 0;
  for (int axis = 0; axis < 3; ++axis) {
    for (int c = 0; c < 8; ++c) {
      if (c & (1 << axis)) continue;
      t.edge_corner[count] = c;
      t.edge_axis[count] = axis;
      ++count;
    }
  }
  // Faces: axis a, side s; corners in counter-clockwise order seen from outside the cube.
  int faces[6][4];
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int s = 0; s < 2; ++s) {
      for (int i = 0; i < 4; ++i) {
        const int k = s == 1 ? i : 3 - i;  // the -a side sees the reversed order
        faces[a * 2 + s][i] = (s << a) | (uv[k][0] << b) | (uv[k][1] << c);
      }
    }
  }
  for (int config = 0; config < 256; ++config) {
    auto inside = [config](int corner) { return (config >> corner) & 1; };
    int next[12];
    for (int& n : next) n = -1;
    for (const auto& face : faces) {
      for (int i = 0; i < 4; ++i) {
        // Entering a run of inside corners between face[i] and face[i+1]...
        if (inside(face[i]) || !inside(face[(i + 1) % 4])) continue;
        // ...leaving it at the first inside -> outside step after that.
        int j = (i + 1) % 4;
        while (!( inside(face[j]) && !inside(face[(j + 1) % 4]))) j = (j + 1) % 4;
        next[EdgeId(t, face[i], face[(i + 1) % 4])] = EdgeId(t, face[j], face[(j + 1) % 4]);
      }
    }
    bool visited[12] = {};
    int length = 0;
    for (int start = 0; start < 12; ++start) {
      if (next[start] < 0 || visited[start]) continue;
      for (int e = start; !visited[e]; e = next[e]) {
        visited[e] = true;
        t.polygons[config][length++] = static_cast<int8_t>(e);
      }
      t.polygons[config][length++] = -1;
    }
    t.polygons[config][length] = -1;
  }
  return t;
}

const CubeTables& Tables() {
  static const CubeTables tables = BuildTables();
  return tables;
}

}  // namespace

IsoSurface ExtractIsoSurface(const BlockGrid& grid, const std::vector<float>& values, float iso,
                             const EdgeCrossingFn& edge_crossing) {
  const CubeTables& tables = Tables();
  IsoSurface surface;
  const int last = grid.nodes_per_axis() - 1;
  const float missing = std::numeric_limits<float>::quiet_NaN();
  std::vector<int32_t> edge_vertex(grid.num_node_slots() * 3, -1);
  alignas(64) float tile[kTileNodes];

  // Pass 1: one vertex per crossed grid edge, owned by the edge's lower node.
  for (int32_t block = 0; block < static_cast<int32_t>(grid.num_blocks()); ++block) {
    grid.GatherTile(block, values.data(), missing, tile);
    for (int local = 0; local < kBlockNodes; ++local) {
      const Eigen::Vector3i node = grid.NodeCoords(block, local);
      if ((node.array() > last).any()) continue;
      const int lx = local & (kBlockSize - 1), ly = (local >> kBlockBits) & (kBlockSize - 1),
                lz = local >> (2 * kBlockBits);
      const float v0 = tile[TileIndex(lx + 1, ly + 1, lz + 1)];
      if (std::isnan(v0)) continue;
      const bool inside0 = v0 < iso;
      for (int axis = 0; axis < 3; ++axis) {
        if (node[axis] == last) continue;
        const float v1 = tile[TileIndex(lx + 1 + (axis == 0), ly + 1 + (axis == 1), lz + 1 + (axis == 2))];
        if (std::isnan(v1) || (v1 < iso) == inside0) continue;
        const float t = edge_crossing ? std::fmin(1.0f, std::fmax(0.0f, edge_crossing(node, axis, v0, v1)))
                                      : std::fmin(1.0f, std::fmax(0.0f, (iso - v0) / (v1 - v0)));
        Eigen::Vector3f position = node.cast<float>();
        position[axis] += t;
        edge_vertex[(static_cast<size_t>(block) * kBlockNodes + local) * 3 + axis] =
            static_cast<int32_t>(surface.positions.size());
        surface.positions.push_back(position);
      }
    }
  }

  // Pass 2: polygons of every cell whose lower corner lies in the block.
  for (int32_t block = 0; block < static_cast<int32_t>(grid.num_blocks()); ++block) {
    grid.GatherTile(block, values.data(), missing, tile);
    for (int local = 0; local < kBlockNodes; ++local) {
      const Eigen::Vector3i node = grid.NodeCoords(block, local);
      if ((node.array() >= last).any()) continue;
      const int lx = local & (kBlockSize - 1), ly = (local >> kBlockBits) & (kBlockSize - 1),
                lz = local >> (2 * kBlockBits);
      int config = 0;
      int present = 0;
      for (int c = 0; c < 8; ++c) {
        const float v = tile[TileIndex(lx + 1 + (c & 1), ly + 1 + ((c >> 1) & 1), lz + 1 + ((c >> 2) & 1))];
        if (std::isnan(v)) continue;
        present |= 1 << c;
        if (v < iso) config |= 1 << c;
      }
      if (config == 0 || config == present) continue;
      if (present != 255) {
        ++surface.cells_skipped;
        continue;
      }
      const int8_t* polygon = tables.polygons[config].data();
      while (*polygon >= 0) {
        int32_t cycle[12];
        int length = 0;
        for (; *polygon >= 0; ++polygon) {
          const int e = *polygon;
          const int c = tables.edge_corner[e];
          const int64_t owner =
              grid.NodeIndex(node.x() + (c & 1), node.y() + ((c >> 1) & 1), node.z() + ((c >> 2) & 1));
          cycle[length++] = edge_vertex[static_cast<size_t>(owner) * 3 + tables.edge_axis[e]];
        }
        ++polygon;  // the cycle's terminator
        for (int i = 1; i + 1 < length; ++i) {
          surface.triangles.push_back({static_cast<uint32_t>(cycle[0]), static_cast<uint32_t>(cycle[i]),
                                       static_cast<uint32_t>(cycle[i + 1])});
        }
      }
    }
  }
  return surface;
}

}  // namespace reconar::poisson
