#include "core/compare/deviation.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

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
  std::vector<std::vector<size_t>> points_of(num_elements);
  for (size_t i = 0; i < as_built.size(); ++i) {
    NearestSurfacePoint nearest = bvh.Nearest(as_built[i], options.max_distance);
    if (nearest.triangle < 0) continue;
    const Eigen::Vector3d& normal = surface.face_normals[static_cast<size_t>(nearest.triangle)];
    if (!as_built_normals.empty() && as_built_normals[i].norm() > 0.0 &&
        as_built_normals[i].normalized().dot(normal) < min_cos) {
      continue;
    }
    const int element = surface.element_of_triangle[static_cast<size_t>(nearest.triangle)];
    report.element_of_point[i] = element;
    const double side = normal.dot(as_built[i] - nearest.point);
    report.signed_distance_m[i] = side >= 0.0 ? nearest.distance : -nearest.distance;
    points_of[static_cast<size_t>(element)].push_back(i);
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
    Design alone;
    alone.elements.push_back(design.elements[e]);
    const DesignSurface own = PlaceDesign(alone, world_from_design);
    const TriangleBvh own_bvh(own.mesh);
    std::vector<Eigen::Vector3d> points;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (size_t i : mine) {
      points.push_back(as_built[i]);
      centre += as_built[i] / n;
    }
    PointToPlaneOptions fit_options;
    fit_options.max_distance = options.max_distance;
    const PointToPlaneReport fit = AlignPointsToSurface(points, own_bvh, own.face_normals, fit_options);
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
