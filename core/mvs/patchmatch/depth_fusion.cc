#include "core/mvs/patchmatch/depth_fusion.h"

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>

#include "core/base/elapsed.h"
#include "core/base/thread_pool.h"

namespace reconar {
namespace {

class DepthMapChecker {
 public:
  DepthMapChecker(const std::vector<const DenseView*>& views, const std::vector<DepthMap>& maps,
                  const PatchMatchOptions& options)
      : views_(views), maps_(maps), options_(options) {
    cos_max_normal_ = std::cos(options.fusion_max_normal_deg * M_PI / 180.0);
    max_reprojection_squared_ = options.fusion_max_reprojection_px * options.fusion_max_reprojection_px;
    cos_max_view_angle_ = std::cos(options.max_view_angle_deg * M_PI / 180.0);
  }

  // A depth below max_cost whose plane faces the view within max_view_angle_deg.
  bool Valid(int v, size_t i) const {
    const DepthMap& m = maps_[static_cast<size_t>(v)];
    if (!(m.depth[i] > 0.0f && m.cost[i] <= options_.max_cost)) return false;
    const DenseView& view = *views_[static_cast<size_t>(v)];
    const int x = static_cast<int>(i % static_cast<size_t>(m.width)),
              y = static_cast<int>(i / static_cast<size_t>(m.width));
    const Eigen::Vector3d ray((x - view.cx) / view.fx, (y - view.cy) / view.fy, 1.0);
    return -m.Normal(i).cast<double>().dot(ray) >= cos_max_view_angle_ * ray.norm();
  }
  // World point and world normal of pixel (x, y) of view v.
  void PointAndNormal(int v, int x, int y, Eigen::Vector3d* point, Eigen::Vector3d* normal) const {
    const DenseView& view = *views_[static_cast<size_t>(v)];
    const DepthMap& m = maps_[static_cast<size_t>(v)];
    const size_t i = m.Index(x, y);
    const double z = m.depth[i];
    const Eigen::Vector3d cam(z * (x - view.cx) / view.fx, z * (y - view.cy) / view.fy, z);
    const Eigen::Matrix3d& r = view.cam_from_world.rotation;
    *point = r.transpose() * (cam - view.cam_from_world.translation);
    *normal = r.transpose() * m.Normal(i).cast<double>();
  }

  // Whether source view s agrees with (point, normal) seen at pixel (x, y) of view v; on success
  // the pixel of s that agrees.
  bool Agrees(int v, int x, int y, const Eigen::Vector3d& point, const Eigen::Vector3d& normal, int s,
              size_t* source_pixel, Eigen::Vector3d* source_point, Eigen::Vector3d* source_normal) const {
    const DepthMap& m = maps_[static_cast<size_t>(s)];
    if (m.empty()) return false;
    const DenseView& source = *views_[static_cast<size_t>(s)];
    const Eigen::Vector3d cam = source.cam_from_world * point;
    if (!(cam.z() > 0.0)) return false;
    const double u = source.fx * cam.x() / cam.z() + source.cx, w = source.fy * cam.y() / cam.z() + source.cy;
    if (!(u >= -0.5 && w >= -0.5 && u < m.width - 0.5 && w < m.height - 0.5)) return false;
    const int qx = static_cast<int>(std::lround(u)), qy = static_cast<int>(std::lround(w));
    const size_t q = m.Index(qx, qy);
    if (!Valid(s, q)) return false;
    const double depth = m.depth[q];
    if (!(std::abs(cam.z() - depth) <= options_.fusion_max_relative_depth * depth)) return false;
    PointAndNormal(s, qx, qy, source_point, source_normal);
    if (!(normal.dot(*source_normal) >= cos_max_normal_)) return false;
    const DenseView& view = *views_[static_cast<size_t>(v)];
    if (!(view.Depth(*source_point) > 0.0)) return false;
    const Eigen::Vector2d back = view.Project(*source_point) - Eigen::Vector2d(x, y);
    if (!(back.squaredNorm() <= max_reprojection_squared_)) return false;
    *source_pixel = q;
    return true;
  }

