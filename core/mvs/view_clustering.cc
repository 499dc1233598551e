#include "core/mvs/view_clustering.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "core/base/median.h"

namespace reconar {
namespace {

// Per sparse point: the registered images that see it, and those that see it well (local ids).
struct PointViews {
  std::vector<int> views;  // ascending
  std::vector<int> good;   // subset of views, ascending
};

using Graph = Eigen::MatrixXd;  // symmetric weights over local image ids, zero diagonal

std::vector<std::vector<int>> ConnectedComponents(const Graph& w, const std::vector<int>& nodes) {
  std::vector<std::vector<int>> components;
  std::vector<char> seen(nodes.size(), 0);
  for (size_t start = 0; start < nodes.size(); ++start) {
    if (seen[start]) continue;
    std::vector<int> component;
    std::vector<size_t> stack = {start};
    seen[start] = 1;
    while (!stack.empty()) {
      const size_t a = stack.back();
      stack.pop_back();
      component.push_back(nodes[a]);
      for (size_t b = 0; b < nodes.size(); ++b) {
        if (!seen[b] && w(nodes[a], nodes[b]) > 0.0) {
          seen[b] = 1;
          stack.push_back(b);
        }
      }
    }
    std::sort(component.begin(), component.end());
    components.push_back(std::move(component));
  }
  return components;
}

// Normalised-cut bisection of a connected node set (Shi & Malik 2000): the second eigenvector of
// D^-1/2 W D^-1/2, mapped by D^-1/2, swept for the lowest Ncut with each side >= n/4.
std::pair<std::vector<int>, std::vector<int>> Bisect(const Graph& w, const std::vector<int>& nodes) {
  const int n = static_cast<int>(nodes.size());
  Eigen::MatrixXd sub(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) sub(a, b) = w(nodes[a], nodes[b]);
  }
  const Eigen::VectorXd degree = sub.rowwise().sum();
  const Eigen::VectorXd inv_sqrt = degree.unaryExpr([](double d) { return d > 0.0 ? 1.0 / std::sqrt(d) : 0.0; });
  const Eigen::MatrixXd normalized = inv_sqrt.asDiagonal() * sub * inv_sqrt.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(normalized);
  const Eigen::VectorXd fiedler = inv_sqrt.asDiagonal() * solver.eigenvectors().col(n - 2);
  std::vector<int> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return fiedler(a) < fiedler(b); });

  const double total = degree.sum();
  const int min_side = std::max(1, (n + 3) / 4);
  std::vector<char> in_first(static_cast<size_t>(n), 0);
  double cut = 0.0, volume_first = 0.0, best = std::numeric_limits<double>::infinity();
  int best_split = n / 2;
  for (int k = 1; k < n; ++k) {
    const int moved = order[static_cast<size_t>(k - 1)];
    // Moving `moved` into the first side: its edges to the first side leave the cut, the others join.
    double to_first = 0.0;
    for (int b = 0; b < n; ++b) to_first += in_first[static_cast<size_t>(b)] ? sub(moved, b) : 0.0;
    cut += degree(moved) - 2.0 * to_first;
    in_first[static_cast<size_t>(moved)] = 1;
    volume_first += degree(moved);
    if (k < min_side || n - k < min_side) continue;
    const double volume_second = total - volume_first;
    const double ncut = (volume_first > 0.0 ? cut / volume_first : 1.0) + (volume_second > 0.0 ? cut / volume_second : 1.0);
    if (ncut < best - 1e-12) {
      best = ncut;
      best_split = k;
    }
  }
  std::vector<int> first, second;
  for (int k = 0; k < n; ++k) (k < best_split ? first : second).push_back(nodes[static_cast<size_t>(order[static_cast<size_t>(k)])]);
  std::sort(first.begin(), first.end());
  std::sort(second.begin(), second.end());
  return {first, second};
}

void SplitUntilBounded(const Graph& w, const std::vector<int>& nodes, int max_size,
                       std::vector<std::vector<int>>* parts) {
  for (std::vector<int>& component : ConnectedComponents(w, nodes)) {
    if (static_cast<int>(component.size()) <= max_size) {
      parts->push_back(std::move(component));
      continue;
    }
    auto [first, second] = Bisect(w, component);
    SplitUntilBounded(w, first, max_size, parts);
    SplitUntilBounded(w, second, max_size, parts);
  }
}

