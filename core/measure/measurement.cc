#include "core/measure/measurement.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <unordered_map>

#include <Eigen/Geometry>

#include "core/base/json_reader.h"
#include "core/base/json_writer.h"
#include "core/geometry/triangulation.h"
#include "core/measure/project_covariance.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/triangle_bvh.h"
#include "core/sfm/tag_observations.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Exactly `count` comma-separated numbers.
bool ParseNumbers(const std::string& text, size_t count, double* out) {
  size_t pos = 0;
  for (size_t k = 0; k < count; ++k) {
    const size_t end = k + 1 < count ? text.find(',', pos) : text.size();
    if (end == std::string::npos) return false;
    const std::string field = text.substr(pos, end - pos);
    char* stop = nullptr;
    out[k] = std::strtod(field.c_str(), &stop);
    if (field.empty() || stop != field.c_str() + field.size() || !std::isfinite(out[k])) return false;
    pos = end + 1;
  }
  return true;
}

Result<int> ParseNonNegative(const std::string& field) {
  char* stop = nullptr;
  const long value = std::strtol(field.c_str(), &stop, 10);
  if (field.empty() || stop != field.c_str() + field.size() || value < 0 || value > 1 << 30) {
    return InvalidArgument("");
  }
  return static_cast<int>(value);
}

int LengthPower(MeasureKind kind) { return kind == MeasureKind::kArea ? 2 : 1; }

double ItemValue(MeasureKind kind, const std::vector<Eigen::Vector3d>& p) {
  switch (kind) {
    case MeasureKind::kDistance:
    case MeasureKind::kPath: {
      double length = 0.0;
      for (size_t k = 1; k < p.size(); ++k) length += (p[k] - p[k - 1]).norm();
      return length;
    }
    case MeasureKind::kArea: {
      Eigen::Vector3d twice_area = Eigen::Vector3d::Zero();
      for (size_t k = 1; k + 1 < p.size(); ++k) twice_area += (p[k] - p[0]).cross(p[k + 1] - p[0]);
      return 0.5 * twice_area.norm();
    }
    case MeasureKind::kHeight: {
      const Eigen::Vector3d normal = (p[2] - p[1]).cross(p[3] - p[1]);
      const double scale = std::max((p[2] - p[1]).squaredNorm(), (p[3] - p[1]).squaredNorm());
      if (!(normal.norm() > 1e-9 * scale)) return kNaN;  // the plane's points on one line
      return normal.normalized().dot(p[0] - p[1]);
    }
  }
  return kNaN;
}

Eigen::Vector3d FaceNormal(const Mesh& mesh, int triangle) {
  const std::array<uint32_t, 3>& t = mesh.triangles[static_cast<size_t>(triangle)];
  const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
  return (mesh.positions[t[1]].cast<double>() - a).cross(mesh.positions[t[2]].cast<double>() - a).normalized();
}

double MedianEdge(const Mesh& mesh) {
  std::vector<double> edges;
  for (size_t i = 0; i < mesh.triangles.size(); i += std::max<size_t>(1, mesh.triangles.size() / 10000)) {
    const std::array<uint32_t, 3>& t = mesh.triangles[i];
    if (std::max({t[0], t[1], t[2]}) >= mesh.positions.size()) continue;
    edges.push_back((mesh.positions[t[1]] - mesh.positions[t[0]]).norm());
  }
  if (edges.empty()) return 0.0;
  std::nth_element(edges.begin(), edges.begin() + static_cast<std::ptrdiff_t>(edges.size() / 2), edges.end());
  return edges[edges.size() / 2];
}

}  // namespace

// Used by ProjectMeasurer::State, so not in the anonymous namespace.
namespace measure_internal {

struct SurfaceSupport {
  int points = 0;             // dense points within the radius
  double rms_distance = 0.0;  // their RMS distance from the plane through the point
};

// The dense points in cubic cells of the support radius, for the points near a surface point.
class PointGrid {
 public:
  PointGrid(std::vector<Eigen::Vector3f> points, double radius) : points_(std::move(points)), radius_(radius) {
    if (!(radius_ > 0.0)) radius_ = 1e-3;
    std::vector<std::pair<int64_t, int>> keyed;
    keyed.reserve(points_.size());
    for (size_t i = 0; i < points_.size(); ++i) {
      if (points_[i].allFinite()) keyed.push_back({Key(Cell(points_[i].cast<double>())), static_cast<int>(i)});
    }
    std::sort(keyed.begin(), keyed.end());
    order_.reserve(keyed.size());
    for (size_t k = 0; k < keyed.size(); ++k) {
      if (k == 0 || keyed[k].first != keyed[k - 1].first) cells_[keyed[k].first] = {static_cast<int>(k), 0};
      ++cells_[keyed[k].first].second;
      order_.push_back(keyed[k].second);
    }
  }

  // The points within `cells` cell sizes of `point`.
  SurfaceSupport Support(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, int cells) const {
    SurfaceSupport support;
    const Eigen::Vector3i centre = Cell(point);
    const double radius = cells * radius_;
    double squares = 0.0;
    for (int dx = -cells; dx <= cells; ++dx) {
      for (int dy = -cells; dy <= cells; ++dy) {
        for (int dz = -cells; dz <= cells; ++dz) {
          const auto cell = cells_.find(Key(centre + Eigen::Vector3i(dx, dy, dz)));
          if (cell == cells_.end()) continue;
          for (int k = cell->second.first; k < cell->second.first + cell->second.second; ++k) {
            const Eigen::Vector3d offset = points_[static_cast<size_t>(order_[static_cast<size_t>(k)])].cast<double>() - point;
            if (offset.squaredNorm() > radius * radius) continue;
            ++support.points;
            squares += std::pow(offset.dot(normal), 2);
          }
        }
      }
    }
    if (support.points > 0) support.rms_distance = std::sqrt(squares / support.points);
    return support;
  }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const { return (p / radius_).array().floor().cast<int>(); }
  static int64_t Key(const Eigen::Vector3i& c) {
    return (static_cast<int64_t>(c.x() & 0x1fffff) << 42) | (static_cast<int64_t>(c.y() & 0x1fffff) << 21) |
           static_cast<int64_t>(c.z() & 0x1fffff);
  }

