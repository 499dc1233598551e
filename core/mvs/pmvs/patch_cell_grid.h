#pragma once
// PatchCellGrids: PMVS's image cells Q_i(x, y) (Furukawa & Ponce 2010, sec. 2.3): every image is
// divided into beta x beta pixel cells and each cell lists the patches whose centre projects into
// it, for every image of the patch's T(p). Memory: one int32 list head per cell plus one 8-byte
// entry per (patch, image). Writes are single-threaded (the merge steps); reads may be parallel.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/mvs/pmvs/patch.h"
#include "core/mvs/pmvs/pmvs_view.h"

namespace reconar {

class PatchCellGrids {
 public:
  PatchCellGrids(const std::vector<PmvsView>& views, int cell_size);

  int cell_size() const { return cell_size_; }
  int cols(int image) const { return cols_[image]; }
  int rows(int image) const { return rows_[image]; }

  // The cell of pixel p in `image`; false outside the grid.
  bool CellOf(int image, const Eigen::Vector2d& pixel, int* x, int* y) const;
  bool Empty(int image, int x, int y) const { return heads_[image][Index(image, x, y)] < 0; }

  // Registers patch `id` in the cell of each image of patch.images where its centre projects.
  void Insert(int id, const Patch& patch);
  // Empties every cell (before re-inserting a compacted patch list).
  void Clear();

  // Calls fn(patch_id) for every patch listed in cell (x, y) of `image`.
  template <typename Fn>
  void ForEach(int image, int x, int y, Fn&& fn) const {
    for (int32_t e = heads_[image][Index(image, x, y)]; e >= 0; e = entries_[e].next) fn(entries_[e].patch);
  }

 private:
  struct Entry {
    int32_t patch;
    int32_t next;
  };
  size_t Index(int image, int x, int y) const { return static_cast<size_t>(y) * cols_[image] + x; }

  const std::vector<PmvsView>& views_;
  int cell_size_;
  std::vector<int> cols_, rows_;
  std::vector<std::vector<int32_t>> heads_;
  std::vector<Entry> entries_;
};

// PMVS's neighbourhood relation (sec. 3.2): p and q lie on a common plane when
// |(c_p - c_q) . n_p| + |(c_p - c_q) . n_q| < 2 rho, rho the world size of `rho_pixels` in p's
// reference image at p's depth.
double NeighbourDistance(const std::vector<PmvsView>& views, const Patch& p, double rho_pixels);
inline bool AreNeighbours(const Patch& p, const Patch& q, double rho) {
  const Eigen::Vector3f d = p.center - q.center;
  return std::abs(d.dot(p.normal)) + std::abs(d.dot(q.normal)) < 2.0 * rho;
}

}  // namespace reconar
