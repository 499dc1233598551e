#include "core/compare/compare_project.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include <Eigen/Geometry>
#include <filesystem>
#include <set>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/base/json_writer.h"
#include "core/compare/report_picture.h"
#include "core/io/image_write.h"
#include "core/math/point_spread.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/mesh_io.h"
#include "core/sfm/model_io.h"
#include "core/sfm/tag_layout.h"
#include "core/sfm/tag_squares.h"

namespace reconar {
namespace {

Result<std::vector<ControlPair>> ControlPairs(const Project& project, const std::string& control_path) {
  RECONAR_ASSIGN_OR_RETURN(const std::vector<ControlTag> tags, ReadControlFile(control_path));
  std::vector<ControlPair> pairs;
  bool any_tag = false;
  for (const ControlTag& tag : tags) {
    if (tag.id < 0) pairs.push_back({-1, tag.design_points[0], tag.world_point});
    any_tag = any_tag || tag.id >= 0;
  }
  if (!any_tag) return pairs;
  std::error_code error;
  if (!std::filesystem::exists(project.TagLayoutPath(), error)) {
    return FailedPrecondition(project.root() + " has no registered tags (" + project.TagLayoutPath() +
                              " is missing: reconstruct with --tag-size) for the control in " + control_path);
  }
  RECONAR_ASSIGN_OR_RETURN(const TagLayout layout, ReadTagLayout(project.TagLayoutPath()));
  for (const ControlTag& tag : tags) {
    if (tag.id < 0) continue;
    const LayoutTag* placed = layout.Find(tag.id);
    if (placed == nullptr) {
      return FileError(StatusCode::kInvalidArgument, control_path,
                       "line " + std::to_string(tag.line) + ": tag " + std::to_string(tag.id) +
                           " is not among the project's reconstructed tags (" + project.TagLayoutPath() + ")");
    }
    if (tag.design_points.size() == 1) {
      pairs.push_back({tag.id, tag.design_points[0], placed->layout_from_tag.translation});
    } else {
      const std::array<Eigen::Vector3d, 4> corners = TagSquareCorners(placed->size);
      for (size_t k = 0; k < 4; ++k) pairs.push_back({tag.id, tag.design_points[k], placed->layout_from_tag * corners[k]});
    }
  }
  return pairs;
}

}  // namespace

Result<CompareReport> CompareWithDesign(const Project& project, const std::string& design_path,
                                        const CompareOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CompareReport report;
  report.design_path = design_path;
  RECONAR_ASSIGN_OR_RETURN(const Design design, ReadDesign(design_path));

  std::error_code error;
  if (std::filesystem::exists(project.TagsJsonPath(), error)) {
    RECONAR_ASSIGN_OR_RETURN(const JsonValue tags, ReadJsonFile(project.TagsJsonPath()));
    const JsonValue* metric = tags.Find("metric");
    report.metric = metric != nullptr && metric->is_bool() && metric->bool_value();
  }
  std::vector<ControlPair> control;
  if (!options.control_path.empty()) {
    RECONAR_ASSIGN_OR_RETURN(control, ControlPairs(project, options.control_path));
  }
  std::set<int> control_tags;
  for (const ControlPair& pair : control) {
    if (pair.tag >= 0) control_tags.insert(pair.tag);
  }
  report.control_tags = static_cast<int>(control_tags.size());
  report.control_points = static_cast<int>(std::count_if(control.begin(), control.end(),
                                                          [](const ControlPair& pair) { return pair.tag < 0; }));

  // The as-built points: the dense points (with their normals), else the mesh's vertices, else
  // the sparse points (thin, but what a project of the sparse stage alone has).
  Result<Reconstruction> views = ReadColmapTextModel(project.SparseDir());
  std::string source = project.DensePointsPath();
  if (!std::filesystem::exists(source, error)) source = project.MeshDir() + "/mesh.ply";
  Mesh cloud;
  if (std::filesystem::exists(source, error)) {
    RECONAR_ASSIGN_OR_RETURN(cloud, ReadMeshFile(source));
  } else if (views.ok()) {
    source = project.SparseDir();
    for (const SfmPoint& point : views->points) {
      if (!point.deleted) cloud.positions.push_back(point.position.cast<float>());
    }
  } else {
    return FailedPrecondition(project.root() + " has no dense points (" + project.DensePointsPath() +
                              "), mesh nor sparse model to compare with the design: run `reconar reconstruct`");
  }
  if (cloud.positions.empty()) return FileError(StatusCode::kCorruptData, source, "no points");
  report.as_built_source = source;
  report.as_built_points = static_cast<int>(cloud.positions.size());
  std::vector<Eigen::Vector3d> points, normals;
  points.reserve(cloud.positions.size());
  for (const Eigen::Vector3f& p : cloud.positions) points.push_back(p.cast<double>());
  for (const Eigen::Vector3f& n : cloud.normals) normals.push_back(n.cast<double>());

  // A project without metres takes them from the design (drawn in metres unless the control's
  // scale is fitted on request): its scale fitted to the control, everything is measured in a
  // metric copy of the world, so that tolerances, distances and sizes are metres.
  if (!report.metric && !control.empty() && !options.registration.similarity) {
    DesignRegistrationOptions scale_only = options.registration;
    scale_only.similarity = true;
    scale_only.refine = false;
    RECONAR_ASSIGN_OR_RETURN(const DesignRegistration scaled, RegisterDesign(design, control, {}, scale_only));
    report.world_units_per_metre = scaled.world_from_design.scale;
    report.units_assumed = true;
  }
  const double metres_per_world_unit = 1.0 / report.world_units_per_metre;
  std::vector<Eigen::Vector3d> metric_points = points;
  for (Eigen::Vector3d& p : metric_points) p *= metres_per_world_unit;
  for (ControlPair& pair : control) pair.world *= metres_per_world_unit;
  if (views.ok()) {
    for (SfmImage& image : views->images) image.cam_from_world.translation *= metres_per_world_unit;
  }
  RECONAR_ASSIGN_OR_RETURN(report.registration, RegisterDesign(design, control, metric_points, options.registration));
  RECONAR_ASSIGN_OR_RETURN(report.deviation,
                           ComputeDeviation(design, report.registration.world_from_design, metric_points, normals,
                                            views.ok() ? &*views : nullptr, options.deviation));
  // A design placed where the model is not: nothing to compare, and a report would only say
  // "missing" everywhere.
  const long on_design = std::count_if(report.deviation.element_of_point.begin(),
                                       report.deviation.element_of_point.end(), [](int e) { return e >= 0; });
  if (on_design == 0) {
    return FailedPrecondition("the design " + design_path + " does not overlap the model: no as-built point of " +
                              source + " lies within " + std::to_string(options.deviation.max_distance) +
                              " m of it" + (control.empty() ? " (no --control: the design is taken as drawn in the "
                                                              "world frame)"
                                                            : "; check the control file " + options.control_path));
  }
  if (on_design < static_cast<long>(points.size() / 100)) {
    char warning[200];
    std::snprintf(warning, sizeof(warning),
                  "only %.2f %% of the as-built points lie within %.3g m of the design: is it placed right?",
                  100.0 * static_cast<double>(on_design) / static_cast<double>(points.size()),
                  options.deviation.max_distance);
    report.warnings.push_back(warning);
  }
  // Back to the world frame: world_from_design = world_from_metric * metric_from_design.
  Sim3& world_from_design = report.registration.world_from_design;
  world_from_design.scale *= report.world_units_per_metre;
  world_from_design.translation *= report.world_units_per_metre;

  report.out_dir = project.root() + "/compare";
  std::filesystem::create_directories(report.out_dir, error);
  if (error) return IoError(report.out_dir + ": " + error.message());
  Mesh coloured;
  coloured.positions = cloud.positions;
  coloured.colors.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    coloured.colors.push_back(report.deviation.element_of_point[i] < 0
                                  ? std::array<uint8_t, 4>{128, 128, 128, 255}
                                  : DeviationColour(report.deviation.signed_distance_m[i], 3.0 * options.deviation.tolerance));
  }
  RECONAR_RETURN_IF_ERROR(WritePly(report.out_dir + "/deviation.ply", coloured));
  // The same points as glTF, with the colour scale as a strip beside them (a third of their width,
  // along the world's x at the corner of their bounding box).
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : points) box.extend(p);
  const double width = std::max(box.sizes().maxCoeff(), 1e-6);
  const std::vector<NamedMesh> deviation_scene = {
      {"as built, coloured by its deviation from the design", coloured},
      DeviationLegendStrip(3.0 * options.deviation.tolerance, report.world_units_per_metre,
                           box.min() - 0.05 * width * Eigen::Vector3d::UnitZ(), width / 3.0 * Eigen::Vector3d::UnitX(),
                           width / 30.0 * Eigen::Vector3d::UnitY())};
  RECONAR_RETURN_IF_ERROR(WriteGlbScene(report.out_dir + "/deviation.glb", deviation_scene));
  std::vector<NamedMesh> placed = PlacedElements(design, report.registration.world_from_design);
  for (NamedMesh& element : placed) ComputeVertexNormals(&element.mesh);
  RECONAR_RETURN_IF_ERROR(WriteGlbScene(report.out_dir + "/design_registered.glb", placed));
  // The top view looks down the world's up: the tag board's y for a project registered by tags,
  // else the points' thinnest direction (the floor's normal for a room, a wall's for a facade).
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  if (!report.metric) up = SpreadOfPoints(metric_points).ThinnestAxis();
  const Image<uint8_t> picture = DrawCompareReport(report, options, metric_points, up);
  RECONAR_RETURN_IF_ERROR(WritePng(report.out_dir + "/report.png", picture.view(), 3));
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(report.out_dir + "/report.json", CompareReportJson(report, options)));
  return report;
}