  std::vector<Eigen::Vector3f> points_;
  double radius_;
  std::vector<int> order_;                                // point indices by cell
  std::unordered_map<int64_t, std::pair<int, int>> cells_;  // cell -> (first in order_, count)
};

}  // namespace measure_internal

using measure_internal::PointGrid;
using measure_internal::SurfaceSupport;

const char* MeasureKindName(MeasureKind kind) {
  switch (kind) {
    case MeasureKind::kDistance: return "distance";
    case MeasureKind::kPath: return "path";
    case MeasureKind::kArea: return "area";
    case MeasureKind::kHeight: return "height";
  }
  return "?";
}

Result<MeasurePoint> ParseMeasurePoint(const std::string& text) {
  MeasurePoint point;
  point.text = text;
  const auto bad = [&](const std::string& why) { return InvalidArgument("point '" + text + "': " + why); };
  if (text.rfind("tag:", 0) == 0) {
    const std::string rest = text.substr(4);
    const size_t colon = rest.find(':');
    Result<int> id = ParseNonNegative(rest.substr(0, colon));
    if (!id.ok()) return bad("expected tag:ID or tag:ID:cK (K 0..3)");
    point.tag_id = *id;
    point.kind = MeasurePointKind::kTagCentre;
    if (colon != std::string::npos) {
      const std::string corner = rest.substr(colon + 1);
      if (corner.size() != 2 || corner[0] != 'c' || corner[1] < '0' || corner[1] > '3') {
        return bad("a corner is c0, c1, c2 or c3 (libapriltag's order)");
      }
      point.kind = MeasurePointKind::kTagCorner;
      point.corner = corner[1] - '0';
    }
    return point;
  }
  if (text.rfind("xyz:", 0) == 0) {
    double xyz[3];
    if (!ParseNumbers(text.substr(4), 3, xyz)) return bad("expected xyz:X,Y,Z (world frame)");
    point.kind = MeasurePointKind::kWorld;
    point.world = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    return point;
  }
  if (text.find('@') == std::string::npos) {
    return bad("expected tag:ID, tag:ID:cK, xyz:X,Y,Z, PHOTO@X,Y or PHOTO@X,Y+PHOTO@X,Y");
  }
  point.kind = MeasurePointKind::kPixels;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t plus = text.find('+', text.find('@', pos));
    if (plus == std::string::npos) plus = text.size();
    const std::string part = text.substr(pos, plus - pos);
    const size_t at = part.rfind('@');
    double xy[2];
    if (at == std::string::npos || at == 0 || !ParseNumbers(part.substr(at + 1), 2, xy)) {
      return bad("'" + part + "' is not PHOTO@X,Y (pixels)");
    }
    point.pixels.push_back({part.substr(0, at), Eigen::Vector2d(xy[0], xy[1])});
    pos = plus + 1;
  }
  return point;
}

// A point of a measurement as a function of the covariance's points: the sum of weight x point,
// or a world-frame point (fixed in the world tag's frame: State::WorldTagFrame).
struct LocatedPoint {
  std::vector<std::pair<int, double>> terms;
  bool world = false;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
};

struct ProjectMeasurer::State {
  Project project;
  MeasureOptions options;
  ProjectCovariance model;
  std::map<std::string, int> image_of_name;
  std::vector<Eigen::Vector3d> positions;  // of the covariance's points (model, then added)
  std::map<std::pair<int, int>, int> corner_point;  // (tag, corner) -> covariance point, once placed
  bool metric = false;
  double tag_size = 0.0;
  int world_tag = -1;
  std::vector<int> scale_corners;  // 4 covariance points per scale tag
  double scale_mean_ = 1.0;        // their mean edge in the model
  double scale_relative_sigma = 0.0;
  double length_relative_sigma = 0.0;
  double square_check_rms = 0.0;  // tags.json "square_check": the squares' cross-check
  double calibration = 1.0;
  std::vector<int> spread_points;  // the model's points that its observations fix
  Eigen::Vector3d model_centroid = Eigen::Vector3d::Zero();
  double model_spread = 1.0;  // RMS distance of spread_points from their centroid
  std::unique_ptr<Mesh> mesh;
  std::unique_ptr<TriangleBvh> surface;
  std::unique_ptr<PointGrid> dense;
  bool surface_read = false;
  Status surface_status;
  std::map<int, Eigen::Vector3d> surface_error;  // placed point -> its error along the ray (direction x σ)

  explicit State(const Project& p) : project(p) {}

  // Forgets the points added after the first `count`.
  void Rewind(size_t count) {
    model.covariance.RemoveAddedPoints(static_cast<int>(count));
    if (count < positions.size()) positions.resize(count);
    for (auto it = surface_error.begin(); it != surface_error.end();) {
      it = it->first >= static_cast<int>(count) ? surface_error.erase(it) : std::next(it);
    }
    for (auto it = corner_point.begin(); it != corner_point.end();) {
      it = it->second >= static_cast<int>(count) ? corner_point.erase(it) : std::next(it);
    }
  }

  Result<int> AddPoint(const Eigen::Vector3d& position, const std::vector<BalObservation>& observations,
                       const std::vector<Eigen::Matrix2d>& residual_projections = {}) {
    RECONAR_ASSIGN_OR_RETURN(const int index, model.covariance.AddPoint(position, observations, residual_projections));
    if (static_cast<size_t>(index) != positions.size()) return Internal("measure: covariance points out of step");
    positions.push_back(position);
    return index;
  }