 private:
  const std::vector<const DenseView*>& views_;
  const std::vector<DepthMap>& maps_;
  const PatchMatchOptions& options_;
  double cos_max_normal_ = 1.0;
  double max_reprojection_squared_ = 0.0;
  double cos_max_view_angle_ = 0.0;
};

}  // namespace

OrientedPoints FuseDepthMaps(const std::vector<const DenseView*>& views, const std::vector<DepthMap>& maps,
                             const std::vector<std::vector<int>>& sources, const PatchMatchOptions& options,
                             ThreadPool* pool, DepthFusionStats* stats) {
  const DepthMapChecker checker(views, maps, options);
  const int num_views = static_cast<int>(views.size());

  // Consistency: per pixel, the number of agreeing sources (rows in parallel).
  auto start = std::chrono::steady_clock::now();
  std::vector<std::vector<uint8_t>> agreeing(static_cast<size_t>(num_views));
  std::vector<size_t> depth_pixels(static_cast<size_t>(num_views), 0), consistent(static_cast<size_t>(num_views), 0);
  for (int v = 0; v < num_views; ++v) {
    const DepthMap& m = maps[static_cast<size_t>(v)];
    if (m.empty()) continue;
    std::vector<uint8_t>& counts = agreeing[static_cast<size_t>(v)];
    counts.assign(m.depth.size(), 0);
    std::vector<size_t> row_depth(static_cast<size_t>(m.height), 0), row_consistent(static_cast<size_t>(m.height), 0);
    pool->ParallelFor(0, static_cast<size_t>(m.height), [&](size_t row, int) {
      const int y = static_cast<int>(row);
      for (int x = 0; x < m.width; ++x) {
        const size_t i = m.Index(x, y);
        if (!checker.Valid(v, i)) continue;
        ++row_depth[row];
        Eigen::Vector3d point, normal, source_point, source_normal;
        checker.PointAndNormal(v, x, y, &point, &normal);
        int count = 0;
        size_t q = 0;
        for (int s : sources[static_cast<size_t>(v)]) {
          if (checker.Agrees(v, x, y, point, normal, s, &q, &source_point, &source_normal)) ++count;
        }
        counts[i] = static_cast<uint8_t>(std::min(count, 255));
        if (count >= options.fusion_min_views) ++row_consistent[row];
      }
    });
    for (size_t y = 0; y < row_depth.size(); ++y) {
      depth_pixels[static_cast<size_t>(v)] += row_depth[y];
      consistent[static_cast<size_t>(v)] += row_consistent[y];
    }
  }
  stats->depth_pixels = 0;
  stats->consistent_pixels = 0;
  for (int v = 0; v < num_views; ++v) {
    stats->depth_pixels += depth_pixels[static_cast<size_t>(v)];
    stats->consistent_pixels += consistent[static_cast<size_t>(v)];
  }
  stats->seconds_consistency = SecondsSince(start);

  // Fusion, in view and pixel order (deterministic): a consistent pixel not used yet becomes a
  // point and uses up the agreeing source pixels.
  start = std::chrono::steady_clock::now();
  OrientedPoints out;
  std::vector<std::vector<uint8_t>> used(static_cast<size_t>(num_views));
  for (int v = 0; v < num_views; ++v) used[static_cast<size_t>(v)].assign(maps[static_cast<size_t>(v)].depth.size(), 0);
  for (int v = 0; v < num_views; ++v) {
    const DepthMap& m = maps[static_cast<size_t>(v)];
    const DenseView& view = *views[static_cast<size_t>(v)];
    const int step = options.fusion_pixel_step;
    for (int y = 0; y < m.height; y += step) {
      for (int x = 0; x < m.width; x += step) {
        const size_t i = m.Index(x, y);
        if (used[static_cast<size_t>(v)][i] || agreeing[static_cast<size_t>(v)][i] < options.fusion_min_views) continue;
        Eigen::Vector3d point, normal, source_point, source_normal;
        checker.PointAndNormal(v, x, y, &point, &normal);
        Eigen::Vector3d point_sum = point, normal_sum = normal;
        double cost_sum = m.cost[i];
        int members = 1;
        used[static_cast<size_t>(v)][i] = 1;
        for (int s : sources[static_cast<size_t>(v)]) {
          size_t q = 0;
          if (!checker.Agrees(v, x, y, point, normal, s, &q, &source_point, &source_normal)) continue;
          point_sum += source_point;
          normal_sum += source_normal;
          cost_sum += maps[static_cast<size_t>(s)].cost[q];
          ++members;
          used[static_cast<size_t>(s)][q] = 1;
        }
        const double normal_length = normal_sum.norm();
        if (!(normal_length > 0.0)) continue;
        out.positions.push_back((point_sum / members).cast<float>());
        out.normals.push_back((normal_sum / normal_length).cast<float>());
        const uint8_t* rgb = view.rgb.row(y) + 3 * x;
        out.colors.push_back({rgb[0], rgb[1], rgb[2]});
        out.scores.push_back(static_cast<float>(std::clamp(1.0 - cost_sum / members, -1.0, 1.0)));
      }
    }
  }
  stats->seconds_fusion = SecondsSince(start);
  return out;
}

}  // namespace reconar
