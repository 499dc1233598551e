#include "core/mvs/pmvs/patch_filter.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/mvs/pmvs/patch_sampler.h"

namespace reconar {
namespace {

constexpr double kMinNeighbourFraction = 0.25;  // PMVS's regularisation threshold

// Keeps the patches with keep[i] set (moving them forward) and rebuilds the grids.
size_t Compact(const std::vector<uint8_t>& keep, std::vector<Patch>* patches, PatchCellGrids* grids) {
  size_t out = 0;
  for (size_t i = 0; i < patches->size(); ++i) {
    if (!keep[i]) continue;
    if (out != i) (*patches)[out] = std::move((*patches)[i]);
    ++out;
  }
  const size_t removed = patches->size() - out;
  patches->resize(out);
  grids->Clear();
  for (size_t i = 0; i < patches->size(); ++i) grids->Insert(static_cast<int>(i), (*patches)[i]);
  return removed;
}

bool CellOfPatch(const PmvsView& view, const PatchCellGrids& grids, int image, const Eigen::Vector3d& center,
                 int* x, int* y) {
  const Eigen::Vector3d h = view.ProjectHomogeneous(center);
  return h.z() > 0.0 && grids.CellOf(image, h.head<2>() / h.z(), x, y);
}

// True when a patch that is not p's neighbour lies in front of p in p's cell (x, y) of `image`.
bool OccludedInCell(const std::vector<PmvsView>& views, const std::vector<Patch>& patches, const PatchCellGrids& grids,
                    size_t i, double rho, int image, int x, int y) {
  const Patch& p = patches[i];
  const PmvsView& view = views[image];
  const double depth = view.Depth(p.center.cast<double>());
  bool occluded = false;
  grids.ForEach(image, x, y, [&](int q_id) {
    const Patch& q = patches[q_id];
    if (occluded || q_id == static_cast<int>(i) || AreNeighbours(p, q, rho)) return;
    occluded = view.Depth(q.center.cast<double>()) < depth;
  });
  return occluded;
}

}  // namespace

size_t FilterPatches(const std::vector<PmvsView>& views, const PatchMvsOptions& options, ThreadPool* pool,
                     std::vector<Patch>* patches, PatchCellGrids* grids) {
  const double rho_pixels = options.cell_size;
  size_t removed = 0;
  std::vector<uint8_t> keep;

  // 1. Visibility consistency.
  keep.assign(patches->size(), 1);
  pool->ParallelFor(0, patches->size(), [&](size_t i, int) {
    const Patch& p = (*patches)[i];
    const Eigen::Vector3d center = p.center.cast<double>();
    const double rho = NeighbourDistance(views, p, rho_pixels);
    double occluded_support = 0.0;
    for (int image : p.images) {
      const PmvsView& view = views[image];
      int x, y;
      if (!CellOfPatch(view, *grids, image, center, &x, &y)) continue;
      const double depth = view.Depth(center);
      grids->ForEach(image, x, y, [&](int q_id) {
        const Patch& q = (*patches)[q_id];
        if (q_id == static_cast<int>(i) || AreNeighbours(p, q, rho)) return;
        if (view.Depth(q.center.cast<double>()) > depth) occluded_support += q.score;
      });
    }
    if (static_cast<double>(p.images.size()) * p.score < occluded_support) keep[i] = 0;
  });
  removed += Compact(keep, patches, grids);

  // 1b. Free-space consistency: the images outside T(p) that see p's location unoccluded (inside,
  // within iota of the normal, no non-neighbour patch in front of p in its cell) and facing it,
  // yet disagree photometrically (NCC < min_ncc), testify that the location is empty. p goes when
  // they outnumber T(p). Filter 1 needs patches behind p; in front of an untextured background
  // (where PMVS makes no patches) this is the only evidence against a fattened silhouette patch.
  keep.assign(patches->size(), 1);
  {
    std::vector<std::unique_ptr<PatchSampler>> samplers;
    for (int w = 0; w < pool->num_threads(); ++w) {
      samplers.push_back(std::make_unique<PatchSampler>(views, options.patch_size, 0.0));
    }
    const double min_cos = std::cos(options.max_view_angle);
    const double margin = 0.5 * options.patch_size;
    pool->ParallelFor(0, patches->size(), [&](size_t i, int worker) {
      const Patch& p = (*patches)[i];
      const Eigen::Vector3d center = p.center.cast<double>();
      const Eigen::Vector3d normal = p.normal.cast<double>();
      const double rho = NeighbourDistance(views, p, rho_pixels);
      PatchSampler& sampler = *samplers[worker];
      bool sampled = false;
      int contradicting = 0;
      for (int image = 0; image < static_cast<int>(views.size()); ++image) {
        if (std::find(p.images.begin(), p.images.end(), image) != p.images.end()) continue;
        const PmvsView& view = views[image];
        if (normal.dot((view.center - center).normalized()) < min_cos) continue;
        const Eigen::Vector3d h = view.ProjectHomogeneous(center);
        if (h.z() <= 0.0 || !view.Inside(h.head<2>() / h.z(), margin)) continue;
        int x, y;
        if (!grids->CellOf(image, h.head<2>() / h.z(), &x, &y)) continue;
        if (OccludedInCell(views, *patches, *grids, i, rho, image, x, y)) continue;
        if (!sampled) {
          if (!sampler.SetPatch(center, normal, p.reference)) return;
          sampled = true;
        }
        const float ncc = sampler.Ncc(image);
        if (ncc > -1.0f && ncc < options.min_ncc) ++contradicting;  // -1: the grid left the image
      }
      if (contradicting > static_cast<int>(p.images.size())) keep[i] = 0;
    });
  }
  removed += Compact(keep, patches, grids);

  // 2. Depth-map consistency.
  keep.assign(patches->size(), 1);
  std::vector<std::vector<int>> remaining(patches->size());
  pool->ParallelFor(0, patches->size(), [&](size_t i, int) {
    const Patch& p = (*patches)[i];
    const Eigen::Vector3d center = p.center.cast<double>();
    const double rho = NeighbourDistance(views, p, rho_pixels);
    std::vector<int>& images = remaining[i];
    for (int image : p.images) {
      int x, y;
      const bool occluded = CellOfPatch(views[image], *grids, image, center, &x, &y) &&
                            OccludedInCell(views, *patches, *grids, i, rho, image, x, y);
      if (occluded && image == p.reference) {
        keep[i] = 0;
        return;
      }
      if (!occluded) images.push_back(image);
    }
    if (static_cast<int>(images.size()) < options.min_visible_views) keep[i] = 0;
  });
  for (size_t i = 0; i < patches->size(); ++i) {
    if (keep[i] && remaining[i].size() != (*patches)[i].images.size()) (*patches)[i].images.swap(remaining[i]);
  }
  remaining.clear();
  removed += Compact(keep, patches, grids);

  // 3. Regularisation: enough neighbours in the 3 x 3 cells around p.
  keep.assign(patches->size(), 1);
  pool->ParallelFor(0, patches->size(), [&](size_t i, int) {
    const Patch& p = (*patches)[i];
    const Eigen::Vector3d center = p.center.cast<double>();
    const double rho = NeighbourDistance(views, p, rho_pixels);
    int total = 0, neighbours = 0;
    for (int image : p.images) {
      int x, y;
      if (!CellOfPatch(views[image], *grids, image, center, &x, &y)) continue;
      for (int ny = std::max(0, y - 1); ny <= std::min(grids->rows(image) - 1, y + 1); ++ny) {
        for (int nx = std::max(0, x - 1); nx <= std::min(grids->cols(image) - 1, x + 1); ++nx) {
          grids->ForEach(image, nx, ny, [&](int q_id) {
            if (q_id == static_cast<int>(i)) return;
            ++total;
            if (AreNeighbours(p, (*patches)[q_id], rho)) ++neighbours;
          });
        }
      }
    }
    if (neighbours == 0 || neighbours < kMinNeighbourFraction * total) keep[i] = 0;
  });
  removed += Compact(keep, patches, grids);
  return removed;
}

}  // namespace reconar
