#include "core/compare/deviation.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "core/base/thread_pool.h"
#include "core/compare/design_registration.h"
#include "core/compare/point_to_plane.h"
#include "core/mesh/triangle_bvh.h"

namespace reconar {
namespace {

// What the registered photos say about points on the design's surface. Each photo's view of the
// as-built points is a coarse depth buffer (the nearest point per cell of kCellPx pixels); a
// surface point the photo faces (in front, in the frame, its face turned toward the photo) is
// then, from that photo:
//   hidden       when an as-built point lies in front of it (beyond the margin): no evidence;
//   present      when the nearest as-built point is at its depth (within the margin);
//   see-through  when the nearest as-built point is behind it: the photo saw past where the
//                surface should be, so it is not there;
//   open         when the cell holds no point: looked at, nothing reconstructed either way.
struct SurfaceSample {
  Eigen::Vector3d point, normal;
  int element = 0;
  double area = 0.0;  // the share of its element's area it stands for
  int unhidden = 0, see_through = 0, present = 0;
};

constexpr int kCellPx = 8;
constexpr size_t kMaxBufferPoints = 150000;  // as-built points projected per photo (evenly thinned)
constexpr int kSamplesPerElement = 256;

void VoteFromViews(const Reconstruction& views, const std::vector<Eigen::Vector3d>& as_built, double margin,
                   ThreadPool* pool, std::vector<SurfaceSample>* samples) {
  std::vector<const SfmImage*> photos;
  for (const SfmImage& image : views.images) {
    if (image.registered && image.camera_id >= 0 && static_cast<size_t>(image.camera_id) < views.cameras.size()) {
      photos.push_back(&image);
    }
  }
  const size_t stride = std::max<size_t>(1, as_built.size() / kMaxBufferPoints);
  struct Votes {
    std::vector<int> unhidden, see_through, present;
    std::vector<float> depth;  // the worker's depth buffer
  };
  std::vector<Votes> votes(static_cast<size_t>(pool->num_threads()));
  for (Votes& v : votes) {
    v.unhidden.assign(samples->size(), 0);
    v.see_through.assign(samples->size(), 0);
    v.present.assign(samples->size(), 0);
  }
  pool->ParallelFor(0, photos.size(), [&](size_t p, int worker) {
    const SfmImage& image = *photos[p];
    const SfmCamera& camera = views.cameras[static_cast<size_t>(image.camera_id)];
    const int columns = (camera.width + kCellPx - 1) / kCellPx, rows = (camera.height + kCellPx - 1) / kCellPx;
    Votes& mine = votes[static_cast<size_t>(worker)];
    mine.depth.assign(static_cast<size_t>(columns) * static_cast<size_t>(rows), INFINITY);
    const double max_r2 = camera.MaxValidRadiusSquared(camera.width, camera.height);
    const auto cell_of = [&](const Eigen::Vector3d& in_camera) -> long {
      if (!(in_camera.z() > 0.0) || !((in_camera.head<2>() / in_camera.z()).squaredNorm() <= max_r2)) return -1;
      const Eigen::Vector2d pixel = camera.Project(in_camera);
      if (!(pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() < camera.width - 0.5 && pixel.y() < camera.height - 0.5)) {
        return -1;
      }
      const int column = std::min(columns - 1, static_cast<int>((pixel.x() + 0.5) / kCellPx));
      const int row = std::min(rows - 1, static_cast<int>((pixel.y() + 0.5) / kCellPx));
      return static_cast<long>(row) * columns + column;
    };
    for (size_t i = 0; i < as_built.size(); i += stride) {
      const Eigen::Vector3d in_camera = image.cam_from_world * as_built[i];
      const long cell = cell_of(in_camera);
      if (cell >= 0) {
        float& nearest = mine.depth[static_cast<size_t>(cell)];
        nearest = std::min(nearest, static_cast<float>(in_camera.z()));
      }
    }
    const Eigen::Vector3d centre = CameraCenterInWorld(image.cam_from_world);
    for (size_t k = 0; k < samples->size(); ++k) {
      const SurfaceSample& sample = (*samples)[k];
      if (sample.normal.dot(centre - sample.point) <= 0.0) continue;
      const Eigen::Vector3d in_camera = image.cam_from_world * sample.point;
      const long cell = cell_of(in_camera);
      if (cell < 0) continue;
      const double nearest = mine.depth[static_cast<size_t>(cell)];
      // Depth along the optical axis; the margin along the ray, near enough for a cell's width.
      if (nearest < in_camera.z() - margin) continue;  // hidden
      ++mine.unhidden[k];
      if (!std::isfinite(nearest)) continue;  // open
      if (nearest > in_camera.z() + margin) {
        ++mine.see_through[k];
      } else {
        ++mine.present[k];
      }
    }
  });
  for (const Votes& v : votes) {
    for (size_t k = 0; k < samples->size(); ++k) {
      (*samples)[k].unhidden += v.unhidden[k];
      (*samples)[k].see_through += v.see_through[k];
      (*samples)[k].present += v.present[k];
    }
  }
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
    const size_t begin = chunk * kChunkPoints, end = std::min(as_built.size(), (chunk + 1) * kChunkPoints);
    std::vector<Eigen::Vector3d> queries;
    queries.reserve(end - begin);
    for (size_t k = begin; k < end; ++k) queries.push_back(as_built[order[k]]);
    std::vector<NearestSurfacePoint> answers(queries.size());
    std::vector<int> candidates;
    bvh.NearestBatch(queries.data(), queries.size(), options.max_distance, answers.data(), &candidates);
    for (size_t k = begin; k < end; ++k) {
      const size_t i = order[k];
      const NearestSurfacePoint& nearest = answers[k - begin];
      if (nearest.triangle < 0) continue;
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

  // Areas; points spread over each element's surface (area-weighted, seeded: the same each run),
  // and what the photos say about them.
  report.elements.resize(num_elements);
  std::vector<double> triangle_area(surface.mesh.triangles.size());
  for (size_t t = 0; t < surface.mesh.triangles.size(); ++t) {
    const std::array<uint32_t, 3>& tri = surface.mesh.triangles[t];
    const Eigen::Vector3d a = surface.mesh.positions[tri[0]].cast<double>();
    triangle_area[t] = 0.5 * (surface.mesh.positions[tri[1]].cast<double>() - a)
                                 .cross(surface.mesh.positions[tri[2]].cast<double>() - a)
                                 .norm();
    report.elements[static_cast<size_t>(surface.element_of_triangle[t])].area_m2 += triangle_area[t];
  }
  std::vector<SurfaceSample> samples;
  std::mt19937_64 random(1);
  for (size_t e = 0; e < num_elements; ++e) {
    if (triangles_of[e].empty() || !(report.elements[e].area_m2 > 0.0)) continue;
    std::vector<double> areas;
    for (size_t t : triangles_of[e]) areas.push_back(triangle_area[t]);
    std::discrete_distribution<size_t> pick(areas.begin(), areas.end());
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int k = 0; k < kSamplesPerElement; ++k) {
      const size_t t = triangles_of[e][pick(random)];
      const std::array<uint32_t, 3>& tri = surface.mesh.triangles[t];
      double u = unit(random), v = unit(random);
      if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
      const Eigen::Vector3d a = surface.mesh.positions[tri[0]].cast<double>();
      const Eigen::Vector3d point = a + u * (surface.mesh.positions[tri[1]].cast<double>() - a) +
                                    v * (surface.mesh.positions[tri[2]].cast<double>() - a);
      samples.push_back({point, surface.face_normals[t], static_cast<int>(e),
                         report.elements[e].area_m2 / kSamplesPerElement});
    }
  }
  if (views != nullptr) VoteFromViews(*views, as_built, options.max_distance, &pool, &samples);
  std::vector<double> see_through_area(num_elements, 0.0), evidence_area(num_elements, 0.0);
  for (const SurfaceSample& sample : samples) {
    ElementDeviation& element = report.elements[static_cast<size_t>(sample.element)];
    if (views == nullptr || sample.unhidden >= 2) element.seen_area_m2 += sample.area;
    if (sample.see_through + sample.present > 0) {
      evidence_area[static_cast<size_t>(sample.element)] += sample.area;
      if (sample.see_through > sample.present) see_through_area[static_cast<size_t>(sample.element)] += sample.area;
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
  for (size_t e = 0; e < num_elements; ++e) {
    ElementDeviation& element = report.elements[e];
    const double expected = report.density_per_m2 * element.seen_area_m2;
    const bool too_few = element.points < options.missing_fraction * expected || element.points == 0;
    // Missing needs the photos to have seen past it: over half of where they looked.
    const bool seen_through = evidence_area[e] > 0.0 && see_through_area[e] > 0.5 * evidence_area[e];
    if (report.views_used && element.seen_area_m2 <= 0.0 && element.points < options.min_points) {
      element.verdict = "not_seen";
    } else if (too_few && report.views_used && !seen_through) {
      element.verdict = "unknown";
    } else if (too_few) {
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