// The fallback without sparse points: camera-geometry weights, bounded parts, overlap growth.
ViewClustering ClusterByCameras(const Reconstruction& rec, const std::vector<int>& registered,
                                const ViewClusteringOptions& options) {
  const int n = static_cast<int>(registered.size());
  std::vector<Eigen::Vector3d> centres, axes;
  for (int id : registered) {
    const Rigid3& pose = rec.images[static_cast<size_t>(id)].cam_from_world;
    centres.push_back(CameraCenterInWorld(pose));
    axes.push_back(pose.rotation.row(2).transpose());
  }
  std::vector<double> nearest;
  for (int a = 0; a < n; ++a) {
    double best = std::numeric_limits<double>::infinity();
    for (int b = 0; b < n; ++b) {
      if (a != b) best = std::min(best, (centres[a] - centres[b]).norm());
    }
    if (std::isfinite(best) && best > 0.0) nearest.push_back(best);
  }
  double spacing = 1.0;
  if (!nearest.empty()) {
    spacing = MedianInPlace(nearest.data(), nearest.size());
  }
  const double sigma = 2.0 * spacing;
  const double min_cos = std::cos(options.max_view_angle);
  Graph w = Graph::Zero(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const double cosine = axes[a].dot(axes[b]);
      if (cosine <= min_cos) continue;
      const double d2 = (centres[a] - centres[b]).squaredNorm();
      w(a, b) = w(b, a) = std::exp(-d2 / (2.0 * sigma * sigma)) * cosine;
    }
  }
  ViewClustering result;
  result.from_camera_geometry = true;
  result.kept_images = registered;
  std::vector<int> all(static_cast<size_t>(n));
  std::iota(all.begin(), all.end(), 0);
  std::vector<std::vector<int>> parts;
  if (n <= options.max_cluster_size) {
    parts.push_back(all);
  } else {
    SplitUntilBounded(w, all, std::max(2, options.max_cluster_size * 3 / 4), &parts);
  }
  for (std::vector<int>& part : parts) {
    std::vector<char> member(static_cast<size_t>(n), 0);
    for (int a : part) member[static_cast<size_t>(a)] = 1;
    // Grow in rings: each round takes every outside image whose strongest edge into the part is
    // within half of the best such edge (both ends of an arc alike), strongest first.
    while (static_cast<int>(part.size()) < options.max_cluster_size) {
      std::vector<std::pair<double, int>> frontier;  // (strongest edge into the part, image)
      double best = 1e-3;  // below this an image shares (almost) nothing with the part
      for (int b = 0; b < n; ++b) {
        if (member[static_cast<size_t>(b)]) continue;
        double strongest = 0.0;
        for (int a : part) strongest = std::max(strongest, w(a, b));
        if (strongest > 1e-3) frontier.emplace_back(strongest, b);
        best = std::max(best, strongest);
      }
      if (frontier.empty()) break;
      std::stable_sort(frontier.begin(), frontier.end(),
                       [](const auto& x, const auto& y) { return x.first > y.first; });
      for (const auto& [strongest, b] : frontier) {
        if (strongest < 0.5 * best || static_cast<int>(part.size()) >= options.max_cluster_size) break;
        member[static_cast<size_t>(b)] = 1;
        part.push_back(b);
      }
    }
    std::vector<int> cluster;
    for (int a : part) cluster.push_back(registered[static_cast<size_t>(a)]);
    std::sort(cluster.begin(), cluster.end());
    result.clusters.push_back(std::move(cluster));
  }
  return result;
}

}  // namespace

