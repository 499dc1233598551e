#include "core/mvs/patchmatch/view_selection.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <utility>

#include "core/base/thread_pool.h"

namespace reconar {
namespace {

bool InView(const DenseView& view, const Eigen::Vector3d& world_point) {
  const Eigen::Vector3d cam = view.cam_from_world * world_point;
  if (!(cam.z() > 0.0)) return false;
  const double u = view.fx * cam.x() / cam.z() + view.cx, v = view.fy * cam.y() / cam.z() + view.cy;
  return u >= -0.5 && v >= -0.5 && u < view.width() - 0.5 && v < view.height() - 0.5;
}

double Quantile(std::vector<double>* values, double q) {
  const size_t k = std::min(values->size() - 1, static_cast<size_t>(q * static_cast<double>(values->size())));
  std::nth_element(values->begin(), values->begin() + static_cast<ptrdiff_t>(k), values->end());
  return (*values)[k];
}

// The point nearest, in the least-squares sense, to the optical axes of all views: where an
// object-centred capture looks. False when the axes are (nearly) parallel or the point is behind
// a camera.
bool AxesMeetingPoint(const std::vector<const DenseView*>& views, Eigen::Vector3d* point) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const DenseView* view : views) {
    const Eigen::Vector3d axis = view->OpticalAxis().normalized();
    const Eigen::Matrix3d off_axis = Eigen::Matrix3d::Identity() - axis * axis.transpose();
    a += off_axis;
    b += off_axis * view->Center();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(a);
  if (eigen.info() != Eigen::Success || !(eigen.eigenvalues()(0) > 1e-3 * eigen.eigenvalues()(2))) return false;
  *point = a.ldlt().solve(b);
  for (const DenseView* view : views) {
    if (!(view->Depth(*point) > 0.0)) return false;
  }
  return point->allFinite();
}

// Without sparse points in a view: its depth range around the depth of the point its cluster
// looks at (AxesMeetingPoint), from half to one and a half times it, and as sources the views whose
// angle to it, seen from that point, lies in the allowed range, nearest first.
void SetUpFromCameraGeometry(const std::vector<const DenseView*>& views, size_t v, const Eigen::Vector3d& target,
                             const PatchMatchOptions& options, PatchMatchViewSetup* setup) {
  const double depth = views[v]->Depth(target);
  setup->depth_min = 0.5 * depth;
  setup->depth_max = 1.5 * depth;
  const double min_angle = options.min_triangulation_angle_deg * M_PI / 180.0;
  const double max_angle = options.max_triangulation_angle_deg * M_PI / 180.0;
  const Eigen::Vector3d ray = (views[v]->Center() - target).normalized();
  std::vector<std::pair<double, int>> candidates;
  for (size_t w = 0; w < views.size(); ++w) {
    if (w == v) continue;
    const double angle = std::acos(std::clamp(ray.dot((views[w]->Center() - target).normalized()), -1.0, 1.0));
    if (angle >= min_angle && angle <= max_angle) candidates.emplace_back(angle, static_cast<int>(w));
  }
  std::sort(candidates.begin(), candidates.end());
  for (size_t k = 0; k < candidates.size() && static_cast<int>(k) < options.max_source_views; ++k) {
    setup->sources.push_back(candidates[k].second);
  }
  setup->valid = !setup->sources.empty();
}

}  // namespace

std::vector<PatchMatchViewSetup> SetUpPatchMatchViews(const std::vector<const DenseView*>& views,
                                                      const std::vector<Eigen::Vector3d>& sparse_points,
                                                      const PatchMatchOptions& options, ThreadPool* pool) {
  const size_t num_views = views.size();
  // in_view[v][i]: point i projects into view v.
  std::vector<std::vector<char>> in_view(num_views, std::vector<char>(sparse_points.size(), 0));
  std::vector<Eigen::Vector3d> centers(num_views);
  for (size_t v = 0; v < num_views; ++v) centers[v] = views[v]->Center();
  pool->ParallelFor(0, num_views, [&](size_t v, int) {
    for (size_t i = 0; i < sparse_points.size(); ++i) in_view[v][i] = InView(*views[v], sparse_points[i]) ? 1 : 0;
  });

  Eigen::Vector3d target;
  const bool have_target = AxesMeetingPoint(views, &target);
  std::vector<PatchMatchViewSetup> setups(num_views);
  const double min_angle = options.min_triangulation_angle_deg * M_PI / 180.0;
  const double max_angle = options.max_triangulation_angle_deg * M_PI / 180.0;
  pool->ParallelFor(0, num_views, [&](size_t v, int) {
    PatchMatchViewSetup& setup = setups[v];
    std::vector<double> depths;
    for (size_t i = 0; i < sparse_points.size(); ++i) {
      if (in_view[v][i]) depths.push_back(views[v]->Depth(sparse_points[i]));
    }
    if (depths.empty() || static_cast<int>(depths.size()) < options.min_range_points) {
      if (have_target) SetUpFromCameraGeometry(views, v, target, options, &setup);
      return;
    }
    const double low = Quantile(&depths, options.depth_percentile);
    const double high = Quantile(&depths, 1.0 - options.depth_percentile);
    setup.depth_min = std::max(low * (1.0 - options.depth_margin), 1e-6 * high);
    setup.depth_max = high * (1.0 + options.depth_margin);
    if (!(setup.depth_max > setup.depth_min) || !std::isfinite(setup.depth_max)) return;

    struct Candidate {
      int view;
      size_t shared;
    };
    std::vector<Candidate> candidates;
    std::vector<double> angles;
    for (size_t w = 0; w < num_views; ++w) {
      if (w == v) continue;
      angles.clear();
      for (size_t i = 0; i < sparse_points.size(); ++i) {
        if (!in_view[v][i] || !in_view[w][i]) continue;
        const Eigen::Vector3d a = centers[v] - sparse_points[i], b = centers[w] - sparse_points[i];
        const double denominator = a.norm() * b.norm();
        if (!(denominator > 0.0)) continue;
        angles.push_back(std::acos(std::clamp(a.dot(b) / denominator, -1.0, 1.0)));
      }
      if (angles.empty()) continue;
      const double median = Quantile(&angles, 0.5);
      if (median >= min_angle && median <= max_angle) candidates.push_back({static_cast<int>(w), angles.size()});
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& a, const Candidate& b) { return a.shared > b.shared; });
    for (size_t k = 0; k < candidates.size() && static_cast<int>(k) < options.max_source_views; ++k) {
      setup.sources.push_back(candidates[k].view);
    }
    setup.valid = !setup.sources.empty();
  });
  return setups;
}

}  // namespace reconar