  // A pixel picked by a person is as precise as options.pick_sigma_px says, against the
  // adjustment's sigma0 for a unit weight.
  double PickWeight() const {
    return std::sqrt(model.covariance.variance_factor()) / std::max(options.pick_sigma_px, 1e-3);
  }

  const SfmImage& image_of_camera(int camera) const {
    const auto it = std::find(model.problem_camera.begin(), model.problem_camera.end(), camera);
    return model.model.images[static_cast<size_t>(it - model.problem_camera.begin())];
  }
  const SfmCamera& camera_of(const SfmImage& image) const {
    return model.model.cameras[static_cast<size_t>(image.camera_id)];
  }

  // Triangulated from observations (pixels) of the covariance's cameras.
  Result<Eigen::Vector3d> Triangulate(const std::vector<BalObservation>& observations, const std::string& what) const {
    std::vector<TriangulationView> views;
    std::vector<Eigen::Vector3d> centres;
    for (const BalObservation& o : observations) {
      const SfmImage& image = image_of_camera(o.camera);
      const SfmCamera& camera = camera_of(image);
      TriangulationView view;
      view.cam_from_world = image.cam_from_world;
      view.focal = camera.focal;
      if (!camera.Undistort(Eigen::Vector2d(o.x, o.y), &view.normalised)) {
        return FailedPrecondition(what + ": the pixel in " + image.name + " is beyond its camera's lens model");
      }
      views.push_back(view);
      centres.push_back(image.Center());
    }
    Eigen::Vector3d point;
    if (views.size() < 2 || !TriangulateMultiView(views, &point)) {
      return FailedPrecondition(what + ": the rays do not meet in front of the photos");
    }
    double widest = 0.0;
    for (size_t a = 0; a < centres.size(); ++a) {
      for (size_t b = a + 1; b < centres.size(); ++b) widest = std::max(widest, TriangulationAngle(centres[a], centres[b], point));
    }
    if (widest * 180.0 / M_PI < options.min_triangulation_angle_deg) {
      return FailedPrecondition(what + ": the photos see it from nearly the same direction (" +
                                std::to_string(widest * 180.0 / M_PI) + " degrees between the rays)");
    }
    return point;
  }

  Result<int> CornerPoint(int tag, int corner, const std::string& what) {
    const auto cached = corner_point.find({tag, corner});
    if (cached != corner_point.end()) return cached->second;
    const auto it = model.tag_corners.find({tag, corner});
    if (it == model.tag_corners.end()) {
      return NotFound(what + ": no registered photo shows tag " + std::to_string(tag) + TagsSeen());
    }
    int index = it->second.point;
    if (index < 0) {
      RECONAR_ASSIGN_OR_RETURN(const Eigen::Vector3d position, Triangulate(it->second.observations, what));
      RECONAR_ASSIGN_OR_RETURN(index, AddPoint(position, it->second.observations));
    }
    corner_point[{tag, corner}] = index;
    return index;
  }

  std::string TagsSeen() const {
    std::set<int> ids;
    for (const auto& [key, corner] : model.tag_corners) ids.insert(key.first);
    if (ids.empty()) return " (the project's photos show no tag)";
    std::string list;
    for (int id : ids) list += (list.empty() ? "" : ",") + std::to_string(id);
    return " (tags seen: " + list + ")";
  }

  Status ReadSurface() {
    if (surface_read) return surface_status;
    surface_read = true;
    surface_status = [&]() -> Status {
      const std::string path = project.MeshDir() + "/mesh.ply";
      std::error_code error;
      if (!std::filesystem::exists(path, error)) {
        return FailedPrecondition(project.root() + " has no surface to meet a photo's ray with (" + path +
                                  " is missing: the mesh stage of `reconar reconstruct` makes it); pick the point in "
                                  "a second photo instead, PHOTO@X,Y+PHOTO2@X,Y, to triangulate it");
      }
      RECONAR_ASSIGN_OR_RETURN(Mesh read, ReadMeshFile(path));
      mesh = std::make_unique<Mesh>(std::move(read));
      surface = std::make_unique<TriangleBvh>(*mesh);
      if (surface->num_triangles() == 0) return FailedPrecondition(path + " has no usable triangle");
      if (!std::filesystem::exists(project.DensePointsPath(), error)) {
        return FailedPrecondition(project.root() + " has a mesh but no dense points (" + project.DensePointsPath() +
                                  " is missing) to tell where the mesh is supported and how closely");
      }
      RECONAR_ASSIGN_OR_RETURN(Mesh points, ReadMeshFile(project.DensePointsPath()));
      double spacing = 0.0;
      if (Result<JsonValue> report = ReadJsonFile(project.MeshDir() + "/report.json"); report.ok()) {
        if (const JsonValue* value = report->Find("median_spacing"); value != nullptr && value->is_number()) {
          spacing = value->number();
        }
      }
      if (!(spacing > 0.0)) spacing = MedianEdge(*mesh);
      dense = std::make_unique<PointGrid>(std::move(points.positions), options.support_radius_spacings * spacing);
      return Status::Ok();
    }();
    return surface_status;
  }

  // Where the dense stage missed a surface (a face every photo saw at a grazing angle), a picked
  // pixel's ray passes through it and meets whatever lies behind. The photo's own model points
  // round the pixel show it: a hit deeper than all of them by more than max_hit_behind is refused.
  Status CheckHitDepth(const BalObservation& pick, const Eigen::Vector3d& hit, const std::string& what) const {
    const SfmImage& image = image_of_camera(pick.camera);
    const SfmCamera& intrinsics = camera_of(image);
    const double radius = options.hit_check_radius * std::hypot(intrinsics.width, intrinsics.height);
    const Eigen::Vector2d pixel(pick.x, pick.y);
    double deepest = 0.0;
    int near = 0;
    for (size_t k = 0; k < image.keypoints.size() && k < image.point3d_ids.size(); ++k) {
      const int id = image.point3d_ids[k];
      if (id < 0 || (image.keypoints[k] - pixel).norm() > radius) continue;
      const SfmPoint& point = model.model.points[static_cast<size_t>(id)];
      if (point.deleted) continue;
      deepest = std::max(deepest, (image.cam_from_world * point.position).z());
      ++near;
    }
    const double depth = (image.cam_from_world * hit).z();
    if (near < options.hit_check_min_points || depth <= (1.0 + options.max_hit_behind) * deepest) return Status::Ok();
    char text[160];
    std::snprintf(text, sizeof(text), "%.3g times as far as the deepest of the %d model points round the pixel", depth / deepest,
                  near);
    return FailedPrecondition(what + ": the mesh under the pixel lies " + text + " in " + image.name +
                              ": its surface there is missing (picked through it); pick the point in a second photo too "
                              "(PHOTO@X,Y+PHOTO2@X,Y)");
  }

