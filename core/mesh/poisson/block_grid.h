#pragma once
// BlockGrid: the nodes of one level of the Poisson hierarchy, a regular grid of (2^depth + 1)^3
// nodes over the unit cube stored sparsely as 8x8x8-node blocks. Only blocks that were added hold
// storage; per-node values live in caller-owned arrays indexed by NodeIndex (block id * 512 +
// local offset, x fastest). The block table is dense (one int per block slot), so memory is
// 4 * (2^(depth-3) + 1)^3 bytes for the table plus the blocks themselves; depth is limited to
// kMaxBlockGridDepth so that the table stays below ~70 MB.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace reconar::poisson {

constexpr int kMaxBlockGridDepth = 11;
constexpr int kBlockBits = 3;
constexpr int kBlockSize = 1 << kBlockBits;                       // nodes per block edge
constexpr int kBlockNodes = kBlockSize * kBlockSize * kBlockSize;  // 512
// A block's nodes plus one ring of neighbours: [-1, kBlockSize] on every axis.
constexpr int kTileSize = kBlockSize + 2;
constexpr int kTileNodes = kTileSize * kTileSize * kTileSize;
// A block's nodes plus two rings: [-2, kBlockSize + 1] on every axis (5-wide stencils).
constexpr int kWideTileSize = kBlockSize + 4;
constexpr int kWideTileNodes = kWideTileSize * kWideTileSize * kWideTileSize;

class BlockGrid {
 public:
  explicit BlockGrid(int depth);

  int depth() const { return depth_; }
  int cells_per_axis() const { return 1 << depth_; }
  int nodes_per_axis() const { return (1 << depth_) + 1; }
  int blocks_per_axis() const { return blocks_per_axis_; }
  size_t num_blocks() const { return block_coords_.size(); }
  size_t num_node_slots() const { return num_blocks() * kBlockNodes; }

  // Block id at block coordinates, or -1 (also for coordinates outside the grid).
  int32_t BlockId(int bx, int by, int bz) const {
    if (static_cast<unsigned>(bx) >= static_cast<unsigned>(blocks_per_axis_) ||
        static_cast<unsigned>(by) >= static_cast<unsigned>(blocks_per_axis_) ||
        static_cast<unsigned>(bz) >= static_cast<unsigned>(blocks_per_axis_)) {
      return -1;
    }
    return table_[(static_cast<size_t>(bz) * blocks_per_axis_ + by) * blocks_per_axis_ + bx];
  }
  // Adds the block (if new) and returns its id. Coordinates must be inside the grid.
  int32_t AddBlock(int bx, int by, int bz);
  // Adds every block overlapping the node box [lo, hi] (clamped to the grid).
  void AddBlocksCoveringNodes(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi);

  const Eigen::Vector3i& block_coords(int32_t block) const { return block_coords_[block]; }

  // Node index or -1 when the node is outside the grid or its block is absent.
  int64_t NodeIndex(int x, int y, int z) const {
    if (static_cast<unsigned>(x) >= static_cast<unsigned>(nodes_per_axis()) ||
        static_cast<unsigned>(y) >= static_cast<unsigned>(nodes_per_axis()) ||
        static_cast<unsigned>(z) >= static_cast<unsigned>(nodes_per_axis())) {
      return -1;
    }
    const int32_t block = BlockId(x >> kBlockBits, y >> kBlockBits, z >> kBlockBits);
    if (block < 0) return -1;
    return static_cast<int64_t>(block) * kBlockNodes + LocalIndex(x & (kBlockSize - 1), y & (kBlockSize - 1),
                                                                  z & (kBlockSize - 1));
  }
  static int LocalIndex(int lx, int ly, int lz) { return (lz * kBlockSize + ly) * kBlockSize + lx; }
  // Global node coordinates of slot `local` of `block`.
  Eigen::Vector3i NodeCoords(int32_t block, int local) const {
    return block_coords_[block] * kBlockSize +
           Eigen::Vector3i(local & (kBlockSize - 1), (local >> kBlockBits) & (kBlockSize - 1), local >> (2 * kBlockBits));
  }
  bool IsValidNode(const Eigen::Vector3i& node) const {
    return (node.array() >= 0).all() && (node.array() < nodes_per_axis()).all();
  }

  // Copies the block's values and its one-node ring into tile[(z+1)*100 + (y+1)*10 + (x+1)];
  // nodes whose block is absent (or outside the grid) get `missing`.
  void GatherTile(int32_t block, const float* values, float missing, float* tile) const;
  // The same with two rings: tile[WideTileIndex(x + 2, y + 2, z + 2)].
  void GatherWideTile(int32_t block, const float* values, float missing, float* tile) const;

 private:
  int depth_;
  int blocks_per_axis_;
  std::vector<int32_t> table_;
  std::vector<Eigen::Vector3i> block_coords_;
};

inline int TileIndex(int tx, int ty, int tz) { return (tz * kTileSize + ty) * kTileSize + tx; }
inline int WideTileIndex(int tx, int ty, int tz) { return (tz * kWideTileSize + ty) * kWideTileSize + tx; }

}  // namespace reconar::poisson
