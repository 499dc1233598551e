#include "core/mesh/poisson/block_grid.h"

#include <algorithm>
#include <cstring>

#include "core/base/check.h"

namespace reconar::poisson {

BlockGrid::BlockGrid(int depth) : depth_(depth) {
  RECONAR_CHECK(depth >= 1 && depth <= kMaxBlockGridDepth) << "depth " << depth;
  blocks_per_axis_ = (nodes_per_axis() + kBlockSize - 1) >> kBlockBits;
  table_.assign(static_cast<size_t>(blocks_per_axis_) * blocks_per_axis_ * blocks_per_axis_, -1);
}

int32_t BlockGrid::AddBlock(int bx, int by, int bz) {
  int32_t& slot = table_[(static_cast<size_t>(bz) * blocks_per_axis_ + by) * blocks_per_axis_ + bx];
  if (slot < 0) {
    slot = static_cast<int32_t>(block_coords_.size());
    block_coords_.emplace_back(bx, by, bz);
  }
  return slot;
}

void BlockGrid::AddBlocksCoveringNodes(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
  const int last = nodes_per_axis() - 1;
  const Eigen::Vector3i block_lo = lo.cwiseMax(0).cwiseMin(last) / kBlockSize;
  const Eigen::Vector3i block_hi = hi.cwiseMax(0).cwiseMin(last) / kBlockSize;
  for (int bz = block_lo.z(); bz <= block_hi.z(); ++bz) {
    for (int by = block_lo.y(); by <= block_hi.y(); ++by) {
      for (int bx = block_lo.x(); bx <= block_hi.x(); ++bx) AddBlock(bx, by, bz);
    }
  }
}

void BlockGrid::GatherTile(int32_t block, const float* values, float missing, float* tile) const {
  const Eigen::Vector3i& b = block_coords_[block];
  // Interior of the tile: the block itself, row by row.
  const float* own = values + static_cast<size_t>(block) * kBlockNodes;
  for (int z = 0; z < kBlockSize; ++z) {
    for (int y = 0; y < kBlockSize; ++y) {
      std::memcpy(tile + TileIndex(1, y + 1, z + 1), own + LocalIndex(0, y, z), kBlockSize * sizeof(float));
    }
  }
  // The ring: for each of the 26 neighbours, copy the face/edge/corner slab it contributes.
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const int32_t neighbour = BlockId(b.x() + dx, b.y() + dy, b.z() + dz);
        const float* src = neighbour < 0 ? nullptr : values + static_cast<size_t>(neighbour) * kBlockNodes;
        // Tile ranges and the matching local coordinates inside the neighbour.
        const int tx0 = dx < 0 ? 0 : (dx > 0 ? kTileSize - 1 : 1);
        const int tx1 = dx == 0 ? kBlockSize : tx0;
        const int ty0 = dy < 0 ? 0 : (dy > 0 ? kTileSize - 1 : 1);
        const int ty1 = dy == 0 ? kBlockSize : ty0;
        const int tz0 = dz < 0 ? 0 : (dz > 0 ? kTileSize - 1 : 1);
        const int tz1 = dz == 0 ? kBlockSize : tz0;
        for (int tz = tz0; tz <= tz1; ++tz) {
          const int lz = (tz - 1) & (kBlockSize - 1);
          for (int ty = ty0; ty <= ty1; ++ty) {
            const int ly = (ty - 1) & (kBlockSize - 1);
            for (int tx = tx0; tx <= tx1; ++tx) {
              const int lx = (tx - 1) & (kBlockSize - 1);
              tile[TileIndex(tx, ty, tz)] = src ? src[LocalIndex(lx, ly, lz)] : missing;
            }
          }
        }
      }
    }
  }
}

void BlockGrid::GatherWideTile(int32_t block, const float* values, float missing, float* tile) const {
  const Eigen::Vector3i& b = block_coords_[block];
  // Along x a tile row spans three blocks: [-2, -1] of the left one, the block, [8, 9] of the right one.
  constexpr int kRing = 2;
  for (int tz = 0; tz < kWideTileSize; ++tz) {
    const int z = tz - kRing;
    const int dz = z < 0 ? -1 : (z >= kBlockSize ? 1 : 0);
    for (int ty = 0; ty < kWideTileSize; ++ty) {
      const int y = ty - kRing;
      const int dy = y < 0 ? -1 : (y >= kBlockSize ? 1 : 0);
      float* row = tile + WideTileIndex(0, ty, tz);
      for (int dx = -1; dx <= 1; ++dx) {
        const int32_t source = BlockId(b.x() + dx, b.y() + dy, b.z() + dz);
        const int x0 = dx < 0 ? kBlockSize - kRing : 0;
        const int count = dx == 0 ? kBlockSize : kRing;
        float* out = row + (dx < 0 ? 0 : (dx == 0 ? kRing : kRing + kBlockSize));
        if (source < 0) {
          std::fill(out, out + count, missing);
          continue;
        }
        std::memcpy(out, values + static_cast<size_t>(source) * kBlockNodes +
                             LocalIndex(x0, y & (kBlockSize - 1), z & (kBlockSize - 1)),
                    static_cast<size_t>(count) * sizeof(float));
      }
    }
  }
}

}  // namespace reconar::poisson
