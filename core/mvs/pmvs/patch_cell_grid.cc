#include "core/mvs/pmvs/patch_cell_grid.h"

#include <cmath>

namespace reconar {

PatchCellGrids::PatchCellGrids(const std::vector<PmvsView>& views, int cell_size)
    : views_(views), cell_size_(cell_size) {
  for (const PmvsView& view : views) {
    cols_.push_back((view.width + cell_size - 1) / cell_size);
    rows_.push_back((view.height + cell_size - 1) / cell_size);
    heads_.emplace_back(static_cast<size_t>(cols_.back()) * rows_.back(), -1);
  }
}

bool PatchCellGrids::CellOf(int image, const Eigen::Vector2d& pixel, int* x, int* y) const {
  // Pixel centres are integers, so pixel k covers [k - 0.5, k + 0.5).
  const double fx = std::floor((pixel.x() + 0.5) / cell_size_);
  const double fy = std::floor((pixel.y() + 0.5) / cell_size_);
  if (!(fx >= 0.0 && fy >= 0.0 && fx < cols_[image] && fy < rows_[image])) return false;
  *x = static_cast<int>(fx);
  *y = static_cast<int>(fy);
  return true;
}

void PatchCellGrids::Insert(int id, const Patch& patch) {
  const Eigen::Vector3d center = patch.center.cast<double>();
  for (int image : patch.images) {
    const PmvsView& view = views_[image];
    const Eigen::Vector3d h = view.ProjectHomogeneous(center);
    if (!(h.z() > 0.0)) continue;
    int x, y;
    if (!CellOf(image, h.head<2>() / h.z(), &x, &y)) continue;
    int32_t& head = heads_[image][Index(image, x, y)];
    entries_.push_back({id, head});
    head = static_cast<int32_t>(entries_.size() - 1);
  }
}

void PatchCellGrids::Clear() {
  for (auto& heads : heads_) std::fill(heads.begin(), heads.end(), -1);
  entries_.clear();
}

double NeighbourDistance(const std::vector<PmvsView>& views, const Patch& p, double rho_pixels) {
  const PmvsView& ref = views[p.reference];
  return rho_pixels * ref.PixelFootprint(ref.Depth(p.center.cast<double>()));
}

}  // namespace reconar
