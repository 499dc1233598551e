#include "core/mvs/pmvs/initial_matching.h"

#include <algorithm>
#include <cmath>

#include "core/geometry/triangulation.h"
#include "core/mvs/pmvs/patch_refiner.h"
#include "core/mvs/pmvs/patch_sampler.h"

namespace reconar {
namespace {

constexpr double kEpipolarDistance = 2.0;  // pixels (PMVS)
constexpr int kBucketSize = 32;            // pixels per side of a feature bucket

// Features of one image bucketed into kBucketSize cells for the epipolar search.
struct FeatureBuckets {
  int cols = 0, rows = 0;
  std::vector<int> start;  // cols * rows + 1 offsets into order
  std::vector<int> order;  // feature indices sorted by bucket

  FeatureBuckets(const std::vector<SeedFeature>& features, int width, int height)
      : cols((width + kBucketSize - 1) / kBucketSize), rows((height + kBucketSize - 1) / kBucketSize) {
    start.assign(static_cast<size_t>(cols) * rows + 1, 0);
    std::vector<int> bucket(features.size());
    for (size_t i = 0; i < features.size(); ++i) {
      const int bx = std::clamp(static_cast<int>(features[i].x) / kBucketSize, 0, cols - 1);
      const int by = std::clamp(static_cast<int>(features[i].y) / kBucketSize, 0, rows - 1);
      bucket[i] = by * cols + bx;
      ++start[bucket[i] + 1];
    }
    for (size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
    order.resize(features.size());
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (size_t i = 0; i < features.size(); ++i) order[fill[bucket[i]]++] = static_cast<int>(i);
  }

  // Calls fn(feature index) for the features in buckets that the band of half-width `distance`
  // around the line l (homogeneous, a x + b y + c = 0) crosses; fn tests the exact distance.
  template <typename Fn>
  void ForEachNearLine(const Eigen::Vector3d& l, double distance, Fn&& fn) const {
    const double norm = std::hypot(l.x(), l.y());
    if (!(norm > 0.0)) return;
    const bool walk_x = std::abs(l.y()) >= std::abs(l.x());  // the line is closer to horizontal
    const int major_count = walk_x ? cols : rows, minor_count = walk_x ? rows : cols;
    const double a = walk_x ? l.x() : l.y(), b = walk_x ? l.y() : l.x();
    // Along the major axis: minor = -(a * major + c) / b, band half-width distance * norm / |b|.
    const double band = distance * norm / std::abs(b) + 1.0;
    for (int m = 0; m < major_count; ++m) {
      const double m0 = m * kBucketSize - 0.5, m1 = (m + 1) * kBucketSize - 0.5;
      const double v0 = -(a * m0 + l.z()) / b, v1 = -(a * m1 + l.z()) / b;
      const int lo = std::max(0, static_cast<int>(std::floor((std::min(v0, v1) - band) / kBucketSize)));
      const int hi = std::min(minor_count - 1, static_cast<int>(std::floor((std::max(v0, v1) + band) / kBucketSize)));
      for (int n = lo; n <= hi; ++n) {
        const int bucket = walk_x ? n * cols + m : m * cols + n;
        for (int k = start[bucket]; k < start[bucket + 1]; ++k) fn(order[k]);
      }
    }
  }
};

struct Candidate {
  Eigen::Vector3d point;
  double distance;  // from the reference camera centre
};

}  // namespace

size_t MatchSeedFeatures(const std::vector<PmvsView>& views, const std::vector<std::vector<SeedFeature>>& features,
                         const PatchMvsOptions& options, ThreadPool* pool, std::vector<Patch>* patches,
                         PatchCellGrids* grids) {
  const int num_views = static_cast<int>(views.size());
  std::vector<FeatureBuckets> buckets;
  for (int i = 0; i < num_views; ++i) buckets.emplace_back(features[i], views[i].width, views[i].height);
  const std::vector<std::vector<int>> neighbours = NeighbourViews(views, M_PI / 3.0);
  std::vector<std::vector<Patch>> found(num_views);
  const float pair_threshold = static_cast<float>(options.min_ncc - 0.3);
  const int cell_size = options.cell_size;

  pool->ParallelFor(0, num_views, [&](size_t index, int) {
    const int ref_id = static_cast<int>(index);
    const PmvsView& ref = views[ref_id];
    PatchRefiner refiner(views, options);
    PatchSampler sampler(views, options.patch_size, options.MinTextureStd());
    const int cols = (ref.width + cell_size - 1) / cell_size, rows = (ref.height + cell_size - 1) / cell_size;
    std::vector<uint8_t> occupied(static_cast<size_t>(cols) * rows, 0);
    std::vector<Candidate> candidates;
    Patch patch;
    for (const SeedFeature& f : features[ref_id]) {
      const int fx = std::min(cols - 1, static_cast<int>((f.x + 0.5f) / cell_size));
      const int fy = std::min(rows - 1, static_cast<int>((f.y + 0.5f) / cell_size));
      if (occupied[static_cast<size_t>(fy) * cols + fx]) continue;
      const Eigen::Vector2d x_ref(f.x, f.y);
      const Eigen::Vector3d ray = ref.RayDirection(f.x, f.y);
      candidates.clear();
      for (int other : neighbours[ref_id]) {
        const PmvsView& view = views[other];
        const Eigen::Vector3d epipole = view.ProjectHomogeneous(ref.center);
        const Eigen::Vector3d vanishing = view.projection.leftCols<3>() * ray;
        const Eigen::Vector3d line = epipole.cross(vanishing);
        const double line_norm = std::hypot(line.x(), line.y());
        buckets[other].ForEachNearLine(line, kEpipolarDistance, [&](int k) {
          const SeedFeature& g = features[other][k];
          if (g.type != f.type) return;
          if (std::abs(line.dot(Eigen::Vector3d(g.x, g.y, 1.0))) > kEpipolarDistance * line_norm) return;
          Eigen::Vector3d point;
          if (!TriangulatePoint(ref.projection, view.projection, x_ref, Eigen::Vector2d(g.x, g.y), &point)) return;
          if (!(ref.Depth(point) > 0.0) || !(view.Depth(point) > 0.0)) return;
          // Cheap screen: the fronto-parallel patch must already correlate between I and J.
          const Eigen::Vector3d normal = (ref.center - point).normalized();
          if (!sampler.SetPatch(point, normal, ref_id) || sampler.Ncc(other) < pair_threshold) return;
          candidates.push_back({point, (point - ref.center).norm()});
        });
      }
      std::sort(candidates.begin(), candidates.end(),
                [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
      for (const Candidate& c : candidates) {
        if (!refiner.Reconstruct(c.point, (ref.center - c.point).normalized(), ref_id,
                                PatchRefiner::Hypothesis::kFeatureMatch, &patch)) continue;
        found[ref_id].push_back(patch);
        int px, py;
        const Eigen::Vector2d pixel = ref.Project(patch.center.cast<double>());
        if (grids->CellOf(ref_id, pixel, &px, &py)) occupied[static_cast<size_t>(py) * cols + px] = 1;
        occupied[static_cast<size_t>(fy) * cols + fx] = 1;
        break;
      }
    }
  });

  size_t added = 0;
  for (int i = 0; i < num_views; ++i) {
    for (Patch& p : found[i]) {
      int x, y;
      if (!grids->CellOf(p.reference, views[p.reference].Project(p.center.cast<double>()), &x, &y)) continue;
      const double rho = NeighbourDistance(views, p, cell_size);
      bool duplicate = false;
      grids->ForEach(p.reference, x, y, [&](int q) { duplicate = duplicate || AreNeighbours(p, (*patches)[q], rho); });
      if (duplicate) continue;
      patches->push_back(std::move(p));
      grids->Insert(static_cast<int>(patches->size() - 1), patches->back());
      ++added;
    }
  }
  return added;
}

}  // namespace reconar