  // The surface point the ray meets, observed in the photos that see it (`pick`, when set, first:
  // the photo and pixel it was picked at), added to the covariance.
  Result<int> PlaceOnSurface(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                             const BalObservation* pick, const std::string& what) {
    RECONAR_RETURN_IF_ERROR(ReadSurface());
    // The first front face (seen from the ray's side) that the dense points support: Poisson closes
    // the surface where there were no points, and a photo does not see a face from behind.
    RayHit hit;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    SurfaceSupport support;
    constexpr int kMaxFacesPassed = 1000;
    for (double from = 0.0, passed = 0;; ++passed) {
      hit = surface->Intersect(origin, direction, from);
      if (hit.triangle < 0 || passed > kMaxFacesPassed) return NotFound(what + ": the ray meets no surface of the model that its dense points support");
      normal = FaceNormal(*mesh, hit.triangle);
      if (normal.dot(direction) < 0.0) {
        // Where the photos gave few points (a plain wall) Poisson interpolated: the support is
        // sought farther, and its scatter about the plane grows with the distance it spans.
        for (int cells = 1; cells <= options.max_support_radii; cells *= 2) {
          support = dense->Support(hit.point, normal, cells);
          if (support.points >= options.min_support_points) break;
        }
        if (support.points >= options.min_support_points) break;
      }
      from = hit.distance * (1.0 + 1e-9);
    }
    if (pick != nullptr) RECONAR_RETURN_IF_ERROR(CheckHitDepth(*pick, hit.point, what));
    std::vector<std::pair<double, BalObservation>> seen_by;
    for (size_t i = 0; i < model.model.images.size(); ++i) {
      const int camera = model.problem_camera[i];
      if (camera < 0 || (pick != nullptr && camera == pick->camera)) continue;
      const SfmImage& image = model.model.images[i];
      const SfmCamera& intrinsics = camera_of(image);
      const Eigen::Vector3d in_camera = image.cam_from_world.rotation * hit.point + image.cam_from_world.translation;
      if (in_camera.z() <= 0.0) continue;
      const Eigen::Vector2d pixel = intrinsics.Project(in_camera);
      if (!(pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() <= intrinsics.width - 1 &&
            pixel.y() <= intrinsics.height - 1)) {
        continue;
      }
      const Eigen::Vector3d centre = image.Center();
      if (normal.dot(centre - hit.point) <= 0.0) continue;
      if (surface->Intersect(centre, hit.point - centre, 1e-9, options.surface_occlusion_fraction).triangle >= 0) continue;
      seen_by.push_back({(hit.point - centre).norm(), {camera, -1, pixel.x(), pixel.y(), 1.0}});
    }
    std::sort(seen_by.begin(), seen_by.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<BalObservation> others;
    for (const auto& [distance, observation] : seen_by) {
      if (static_cast<int>(others.size()) + (pick != nullptr ? 1 : 0) >= options.max_surface_views) break;
      others.push_back(observation);
    }
    // The surface's own error, the dense points' scatter about it, along the normal; along the ray
    // that is more by 1 / cos(incidence).
    const Eigen::Vector3d along = direction.normalized();
    const double incidence = std::max(std::abs(normal.dot(along)), 0.2);
    const double surface_sigma = support.rms_distance / incidence;
    if (pick == nullptr) {
      // A ray from outside the model (the view's camera): the point as the photos that see it place it.
      RECONAR_ASSIGN_OR_RETURN(const int index, AddPoint(hit.point, others));
      surface_error[index] = along * surface_sigma;
      return index;
    }
    // Picked in a photo: across its ray, the pick and that photo's pose place it; along it, the
    // photos that see the surface there (each observation kept along the image of the ray only).
    std::vector<BalObservation> observations = {*pick};
    std::vector<Eigen::Matrix2d> projections = {Eigen::Matrix2d::Identity()};
    for (const BalObservation& other : others) {
      const SfmImage& image = image_of_camera(other.camera);
      const Eigen::Vector3d further = hit.point + 0.01 * hit.distance * direction;
      const Eigen::Vector2d step =
          camera_of(image).Project(image.cam_from_world.rotation * further + image.cam_from_world.translation) -
          Eigen::Vector2d(other.x, other.y);
      if (!(step.norm() > 1e-6)) continue;  // it sees the ray end on: no hold on the depth
      const Eigen::Vector2d e = step.normalized();
      observations.push_back(other);
      projections.push_back(e * e.transpose());
    }
    RECONAR_ASSIGN_OR_RETURN(const int index, AddPoint(hit.point, observations, projections));
    surface_error[index] = along * surface_sigma;
    return index;
  }

  Result<int> PixelsPoint(const MeasurePoint& point) {
    std::vector<BalObservation> observations;
    for (const PhotoPixel& pick : point.pixels) {
      const std::string what = "point '" + point.text + "'";
      const auto it = image_of_name.find(pick.image);
      if (it == image_of_name.end()) return NotFound(what + ": the project has no photo " + pick.image);
      const SfmImage& image = model.model.images[static_cast<size_t>(it->second)];
      const int camera = model.problem_camera[static_cast<size_t>(it->second)];
      if (camera < 0) return FailedPrecondition(what + ": " + pick.image + " is not registered in the model");
      const SfmCamera& intrinsics = camera_of(image);
      if (!(pick.pixel.x() >= -0.5 && pick.pixel.y() >= -0.5 && pick.pixel.x() <= intrinsics.width - 0.5 &&
            pick.pixel.y() <= intrinsics.height - 0.5)) {
        return InvalidArgument(what + ": the pixel is outside " + pick.image + " (" + std::to_string(intrinsics.width) +
                               " x " + std::to_string(intrinsics.height) + ")");
      }
      observations.push_back({camera, -1, pick.pixel.x(), pick.pixel.y(), PickWeight()});
    }
    const std::string what = "point '" + point.text + "'";
    if (observations.size() >= 2) {
      RECONAR_ASSIGN_OR_RETURN(const Eigen::Vector3d position, Triangulate(observations, what));
      for (const BalObservation& o : observations) {
        const SfmImage& image = image_of_camera(o.camera);
        const Eigen::Vector3d in_camera = image.cam_from_world.rotation * position + image.cam_from_world.translation;
        const double miss = (camera_of(image).Project(in_camera) - Eigen::Vector2d(o.x, o.y)).norm();
        if (!(miss <= options.max_pick_reprojection_px)) {
          return FailedPrecondition(what + ": the pixels are not of one point (" + image.name + " misses it by " +
                                    std::to_string(miss) + " px)");
        }
      }
      return AddPoint(position, observations);
    }
    const SfmImage& image = image_of_camera(observations[0].camera);
    Eigen::Vector2d normalised;
    if (!camera_of(image).Undistort(Eigen::Vector2d(observations[0].x, observations[0].y), &normalised)) {
      return FailedPrecondition(what + ": the pixel is beyond its camera's lens model");
    }
    const Eigen::Vector3d direction = image.cam_from_world.rotation.transpose() * normalised.homogeneous();
    return PlaceOnSurface(image.Center(), direction, &observations[0], what);
  }

  Result<LocatedPoint> Locate(const MeasurePoint& point) {
    LocatedPoint located;
    const std::string what = "point '" + point.text + "'";
    switch (point.kind) {
      case MeasurePointKind::kTagCorner: {
        RECONAR_ASSIGN_OR_RETURN(const int index, CornerPoint(point.tag_id, point.corner, what));
        located.terms.push_back({index, 1.0});
        break;
      }
      case MeasurePointKind::kTagCentre:
        for (int corner = 0; corner < 4; ++corner) {
          RECONAR_ASSIGN_OR_RETURN(const int index, CornerPoint(point.tag_id, corner, what));
          located.terms.push_back({index, 0.25});
        }
        break;
      case MeasurePointKind::kWorld:
        located.world = true;
        located.xyz = point.world;
        if (metric) {  // so that its σ carries the world frame's: the world tag's corners fix it
          for (int corner = 0; corner < 4; ++corner) RECONAR_RETURN_IF_ERROR(CornerPoint(world_tag, corner, what).status());
        }
        break;
      case MeasurePointKind::kPixels: {
        if (point.pixels.empty()) return InvalidArgument(what + ": no pixel");
        RECONAR_ASSIGN_OR_RETURN(const int index, PixelsPoint(point));
        located.terms.push_back({index, 1.0});
        break;
      }
      case MeasurePointKind::kPlaced:
        if (point.placed < 0 || static_cast<size_t>(point.placed) >= positions.size()) {
          return InvalidArgument(what + ": not a point this project's measurer placed");
        }
        located.terms.push_back({point.placed, 1.0});
        break;
    }
    return located;
  }

  // The world tag's frame as the corners' centre and the rotation that best fits the ideal square
  // to them, at positions `y`: a world point's place moves with it.
  Eigen::Vector3d WorldTagFrame(const std::map<int, Eigen::Vector3d>& y, const Eigen::Vector3d& xyz,
                                double scale_mean) const {
    Eigen::Matrix<double, 3, 4> ideal, seen;
    for (int corner = 0; corner < 4; ++corner) {
      ideal.col(corner) = Eigen::Vector3d(kTagCornerUnits[corner][0], kTagCornerUnits[corner][1], 0.0);
      seen.col(corner) = y.at(corner_point.at({world_tag, corner}));
    }
    const Eigen::Matrix4d fit = Eigen::umeyama(ideal, seen, false);
    return seen.rowwise().mean() + scale_mean / tag_size * fit.topLeftCorner<3, 3>() * xyz;
  }

  // The scale tags' mean edge in the model, and its gradient (per scale corner).
  double ScaleMean(std::vector<PointGradient>* gradient) const {
    double sum = 0.0;
    const double n = static_cast<double>(scale_corners.size());
    for (size_t t = 0; t < scale_corners.size(); t += 4) {
      for (size_t k = 0; k < 4; ++k) {
        const int from = scale_corners[t + k], to = scale_corners[t + (k + 1) % 4];
        const Eigen::Vector3d edge = positions[static_cast<size_t>(to)] - positions[static_cast<size_t>(from)];
        sum += edge.norm();
        if (gradient != nullptr) {
          gradient->push_back({to, edge.normalized() / n});
          gradient->push_back({from, -edge.normalized() / n});
        }
      }
    }
    return sum / n;
  }

  // The item's value with the points at y and the metric scale (the scale tags' mean edge in
  // the model) `scale_mean`, which places world points.
  double Function(MeasureKind kind, const std::vector<LocatedPoint>& points, const std::map<int, Eigen::Vector3d>& y,
                  const std::map<int, Eigen::Vector3d>& y0, double scale_mean, std::vector<Eigen::Vector3d>* at) const {
    std::vector<Eigen::Vector3d> p;
    for (const LocatedPoint& point : points) {
      if (point.world) {
        p.push_back(metric ? point.xyz + WorldTagFrame(y, point.xyz, scale_mean) - WorldTagFrame(y0, point.xyz, scale_mean_)
                           : point.xyz);
        continue;
      }
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (const auto& [index, weight] : point.terms) sum += weight * y.at(index);
      p.push_back(sum);
    }
    if (at != nullptr) *at = p;
    return ItemValue(kind, p);
  }

  // Value and σ before calibration. The σ is that of a function the model's similarity does not
  // change: the value times (M0 / M)^d, M the scale tags' mean edge (metric) or the model's size
  // (not), d the value's power of length; its gradient is the value's at fixed M (by central
  // differences over the points it reads) plus (dvalue/dM - d value / M) dM/dY.
  MeasuredItem Evaluate(MeasureKind kind, const std::vector<LocatedPoint>& points) const {
    std::map<int, Eigen::Vector3d> y;
    for (const LocatedPoint& point : points) {
      for (const auto& [index, weight] : point.terms) y[index] = positions[static_cast<size_t>(index)];
      if (point.world && metric) {
        for (int corner = 0; corner < 4; ++corner) {
          const int index = corner_point.at({world_tag, corner});
          y[index] = positions[static_cast<size_t>(index)];
        }
      }
    }
    const std::map<int, Eigen::Vector3d> y0 = y;
    MeasuredItem item;
    item.kind = kind;
    item.value = Function(kind, points, y, y0, scale_mean_, &item.points);
    item.unit = metric ? (LengthPower(kind) == 2 ? "m2" : "m") : (LengthPower(kind) == 2 ? "model units^2" : "model units");
    const double step = 1e-7 * model_spread;  // the central difference's error is far below the σ
    std::vector<PointGradient> gradients;
    for (auto& [index, position] : y) {
      PointGradient gradient{index, Eigen::Vector3d::Zero()};
      for (int axis = 0; axis < 3; ++axis) {
        const double kept = position[axis];
        position[axis] = kept + step;
        const double up = Function(kind, points, y, y0, scale_mean_, nullptr);
        position[axis] = kept - step;
        const double down = Function(kind, points, y, y0, scale_mean_, nullptr);
        position[axis] = kept;
        gradient.gradient[axis] = (up - down) / (2.0 * step);
      }
      gradients.push_back(gradient);
    }
    const double power = LengthPower(kind);
    if (metric) {
      const double scale_step = 1e-7 * scale_mean_;
      const double d_value_d_scale = (Function(kind, points, y0, y0, scale_mean_ + scale_step, nullptr) -
                                      Function(kind, points, y0, y0, scale_mean_ - scale_step, nullptr)) /
                                     (2.0 * scale_step);
      const double d_function_d_scale = d_value_d_scale - power * item.value / scale_mean_;
      std::vector<PointGradient> scale_gradient;
      ScaleMean(&scale_gradient);
      for (PointGradient& g : scale_gradient) g.gradient *= d_function_d_scale;
      gradients.insert(gradients.end(), scale_gradient.begin(), scale_gradient.end());
    } else {
      // M is the RMS distance of spread_points from their centroid c: dM/dY_i = (Y_i - c) / (N M).
      const double n = static_cast<double>(spread_points.size());
      for (int i : spread_points) {
        gradients.push_back({i, -power * item.value * (positions[static_cast<size_t>(i)] - model_centroid) /
                                    (n * model_spread * model_spread)});
      }
    }
    std::map<int, Eigen::Vector3d> merged;  // Variance takes one gradient per point
    for (const PointGradient& g : gradients) {
      merged.emplace(g.point, Eigen::Vector3d::Zero()).first->second += g.gradient;
    }
    gradients.clear();
    for (const auto& [index, gradient] : merged) gradients.push_back({index, gradient});
    const double scale_term = LengthPower(kind) * item.value * scale_relative_sigma;
    const double length_term = LengthPower(kind) * item.value * length_relative_sigma;
    double surface_variance = 0.0;
    for (const PointGradient& gradient : gradients) {
      const auto error = surface_error.find(gradient.point);
      if (error != surface_error.end()) surface_variance += std::pow(gradient.gradient.dot(error->second), 2);
    }
    item.sigma = std::sqrt(model.covariance.Variance(gradients) + surface_variance + scale_term * scale_term +
                           length_term * length_term);
    return item;
  }

  // The scale tags' corners, the scale's spread and σ's calibration by their edges and diagonals.
  void SetUpScale(MeasureSetup* setup) {
    std::vector<int> complete;
    for (int id : setup->scale_tags) {
      std::vector<int> corners;
      for (int corner = 0; corner < 4; ++corner) {
        Result<int> index = CornerPoint(id, corner, "scale tag " + std::to_string(id));
        if (index.ok()) corners.push_back(*index);
      }
      if (corners.size() < 4) continue;
      complete.push_back(id);
      scale_corners.insert(scale_corners.end(), corners.begin(), corners.end());
    }
    setup->scale_tags = complete;
    if (complete.empty()) {
      metric = false;
      return;
    }
    scale_mean_ = ScaleMean(nullptr);
    const double mean = scale_mean_;
    std::vector<double> edges;
    for (size_t t = 0; t < scale_corners.size(); t += 4) {
      for (size_t k = 0; k < 4; ++k) {
        edges.push_back((positions[static_cast<size_t>(scale_corners[t + (k + 1) % 4])] -
                         positions[static_cast<size_t>(scale_corners[t + k])]).norm());
      }
    }
    double spread = 0.0;
    for (double e : edges) spread += (e - mean) * (e - mean) / static_cast<double>(edges.size() - 1);
    scale_relative_sigma = std::sqrt(spread) / mean / std::sqrt(static_cast<double>(edges.size()));
    setup->scale_relative_sigma = scale_relative_sigma;

    const auto segment_of = [&](size_t t, int s) {
      std::vector<LocatedPoint> ends(2);
      ends[0].terms = {{scale_corners[t + static_cast<size_t>(kTagSegments[s][0])], 1.0}};
      ends[1].terms = {{scale_corners[t + static_cast<size_t>(kTagSegments[s][1])], 1.0}};
      return Evaluate(MeasureKind::kDistance, ends);
    };
    // The edges' relative spread beyond what the covariance and the scale's own term explain.
    double relative_variance = 0.0, explained = 0.0;
    size_t edge = 0;
    for (size_t t = 0; t < scale_corners.size(); t += 4) {
      for (int s = 0; s < 4; ++s, ++edge) {
        const MeasuredItem segment = segment_of(t, s);
        relative_variance += std::pow(edges[edge] / mean - 1.0, 2) / static_cast<double>(edges.size() - 1);
        if (std::isfinite(segment.sigma)) explained += std::pow(segment.sigma / segment.value, 2) / static_cast<double>(edges.size());
      }
    }
    length_relative_sigma = std::sqrt(std::max(0.0, relative_variance - explained));
    if (square_check_rms > 0.0) {
      // The scale tags were held as squares: their own edges no longer show how the model's scale
      // varies; the tags the mapper's cross-check left out of the squares do.
      length_relative_sigma = square_check_rms;
      scale_relative_sigma = square_check_rms / std::sqrt(static_cast<double>(complete.size()));
      setup->scale_relative_sigma = scale_relative_sigma;
    }
    setup->length_relative_sigma = length_relative_sigma;
    std::vector<double> normalised;
    for (size_t t = 0; t < scale_corners.size(); t += 4) {
      for (int s = 0; s < 6; ++s) {
        const MeasuredItem segment = segment_of(t, s);
        const double truth = s < 4 ? tag_size : tag_size * std::sqrt(2.0);
        if (segment.sigma > 0.0 && std::isfinite(segment.sigma)) {
          normalised.push_back(std::abs(segment.value - truth) / segment.sigma);
        }
      }
    }
    setup->scale_segments = static_cast<int>(normalised.size());
    if (normalised.empty()) return;
    double squares = 0.0;
    for (double e : normalised) squares += e * e;
    std::sort(normalised.begin(), normalised.end());
    const double rms = std::sqrt(squares / static_cast<double>(normalised.size()));
    const double p95 = normalised[std::min(normalised.size() - 1,
                                           static_cast<size_t>(std::ceil(0.95 * static_cast<double>(normalised.size()))) - 1)];
    calibration = std::max({1.0, rms, p95 / 1.96});
    setup->sigma_calibration = calibration;
  }
};

ProjectMeasurer::ProjectMeasurer(std::unique_ptr<State> state) : state_(std::move(state)) {}
ProjectMeasurer::ProjectMeasurer(ProjectMeasurer&&) noexcept = default;
ProjectMeasurer& ProjectMeasurer::operator=(ProjectMeasurer&&) noexcept = default;
ProjectMeasurer::~ProjectMeasurer() = default;

Result<ProjectMeasurer> ProjectMeasurer::Open(const Project& project, const MeasureOptions& options) {
  const Clock::time_point start = Clock::now();
  std::error_code error;
  if (!std::filesystem::exists(project.SparseDir() + "/points3D.txt", error)) {
    return NotFound(project.root() + " has no sparse model (" + project.SparseDir() +
                    "/points3D.txt is missing): run `reconar reconstruct` first");
  }
  auto state = std::make_unique<State>(project);
  state->options = options;
  RECONAR_ASSIGN_OR_RETURN(state->model, ComputeProjectCovariance(project));
  const Reconstruction& model = state->model.model;
  for (size_t i = 0; i < model.images.size(); ++i) state->image_of_name[model.images[i].name] = static_cast<int>(i);
  for (size_t p = 0; p < model.points.size(); ++p) {
    if (state->model.problem_point[p] >= 0) state->positions.push_back(model.points[p].position);
  }
  for (int i = 0; i < static_cast<int>(state->positions.size()); ++i) {
    if (state->model.covariance.determined(i)) state->spread_points.push_back(i);
  }
  if (!state->spread_points.empty()) {
    const double n = static_cast<double>(state->spread_points.size());
    for (int i : state->spread_points) state->model_centroid += state->positions[static_cast<size_t>(i)] / n;
    double squares = 0.0;
    for (int i : state->spread_points) squares += (state->positions[static_cast<size_t>(i)] - state->model_centroid).squaredNorm();
    state->model_spread = std::sqrt(squares / n);
  }
  if (!(state->model_spread > 0.0)) return FailedPrecondition(project.SparseDir() + ": the model has no extent");
  MeasureSetup setup;
  setup.cameras = model.NumRegisteredImages();
  setup.points = static_cast<int>(state->positions.size());
  setup.observations = state->model.observations;
  setup.sigma0_px = std::sqrt(state->model.covariance.variance_factor());
  if (std::filesystem::exists(project.TagsJsonPath(), error)) {
    RECONAR_ASSIGN_OR_RETURN(const JsonValue tags, ReadJsonFile(project.TagsJsonPath()));
    const JsonValue* metric = tags.Find("metric");
    const JsonValue* size = tags.Find("tag_size_m");
    const JsonValue* world = tags.Find("world_tag");
    if (metric != nullptr && metric->is_bool() && metric->bool_value() && size != nullptr && size->is_number() &&
        size->number() > 0.0 && world != nullptr && world->AsInteger()) {
      state->metric = true;
      state->tag_size = size->number();
      state->world_tag = static_cast<int>(*world->AsInteger());
      const JsonValue* scale = tags.Find("scale_tags");
      const JsonValue* all = tags.Find("tags");
      if (scale != nullptr && scale->is_array() && scale->size() > 0) {
        for (size_t k = 0; k < scale->size(); ++k) {
          if ((*scale)[k].AsInteger()) setup.scale_tags.push_back(static_cast<int>(*(*scale)[k].AsInteger()));
        }
      } else if (all != nullptr && all->is_array()) {
        for (size_t k = 0; k < all->size(); ++k) {
          const JsonValue* id = (*all)[k].Find("id");
          if (id != nullptr && id->AsInteger()) setup.scale_tags.push_back(static_cast<int>(*id->AsInteger()));
        }
      }
      const JsonValue* check = tags.Find("square_check");
      const JsonValue* check_rms = check != nullptr ? check->Find("rms_relative_error") : nullptr;
      if (check_rms != nullptr && check_rms->is_number() && check_rms->number() > 0.0) {
        state->square_check_rms = check_rms->number();
      }
      state->SetUpScale(&setup);
    }
  }
  setup.metric = state->metric;
  setup.tag_size_m = state->tag_size;
  setup.seconds_setup = std::chrono::duration<double>(Clock::now() - start).count();
  ProjectMeasurer measurer(std::move(state));
  measurer.setup_ = setup;
  return measurer;
}

Result<MeasuredItem> ProjectMeasurer::Measure(const MeasureItem& item) {
  const size_t n = item.points.size();
  const bool count_ok = item.kind == MeasureKind::kDistance ? n == 2
                        : item.kind == MeasureKind::kPath   ? n >= 2
                        : item.kind == MeasureKind::kArea   ? n >= 3
                                                            : n == 4;
  if (!count_ok) {
    return InvalidArgument(std::string(MeasureKindName(item.kind)) + " takes " +
                           (item.kind == MeasureKind::kDistance ? "2 points"
                            : item.kind == MeasureKind::kPath   ? "2 or more points"
                            : item.kind == MeasureKind::kArea   ? "3 or more points (a polygon)"
                                                                : "a point and a plane of 3 points") +
                           ", got " + std::to_string(n));
  }
  std::vector<LocatedPoint> located;
  for (const MeasurePoint& point : item.points) {
    RECONAR_ASSIGN_OR_RETURN(LocatedPoint one, state_->Locate(point));
    located.push_back(std::move(one));
  }
  MeasuredItem measured = state_->Evaluate(item.kind, located);
  if (item.kind == MeasureKind::kHeight && !std::isfinite(measured.value)) {
    return InvalidArgument("height: the plane's three points are on one line");
  }
  measured.sigma *= state_->calibration;
  for (const MeasurePoint& point : item.points) measured.point_texts.push_back(point.text);
  return measured;
}

Status ProjectMeasurer::LoadSurface() { return state_->ReadSurface(); }

Result<MeasuredItem> ProjectMeasurer::MeasureBetweenPixels(const Rigid3& cam_from_world, const RadialCamera& camera,
                                                           const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const size_t mark = state_->positions.size();
  MeasureItem item;
  Result<MeasuredItem> measured = [&]() -> Result<MeasuredItem> {
    for (const Eigen::Vector2d& pixel : {a, b}) {
      Eigen::Vector2d normalised;
      if (!camera.Undistort(pixel, &normalised)) {
        return InvalidArgument("pixel (" + std::to_string(pixel.x()) + ", " + std::to_string(pixel.y()) +
                               ") is beyond the camera's lens model");
      }
      const Eigen::Vector3d direction = cam_from_world.rotation.transpose() * normalised.homogeneous();
      RECONAR_ASSIGN_OR_RETURN(MeasurePoint point, PointOnSurface(CameraCenterInWorld(cam_from_world), direction));
      item.points.push_back(std::move(point));
    }
    return Measure(item);
  }();
  state_->Rewind(mark);
  return measured;
}

Result<MeasurePoint> ProjectMeasurer::PointOnSurface(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  RECONAR_ASSIGN_OR_RETURN(const int index, state_->PlaceOnSurface(origin, direction, nullptr, "the picked point"));
  MeasurePoint point;
  point.kind = MeasurePointKind::kPlaced;
  point.placed = index;
  point.world = state_->positions[static_cast<size_t>(index)];
  point.text = "surface@" + std::to_string(point.world.x()) + "," + std::to_string(point.world.y()) + "," +
               std::to_string(point.world.z());
  return point;
}

std::string MeasurementsJson(const MeasureSetup& setup, const std::vector<MeasuredItem>& items) {
  JsonWriter json(2);
  json.BeginObject().Key("metric").Bool(setup.metric);
  json.Key("setup").BeginObject();
  json.Key("tag_size_m").Double(setup.tag_size_m);
  json.Key("scale_tags").BeginArray();
  for (int id : setup.scale_tags) json.Int(id);
  json.EndArray();
  json.Key("scale_segments").Int(setup.scale_segments);
  json.Key("sigma_calibration").Double(setup.sigma_calibration);
  json.Key("scale_relative_sigma").Double(setup.scale_relative_sigma);
  json.Key("length_relative_sigma").Double(setup.length_relative_sigma);
  json.Key("sigma0_px").Double(setup.sigma0_px);
  json.Key("cameras").Int(setup.cameras).Key("points").Int(setup.points).Key("observations").Int(setup.observations);
  json.Key("seconds_setup").Double(setup.seconds_setup);
  json.EndObject();
  json.Key("items").BeginArray();
  for (const MeasuredItem& item : items) json.Raw(MeasuredItemJson(item));
  json.EndArray().EndObject();
  return json.str() + "\n";
}

std::string MeasuredItemJson(const MeasuredItem& item) {
  JsonWriter json;
  json.BeginObject().Key("kind").String(MeasureKindName(item.kind));
  json.Key("point_names").BeginArray();
  for (const std::string& text : item.point_texts) json.String(text);
  json.EndArray();
  json.Key("points").BeginArray();
  for (const Eigen::Vector3d& p : item.points) json.BeginArray().Double(p.x()).Double(p.y()).Double(p.z()).EndArray();
  json.EndArray();
  json.Key("value").Double(item.value).Key("sigma").Double(item.sigma).Key("unit").String(item.unit);
  json.EndObject();
  return json.str();
}

}  // namespace reconar