Status ViewClusteringOptions::Check() const {
  if (min_views_per_point < 2) return InvalidArgument("view clustering: min_views_per_point must be >= 2");
  if (max_cluster_size < min_views_per_point) {
    return InvalidArgument("view clustering: max_cluster_size (" + std::to_string(max_cluster_size) +
                           ") must be >= min_views_per_point (" + std::to_string(min_views_per_point) + ")");
  }
  if (!(coverage_ratio >= 0.0 && coverage_ratio <= 1.0)) {
    return InvalidArgument("view clustering: coverage_ratio must be in [0, 1]");
  }
  if (!(resolution_ratio > 0.0 && resolution_ratio <= 1.0)) {
    return InvalidArgument("view clustering: resolution_ratio must be in (0, 1]");
  }
  if (!(max_view_angle > 0.0 && max_view_angle <= M_PI)) {
    return InvalidArgument("view clustering: max_view_angle must be in (0, pi]");
  }
  return Status::Ok();
}

Result<ViewClustering> ClusterViews(const Reconstruction& rec, const ViewClusteringOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  // Local ids 0..n-1 over the registered images with a usable camera.
  std::vector<int> registered;
  std::vector<int> local_of(rec.images.size(), -1);
  for (size_t i = 0; i < rec.images.size(); ++i) {
    const SfmImage& image = rec.images[i];
    if (!image.registered || image.camera_id < 0 || static_cast<size_t>(image.camera_id) >= rec.cameras.size()) {
      continue;
    }
    local_of[i] = static_cast<int>(registered.size());
    registered.push_back(static_cast<int>(i));
  }
  if (registered.empty()) return FailedPrecondition("view clustering: the model has no registered image");
  const int n = static_cast<int>(registered.size());

  // Visibility and resolution of every sparse point.
  std::vector<PointViews> points;
  std::vector<double> resolution_sum(static_cast<size_t>(n), 0.0);
  std::vector<int> resolution_count(static_cast<size_t>(n), 0);
  for (const SfmPoint& point : rec.points) {
    if (point.deleted) continue;
    std::vector<std::pair<int, double>> seen;  // (local id, resolution)
    for (const TrackElement& element : point.track) {
      if (element.image_id < 0 || static_cast<size_t>(element.image_id) >= rec.images.size()) continue;
      const int local = local_of[static_cast<size_t>(element.image_id)];
      if (local < 0) continue;
      const SfmImage& image = rec.images[static_cast<size_t>(element.image_id)];
      const double depth = (image.cam_from_world * point.position).z();
      if (!(depth > 0.0)) continue;
      seen.emplace_back(local, rec.cameras[static_cast<size_t>(image.camera_id)].focal / depth);
    }
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
               seen.end());
    if (seen.size() < 2) continue;
    double best = 0.0;
    for (const auto& [local, res] : seen) best = std::max(best, res);
    PointViews views;
    for (const auto& [local, res] : seen) {
      views.views.push_back(local);
      if (res >= options.resolution_ratio * best) views.good.push_back(local);
      resolution_sum[static_cast<size_t>(local)] += res;
      ++resolution_count[static_cast<size_t>(local)];
    }
    points.push_back(std::move(views));
  }
  if (points.empty()) return ClusterByCameras(rec, registered, options);

  ViewClustering result;
  result.points_considered = static_cast<int>(points.size());
  const int m = options.min_views_per_point;
  std::vector<std::vector<int>> good_points_of(static_cast<size_t>(n));
  for (size_t p = 0; p < points.size(); ++p) {
    for (int local : points[p].good) good_points_of[static_cast<size_t>(local)].push_back(static_cast<int>(p));
  }

  // 1. Redundant images, from the lowest mean resolution up.
  std::vector<char> kept(static_cast<size_t>(n), 1);
  if (options.remove_redundant) {
    std::vector<int> good_kept(points.size());
    for (size_t p = 0; p < points.size(); ++p) good_kept[p] = static_cast<int>(points[p].good.size());
    std::vector<int> order(static_cast<size_t>(n));
    std::iota(order.begin(), order.end(), 0);
    const auto mean_resolution = [&](int a) {
      return resolution_count[static_cast<size_t>(a)] > 0
                 ? resolution_sum[static_cast<size_t>(a)] / resolution_count[static_cast<size_t>(a)]
                 : 0.0;
    };
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return mean_resolution(a) < mean_resolution(b); });
    for (int a : order) {
      bool removable = true;
      for (int p : good_points_of[static_cast<size_t>(a)]) {
        const int need = std::min(m, static_cast<int>(points[static_cast<size_t>(p)].good.size()));
        if (good_kept[static_cast<size_t>(p)] - 1 < need) {
          removable = false;
          break;
        }
      }
      if (!removable) continue;
      kept[static_cast<size_t>(a)] = 0;
      for (int p : good_points_of[static_cast<size_t>(a)]) --good_kept[static_cast<size_t>(p)];
    }
  }
  std::vector<int> kept_local;
  for (int a = 0; a < n; ++a) {
    (kept[static_cast<size_t>(a)] ? result.kept_images : result.removed_images).push_back(registered[static_cast<size_t>(a)]);
    if (kept[static_cast<size_t>(a)]) kept_local.push_back(a);
  }

  // Per point, the kept views that count for coverage and how many of them a cluster needs.
  std::vector<std::vector<int>> candidates(points.size());
  std::vector<int> need(points.size(), 0);
  std::vector<std::vector<int>> points_of(static_cast<size_t>(n));  // coverage-relevant points per kept image
  for (size_t p = 0; p < points.size(); ++p) {
    std::vector<int> good, all;
    for (int a : points[p].good) {
      if (kept[static_cast<size_t>(a)]) good.push_back(a);
    }
    for (int a : points[p].views) {
      if (kept[static_cast<size_t>(a)]) all.push_back(a);
    }
    candidates[p] = good.size() >= 2 ? good : all;
    if (candidates[p].size() < 2) continue;
    need[p] = std::min(m, static_cast<int>(candidates[p].size()));
    for (int a : all) points_of[static_cast<size_t>(a)].push_back(static_cast<int>(p));
  }

  // 2. View graph over kept images: shared sparse points.
  Graph w = Graph::Zero(n, n);
  for (size_t p = 0; p < points.size(); ++p) {
    const std::vector<int>& views = points[p].views;
    for (size_t i = 0; i < views.size(); ++i) {
      if (!kept[static_cast<size_t>(views[i])]) continue;
      for (size_t j = i + 1; j < views.size(); ++j) {
        if (!kept[static_cast<size_t>(views[j])]) continue;
        w(views[i], views[j]) += 1.0;
        w(views[j], views[i]) += 1.0;
      }
    }
  }
  std::vector<std::vector<int>> clusters;  // local ids, ascending
  SplitUntilBounded(w, kept_local, options.max_cluster_size, &clusters);

  // 3. Coverage: add images until every kept image has coverage_ratio of its points covered.
  std::vector<std::vector<int>> candidate_points_of(static_cast<size_t>(n));
  for (size_t p = 0; p < points.size(); ++p) {
    if (need[p] == 0) continue;
    for (int a : candidates[p]) candidate_points_of[static_cast<size_t>(a)].push_back(static_cast<int>(p));
  }
  std::vector<std::vector<char>> member;  // per cluster, per local image
  const auto count_in = [&](size_t c, size_t p) {
    int k = 0;
    for (int a : candidates[p]) k += member[c][static_cast<size_t>(a)];
    return k;
  };
  std::vector<char> covered(points.size(), 0);
  const auto add_cluster = [&](const std::vector<int>& cluster) {
    member.emplace_back(static_cast<size_t>(n), 0);
    for (int a : cluster) member.back()[static_cast<size_t>(a)] = 1;
    for (size_t p = 0; p < points.size(); ++p) {
      if (need[p] > 0 && !covered[p] && count_in(member.size() - 1, p) >= need[p]) covered[p] = 1;
    }
  };
  for (const std::vector<int>& cluster : clusters) add_cluster(cluster);
  const auto add_image = [&](size_t c, int a) {
    clusters[c].insert(std::upper_bound(clusters[c].begin(), clusters[c].end(), a), a);
    member[c][static_cast<size_t>(a)] = 1;
    for (int p : candidate_points_of[static_cast<size_t>(a)]) {
      if (!covered[static_cast<size_t>(p)] && count_in(c, static_cast<size_t>(p)) >= need[static_cast<size_t>(p)]) {
        covered[static_cast<size_t>(p)] = 1;
      }
    }
  };
  const auto num_covered = [&] { return static_cast<int>(std::count(covered.begin(), covered.end(), 1)); };
  std::vector<char> hopeless(static_cast<size_t>(n), 0);
  const int max_rounds = 4 * n * (n + 1);  // a round adds an image to a cluster or gives one image up
  for (int round = 0; round < max_rounds; ++round) {
    // Deficient images and the uncovered points that matter to them.
    std::vector<char> is_wanted(points.size(), 0);
    int worst = -1;
    double worst_ratio = 2.0;
    for (int a : kept_local) {
      const std::vector<int>& mine = points_of[static_cast<size_t>(a)];
      if (mine.empty() || hopeless[static_cast<size_t>(a)]) continue;
      int done = 0;
      for (int p : mine) done += covered[static_cast<size_t>(p)];
      const double ratio = static_cast<double>(done) / static_cast<double>(mine.size());
      if (ratio >= options.coverage_ratio) continue;
      for (int p : mine) is_wanted[static_cast<size_t>(p)] |= !covered[static_cast<size_t>(p)];
      if (ratio < worst_ratio) {
        worst_ratio = ratio;
        worst = a;
      }
    }
    if (worst < 0) break;
    std::vector<int> wanted;
    for (size_t p = 0; p < points.size(); ++p) {
      if (is_wanted[p]) wanted.push_back(static_cast<int>(p));
    }
    // Best single addition to a cluster with room: the image that completes most wanted points.
    size_t best_cluster = 0;
    int best_image = -1, best_gain = 0;
    std::vector<int> gain(static_cast<size_t>(n));
    for (size_t c = 0; c < clusters.size(); ++c) {
      if (static_cast<int>(clusters[c].size()) >= options.max_cluster_size) continue;
      std::fill(gain.begin(), gain.end(), 0);
      for (int p : wanted) {
        if (count_in(c, static_cast<size_t>(p)) != need[static_cast<size_t>(p)] - 1) continue;
        for (int a : candidates[static_cast<size_t>(p)]) gain[static_cast<size_t>(a)] += 1 - member[c][static_cast<size_t>(a)];
      }
      for (int a = 0; a < n; ++a) {
        if (gain[static_cast<size_t>(a)] > best_gain) {
          best_gain = gain[static_cast<size_t>(a)];
          best_image = a;
          best_cluster = c;
        }
      }
    }
    if (best_image >= 0) {
      add_image(best_cluster, best_image);
      continue;
    }
    // No cluster with room helps: a new cluster around the worst-covered image, with the images
    // that share most of its uncovered points.
    std::vector<int> shared(static_cast<size_t>(n), 0);
    for (int p : points_of[static_cast<size_t>(worst)]) {
      if (covered[static_cast<size_t>(p)]) continue;
      for (int a : candidates[static_cast<size_t>(p)]) ++shared[static_cast<size_t>(a)];
    }
    std::vector<int> order;
    for (int a : kept_local) {
      if (a != worst && shared[static_cast<size_t>(a)] > 0) order.push_back(a);
    }
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return shared[static_cast<size_t>(a)] > shared[static_cast<size_t>(b)]; });
    std::vector<int> fresh = {worst};
    for (int a : order) {
      if (static_cast<int>(fresh.size()) >= options.max_cluster_size) break;
      fresh.push_back(a);
    }
    std::sort(fresh.begin(), fresh.end());
    const int before = num_covered();
    clusters.push_back(fresh);
    add_cluster(fresh);
    if (num_covered() == before) {  // nothing gained: this image cannot reach the ratio
      hopeless[static_cast<size_t>(worst)] = 1;
      clusters.pop_back();
      member.pop_back();
    }
  }

  int covered_points = 0, relevant = 0;
  for (size_t p = 0; p < points.size(); ++p) {
    if (need[p] == 0) continue;
    ++relevant;
    covered_points += covered[p];
  }
  result.covered_fraction = relevant > 0 ? static_cast<double>(covered_points) / relevant : 0.0;
  for (const std::vector<int>& cluster : clusters) {
    std::vector<int> ids;
    for (int a : cluster) ids.push_back(registered[static_cast<size_t>(a)]);
    result.clusters.push_back(std::move(ids));
  }
  return result;
}

}  // namespace reconar