std::string CompareReportJson(const CompareReport& report, const CompareOptions& options) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("design").String(report.design_path);
  json.Key("as_built").BeginObject().Key("source").String(report.as_built_source).Key("points").Int(report.as_built_points).EndObject();
  json.Key("metric").Bool(report.metric);
  json.Key("tolerance_m").Double(options.deviation.tolerance);
  const DesignRegistration& r = report.registration;
  json.Key("registration").BeginObject();
  json.Key("world_from_design").BeginArray();
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = r.world_from_design.scale * r.world_from_design.rotation;
  m.topRightCorner<3, 1>() = r.world_from_design.translation;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) json.Double(m(row, col));
  json.EndArray();
  json.Key("scale").Double(r.world_from_design.scale);
  json.Key("units").String(r.units);
  json.Key("units_assumed").Bool(report.units_assumed);
  json.Key("world_units_per_metre").Double(report.world_units_per_metre);
  json.Key("control_tags").Int(report.control_tags);
  json.Key("control_points").Int(report.control_points);
  json.Key("control_rms_m").Double(r.control_rms_m);
  json.Key("control_residuals_m").BeginArray();
  for (double residual : r.control_residuals_m) json.Double(residual);
  json.EndArray();
  json.Key("refined").Bool(r.refined);
  if (!r.icp_rejected.empty()) json.Key("icp_rejected").String(r.icp_rejected);
  json.Key("icp_rms_m").Double(r.icp_rms_m);
  json.Key("points_used").Int(r.points_used);
  json.Key("overlap").Double(r.overlap);
  json.Key("icp_iterations").Int(r.icp_iterations);
  json.Key("icp_turn_deg").Double(r.icp_turn_deg);
  json.Key("icp_shift_m").Double(r.icp_shift_m);
  json.Key("free_directions").Int(r.free_directions);
  json.EndObject();
  json.Key("density_per_m2").Double(report.deviation.density_per_m2);
  json.Key("elements").BeginArray();
  for (const ElementDeviation& e : report.deviation.elements) {
    json.BeginObject();
    json.Key("name").String(e.name).Key("points").Int(e.points);
    json.Key("area_m2").Double(e.area_m2).Key("seen_area_m2").Double(e.seen_area_m2);
    json.Key("mean_m").Double(e.mean_m).Key("rms_m").Double(e.rms_m).Key("p95_m").Double(e.p95_m);
    json.Key("within_tolerance").Double(e.within_tolerance);
    json.Key("shift_m").BeginArray().Double(e.shift_m.x()).Double(e.shift_m.y()).Double(e.shift_m.z()).EndArray();
    json.Key("turn_deg").Double(e.turn_deg).Key("largest_move_m").Double(e.largest_move_m);
    json.Key("verdict").String(e.verdict);
    json.EndObject();
  }
  json.EndArray();
  json.Key("warnings").BeginArray();
  for (const std::string& warning : report.warnings) json.String(warning);
  json.EndArray();
  json.Key("seconds").Double(report.seconds);
  json.EndObject();
  return json.str() + "\n";
}

}  // namespace reconar
