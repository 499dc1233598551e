#include "core/compare/deviation.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "core/base/thread_pool.h"
#include "core/compare/design_registration.h"
#include "core/compare/point_to_plane.h"
#include "core/mesh/triangle_bvh.h"

namespace reconar {
namespace {

// Registered photos that face the point (in front, within the frame, the face turned toward them).
int FacingViews(const Reconstruction& views, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  int count = 0;
  for (const SfmImage& image : views.images) {
    if (!image.registered || image.camera_id < 0 || static_cast<size_t>(image.camera_id) >= views.cameras.size()) continue;
    const SfmCamera& camera = views.cameras[static_cast<size_t>(image.camera_id)];
    const Eigen::Vector3d in_camera = image.cam_from_world * point;
    if (!(in_camera.z() > 0.0)) continue;
    const Eigen::Vector3d centre = CameraCenterInWorld(image.cam_from_world);
    if (normal.dot(centre - point) <= 0.0) continue;
    const Eigen::Vector2d pixel = camera.Project(in_camera);
    if (pixel.x() < 0.0 || pixel.y() < 0.0 || pixel.x() > camera.width - 1 || pixel.y() > camera.height - 1) continue;
    ++count;
  }
  return count;
}

// The points' indices along a Morton (Z-order) curve over their bounding box, 2^10 cells a side:
// nearby queries one after another keep the tree's nodes in cache and the previous answer near.
std::vector<uint32_t> SpatialOrder(const std::vector<Eigen::Vector3d>& points) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : points) {
    if (p.allFinite()) box.extend(p);
  }
  const Eigen::Vector3d scale = 1023.0 * (box.sizes().array().max(1e-12)).inverse();
  const auto spread = [](uint64_t v) {  // 10 bits to every third of 30
    v = (v | (v << 16)) & 0x030000FFull;
    v = (v | (v << 8)) & 0x0300F00Full;
    v = (v | (v << 4)) & 0x030C30C3ull;
    v = (v | (v << 2)) & 0x09249249ull;
    return v;
  };
  std::vector<std::pair<uint64_t, uint32_t>> keyed(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    uint64_t key = 0;
    if (points[i].allFinite()) {
      const Eigen::Vector3d cell = ((points[i] - box.min()).array() * scale.array()).max(0.0).min(1023.0);
      key = spread(static_cast<uint64_t>(cell.x())) | (spread(static_cast<uint64_t>(cell.y())) << 1) |
            (spread(static_cast<uint64_t>(cell.z())) << 2);
    }
    keyed[i] = {key, static_cast<uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<uint32_t> order(points.size());
  for (size_t i = 0; i < points.size(); ++i) order[i] = keyed[i].second;
  return order;
}

double Percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(fraction * static_cast<double>(values.size())));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
  return values[k];
}

}  // namespace

