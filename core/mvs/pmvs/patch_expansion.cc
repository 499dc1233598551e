#include "core/mvs/pmvs/patch_expansion.h"

#include <cmath>

#include "core/mvs/pmvs/patch_refiner.h"

namespace reconar {
namespace {

struct Hypothesis {
  int parent;
  int image;
  int cell_x, cell_y;
};

}  // namespace

size_t ExpandPatches(const std::vector<PmvsView>& views, const PatchMvsOptions& options, std::vector<int> seeds,
                     ThreadPool* pool, std::vector<Patch>* patches, PatchCellGrids* grids) {
  const int num_views = static_cast<int>(views.size());
  const int cell_size = grids->cell_size();
  // Cells already proposed during this call: each cell is tried at most once, which bounds the
  // work and ends the waves.
  std::vector<std::vector<uint8_t>> proposed(num_views);
  for (int i = 0; i < num_views; ++i) proposed[i].assign(static_cast<size_t>(grids->cols(i)) * grids->rows(i), 0);
  std::vector<PatchRefiner> refiners;
  for (int w = 0; w < pool->num_threads(); ++w) refiners.emplace_back(views, options);

  std::vector<Hypothesis> hypotheses;
  std::vector<Patch> results;
  std::vector<uint8_t> accepted;
  size_t added = 0;
  while (!seeds.empty()) {
    hypotheses.clear();
    for (int id : seeds) {
      const Patch& p = (*patches)[id];
      const Eigen::Vector3d center = p.center.cast<double>();
      for (int image : p.images) {
        int x, y;
        if (!grids->CellOf(image, views[image].Project(center), &x, &y)) continue;
        static constexpr int kSteps[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
        for (const auto& step : kSteps) {
          const int nx = x + step[0], ny = y + step[1];
          if (nx < 0 || ny < 0 || nx >= grids->cols(image) || ny >= grids->rows(image)) continue;
          uint8_t& mark = proposed[image][static_cast<size_t>(ny) * grids->cols(image) + nx];
          if (mark || !grids->Empty(image, nx, ny)) continue;
          mark = 1;
          hypotheses.push_back({id, image, nx, ny});
        }
      }
    }
    results.resize(hypotheses.size());
    accepted.assign(hypotheses.size(), 0);
    pool->ParallelFor(0, hypotheses.size(), [&](size_t k, int worker) {
      const Hypothesis& h = hypotheses[k];
      const Patch& parent = (*patches)[h.parent];
      const PmvsView& view = views[h.image];
      const Eigen::Vector3d normal = parent.normal.cast<double>();
      const Eigen::Vector3d ray = view.RayDirection((h.cell_x + 0.5) * cell_size - 0.5, (h.cell_y + 0.5) * cell_size - 0.5);
      const double denominator = ray.dot(normal);
      if (std::abs(denominator) < 1e-12) return;
      const double s = (parent.center.cast<double>() - view.center).dot(normal) / denominator;
      if (!(s > 0.0)) return;
      const Eigen::Vector3d center = view.center + s * ray;
      accepted[k] = refiners[worker].Reconstruct(center, normal, parent.reference,
                                                   PatchRefiner::Hypothesis::kExpansion, &results[k]);
    });
    std::vector<int> next;
    for (size_t k = 0; k < hypotheses.size(); ++k) {
      const Hypothesis& h = hypotheses[k];
      if (!accepted[k] || !grids->Empty(h.image, h.cell_x, h.cell_y)) continue;
      patches->push_back(std::move(results[k]));
      results[k] = Patch();
      const int id = static_cast<int>(patches->size() - 1);
      grids->Insert(id, patches->back());
      next.push_back(id);
      ++added;
    }
    seeds.swap(next);
  }
  return added;
}

}  // namespace reconar