Result<DeviationReport> ComputeDeviation(const Design& design, const Sim3& world_from_design,
                                         const std::vector<Eigen::Vector3d>& as_built,
                                         const std::vector<Eigen::Vector3d>& as_built_normals,
                                         const Reconstruction* views, const DeviationOptions& options) {
  if (!(options.tolerance > 0.0) || !(options.max_distance > 0.0))
    return InvalidArgument("deviation: the tolerance and the distance bound must be positive");
  if (!as_built_normals.empty() && as_built_normals.size() != as_built.size())
    return InvalidArgument("deviation: as-built normals are not one per point");
  const DesignSurface surface = PlaceDesign(design, world_from_design);
  const TriangleBvh bvh(surface.mesh);
  const double min_cos = std::cos(options.max_normal_angle_deg * M_PI / 180.0);
  DeviationReport report;
  report.views_used = views != nullptr;
  report.element_of_point.assign(as_built.size(), -1);
  report.signed_distance_m.assign(as_built.size(), 0.0);
  const size_t num_elements = design.elements.size();
  std::vector<std::vector<size_t>> triangles_of(num_elements);
  for (size_t t = 0; t < surface.element_of_triangle.size(); ++t) {
    triangles_of[static_cast<size_t>(surface.element_of_triangle[t])].push_back(t);
  }
  ThreadPool pool(ThreadPool::ResolveThreadCount(options.num_threads));
  const std::vector<uint32_t> order = SpatialOrder(as_built);
  constexpr size_t kChunkPoints = 4096;
  pool.ParallelFor(0, (as_built.size() + kChunkPoints - 1) / kChunkPoints, [&](size_t chunk, int) {
    const size_t end = std::min(as_built.size(), (chunk + 1) * kChunkPoints);
    int previous = -1;
    for (size_t k = chunk * kChunkPoints; k < end; ++k) {
      const size_t i = order[k];
      const NearestSurfacePoint nearest = bvh.Nearest(as_built[i], options.max_distance, previous);
      if (nearest.triangle < 0) continue;
      previous = nearest.triangle;
      const Eigen::Vector3d& normal = surface.face_normals[static_cast<size_t>(nearest.triangle)];
      if (!as_built_normals.empty() && as_built_normals[i].norm() > 0.0 &&
          as_built_normals[i].normalized().dot(normal) < min_cos) {
        continue;
      }
      report.element_of_point[i] = surface.element_of_triangle[static_cast<size_t>(nearest.triangle)];
      const double side = normal.dot(as_built[i] - nearest.point);
      report.signed_distance_m[i] = side >= 0.0 ? nearest.distance : -nearest.distance;
    }
  });
  std::vector<std::vector<size_t>> points_of(num_elements);
  for (size_t i = 0; i < as_built.size(); ++i) {
    if (report.element_of_point[i] >= 0) points_of[static_cast<size_t>(report.element_of_point[i])].push_back(i);
  }

  // Areas, and the areas two registered photos face (sampled at each triangle's centroid).
  report.elements.resize(num_elements);
  for (size_t t = 0; t < surface.mesh.triangles.size(); ++t) {
    const std::array<uint32_t, 3>& tri = surface.mesh.triangles[t];
    const Eigen::Vector3d a = surface.mesh.positions[tri[0]].cast<double>();
    const Eigen::Vector3d b = surface.mesh.positions[tri[1]].cast<double>();
    const Eigen::Vector3d c = surface.mesh.positions[tri[2]].cast<double>();
    const double area = 0.5 * (b - a).cross(c - a).norm();
    ElementDeviation& element = report.elements[static_cast<size_t>(surface.element_of_triangle[t])];
    element.area_m2 += area;
    if (views == nullptr || FacingViews(*views, (a + b + c) / 3.0, surface.face_normals[t]) >= 2) {
      element.seen_area_m2 += area;
    }
  }

  std::vector<double> densities;
  for (size_t e = 0; e < num_elements; ++e) {
    ElementDeviation& element = report.elements[e];
    element.name = design.elements[e].name;
    const std::vector<size_t>& mine = points_of[e];
    element.points = static_cast<int>(mine.size());
    if (mine.empty()) continue;
    std::vector<double> magnitudes;
    double sum = 0.0, squares = 0.0;
    int within = 0;
    for (size_t i : mine) {
      const double d = report.signed_distance_m[i];
      sum += d;
      squares += d * d;
      magnitudes.push_back(std::abs(d));
      within += std::abs(d) <= options.tolerance ? 1 : 0;
    }
    const double n = static_cast<double>(mine.size());
    element.mean_m = sum / n;
    element.rms_m = std::sqrt(squares / n);
    element.p95_m = Percentile(magnitudes, 0.95);
    element.within_tolerance = within / n;
    if (element.seen_area_m2 > 0.0) densities.push_back(n / element.seen_area_m2);
    if (element.points < options.min_points) continue;
    // The element's own fit: its points onto its surface alone.
    const TriangleBvh own_bvh(SubMesh(surface.mesh, triangles_of[e]));
    std::vector<Eigen::Vector3d> own_normals;
    for (size_t t : triangles_of[e]) own_normals.push_back(surface.face_normals[t]);
    std::vector<Eigen::Vector3d> points;
    const size_t stride = std::max<size_t>(1, mine.size() / static_cast<size_t>(std::max(1, options.max_fit_points)));
    for (size_t k = 0; k < mine.size(); k += stride) points.push_back(as_built[mine[k]]);
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : points) centre += p / static_cast<double>(points.size());
    PointToPlaneOptions fit_options;
    fit_options.max_distance = options.max_distance;
    const PointToPlaneReport fit =
        AlignPointsToSurface(points, own_bvh, own_normals, fit_options, Rigid3(), &pool);
    const Rigid3 element_move = fit.surface_from_points.Inverse();  // the design element onto its points
    element.shift_m = element_move * centre - centre;
    element.turn_deg = std::acos(std::clamp((element_move.rotation.trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / M_PI;
    for (const Eigen::Vector3d& p : points) {
      const Eigen::Vector3d on_design = fit.surface_from_points * p;  // where the design had it
      element.largest_move_m = std::max(element.largest_move_m, (element_move * on_design - on_design).norm());
    }
  }
  if (!densities.empty()) {
    std::nth_element(densities.begin(), densities.begin() + static_cast<long>(densities.size() / 2), densities.end());
    report.density_per_m2 = densities[densities.size() / 2];
  }
  for (ElementDeviation& element : report.elements) {
    const double expected = report.density_per_m2 * element.seen_area_m2;
    if (report.views_used && element.seen_area_m2 <= 0.0 && element.points < options.min_points) {
      element.verdict = "not_seen";
    } else if (element.points < options.missing_fraction * expected || element.points == 0) {
      element.verdict = "missing";
    } else if (element.largest_move_m > options.tolerance || element.rms_m > options.tolerance) {
      element.verdict = "deviates";
    } else {
      element.verdict = "as_designed";
    }
  }
  return report;
}

}  // namespace reconar
