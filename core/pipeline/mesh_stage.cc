#include "core/pipeline/mesh_stage.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/base/atomic_file.h"
#include "core/base/json_writer.h"
#include "core/base/keep_masked.h"
#include "core/base/median.h"
#include "core/base/memory_usage.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/poisson/point_kdtree.h"
#include "core/mesh/poisson/point_normals.h"
#include "core/pipeline/stage_record.h"
#include "core/pipeline/texture_stage.h"

namespace reconar {
namespace {

constexpr int kMinDepth = 5;


// Median over (at most 20,000 evenly strided) points of the mean distance to their 8 nearest.
double MedianSpacing(const std::vector<Eigen::Vector3f>& positions) {
  const poisson::PointKdTree tree(positions);
  const size_t stride = std::max<size_t>(1, positions.size() / 20000);
  std::vector<double> spacing;
  std::vector<std::pair<float, uint32_t>> nearest;
  for (size_t i = 0; i < positions.size(); i += stride) {
    tree.Nearest(positions[i], 9, &nearest);
    double sum = 0.0;
    for (size_t j = 1; j < nearest.size(); ++j) sum += std::sqrt(nearest[j].first);
    if (nearest.size() > 1) spacing.push_back(sum / static_cast<double>(nearest.size() - 1));
  }
  if (spacing.empty()) return 0.0;
  return MedianInPlace(spacing.data(), spacing.size());
}

}  // namespace

Status MeshStageOptions::Check() const {
  RECONAR_RETURN_IF_ERROR(poisson.Check());
  if (formats.empty()) return InvalidArgument("mesh stage: no output format");
  for (const std::string& format : formats) {
    RECONAR_RETURN_IF_ERROR(MeshFileFormatOf("mesh." + format).status());
  }
  return Status::Ok();
}

Result<MeshStageReport> MeshPointsFile(const std::string& points_path, const std::vector<std::string>& mesh_paths,
                                       const MeshStageOptions& options, const MeshFileOptions& file_options) {
  RECONAR_RETURN_IF_ERROR(options.poisson.Check());
  RECONAR_RETURN_IF_ERROR(ReadableMeshFileFormatOf(points_path).status());
  for (const std::string& path : mesh_paths) RECONAR_RETURN_IF_ERROR(MeshFileFormatOf(path).status());
  const auto start = std::chrono::steady_clock::now();
  ResetPeakResidentBytes();
  MeshStageReport report;
  RECONAR_ASSIGN_OR_RETURN(Mesh points, ReadMeshFile(points_path));
  points.triangles.clear();
  report.points = points.positions.size();
  if (options.remove_outliers) {
    OutlierFilterOptions outliers = options.outliers;
    if (outliers.num_threads == 0) outliers.num_threads = options.poisson.num_threads;
    const auto keep = FindInlierPoints(points.positions, outliers, &report.outliers);
    if (!keep.ok()) return keep.status().WithContext(points_path);
    KeepMasked(*keep, &points.positions);
    KeepMasked(*keep, &points.normals);
    KeepMasked(*keep, &points.colors);
  }
  if (options.estimate_normals) {
    RECONAR_RETURN_IF_ERROR(EstimateNormals(&points, NormalEstimationOptions()).WithContext(points_path));
    report.normals_estimated = true;
  } else if (points.normals.empty()) {
    return FileError(StatusCode::kInvalidArgument, points_path,
                     "the points have no normals (Poisson needs oriented points; --estimate-normals estimates them)");
  }
  report.requested_depth = report.depth = options.poisson.depth;
  if (options.depth_from_spacing) {
    Eigen::Vector3f lo = points.positions.front(), hi = lo;
    for (const Eigen::Vector3f& p : points.positions) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    report.median_spacing = MedianSpacing(points.positions);
    const double cube = options.poisson.scale * static_cast<double>((hi - lo).maxCoeff());
    if (report.median_spacing > 0.0 && cube > 0.0) {
      report.spacing_depth = std::max(kMinDepth, static_cast<int>(std::ceil(std::log2(cube / report.median_spacing))));
      report.depth = std::min(report.depth, report.spacing_depth);
    }
  }

  if (options.memory_budget_bytes > 0 && report.depth > kMinDepth) {
    PoissonOptions pilot = options.poisson;
    pilot.depth = std::max(kMinDepth, report.depth - 2);
    pilot.trim = 0.0;
    pilot.show_progress = false;
    ReleaseFreeHeapMemory();
    const size_t baseline = CurrentMemoryUsage().resident_bytes;
    ResetPeakResidentBytes();
    RECONAR_RETURN_IF_ERROR(ReconstructPoissonSurface(points, pilot, nullptr).status());
    report.pilot_peak_bytes = PeakResidentBytes() > baseline ? PeakResidentBytes() - baseline : 0;
    ResetPeakResidentBytes();
    int depth = report.depth;
    for (; depth >= kMinDepth; --depth) {
      const double growth = depth >= pilot.depth ? static_cast<double>(1ull << (2 * (depth - pilot.depth))) : 1.0;
      report.estimated_peak_bytes =
          baseline + static_cast<size_t>(growth * static_cast<double>(report.pilot_peak_bytes));
      if (report.estimated_peak_bytes <= options.memory_budget_bytes) break;
    }
    if (depth < kMinDepth) {
      return ResourceExhausted("mesh: even depth " + std::to_string(kMinDepth) + " needs an estimated " +
                               std::to_string(static_cast<int>(Mib(report.estimated_peak_bytes))) +
                               " MiB, over the budget of " +
                               std::to_string(static_cast<int>(Mib(options.memory_budget_bytes))) + " MiB");
    }
    report.depth_lowered_for_budget = depth < report.depth;
    report.depth = depth;
  }

  PoissonOptions poisson = options.poisson;
  poisson.depth = report.depth;
  if (options.depth_from_spacing && poisson.trim > 0.0) {
    poisson.trim = std::min(poisson.trim, static_cast<double>(report.depth - 1));
  }
  auto surface = ReconstructPoissonSurface(points, poisson, &report.poisson);
  if (!surface.ok()) return surface.status().WithContext(points_path);
  Mesh mesh = std::move(*surface);
  RECONAR_ASSIGN_OR_RETURN(report.simplify, SimplifyToFaceBudget(options.max_faces, &mesh));
  report.simplified = report.simplify.simplified;
  report.vertices = mesh.positions.size();
  report.faces = mesh.triangles.size();
  for (const std::string& path : mesh_paths) {
    const size_t slash = path.find_last_of('/');
    if (slash != std::string::npos && slash > 0) RECONAR_RETURN_IF_ERROR(CreateDirectories(path.substr(0, slash)));
    RECONAR_RETURN_IF_ERROR(WriteMeshFile(path, mesh, file_options));
    report.paths.push_back(path);
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.peak_rss_bytes = PeakResidentBytes();
  return report;
}

std::string MeshStageSettings(const MeshStageOptions& options) {
  std::string formats;
  for (const std::string& f : options.formats) formats += (formats.empty() ? "" : ",") + f;
  return StageRecord::Settings({{"version", 2},
                                {"depth", options.poisson.depth},
                                {"trim", options.poisson.trim},
                                {"point_weight", options.poisson.point_weight},
                                {"budget_mib", Mib(options.memory_budget_bytes)},
                                {"max_faces", static_cast<double>(options.max_faces)}}) +
         " formats=" + formats;
}

Result<MeshStageReport> RunMeshStage(const Project& project, const MeshStageOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (::access(project.DensePointsPath().c_str(), F_OK) != 0) {
    return FailedPrecondition(project.DensePointsPath() + ": no dense points; run the dense stage first");
  }
  std::vector<std::string> paths;
  for (const std::string& format : options.formats) paths.push_back(project.MeshDir() + "/mesh." + format);
  RECONAR_ASSIGN_OR_RETURN(MeshStageReport report, MeshPointsFile(project.DensePointsPath(), paths, options));
  RECONAR_RETURN_IF_ERROR(RemoveTexturedModel(project));
  report.report_path = project.MeshDir() + "/report.json";
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(report.report_path, MeshReportJson(report)));
  return report;
}

std::string MeshReportJson(const MeshStageReport& report) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("points").Int(static_cast<long long>(report.points));
  if (report.outliers.input_points > 0) {
    json.Key("outliers_removed")
        .Int(static_cast<long long>(report.outliers.input_points - report.outliers.kept_points()));
  }
  json.Key("normals_estimated").Bool(report.normals_estimated);
  json.Key("requested_depth").Int(report.requested_depth).Key("median_spacing").Double(report.median_spacing);
  json.Key("spacing_depth").Int(report.spacing_depth).Key("depth").Int(report.depth);
  json.Key("depth_lowered_for_memory_budget").Bool(report.depth_lowered_for_budget);
  json.Key("pilot_peak_mib").Double(Mib(report.pilot_peak_bytes));
  json.Key("estimated_peak_mib").Double(Mib(report.estimated_peak_bytes));
  json.Key("vertices").Int(static_cast<long long>(report.vertices));
  json.Key("triangles").Int(static_cast<long long>(report.faces));
  json.Key("poisson_vertices").Int(static_cast<long long>(report.poisson.vertices));
  json.Key("poisson_triangles").Int(static_cast<long long>(report.poisson.triangles));
  json.Key("simplified").Bool(report.simplified);
  if (report.simplified) {
    json.Key("simplify_seconds").Double(report.simplify.seconds);
    json.Key("simplify_max_error").Double(report.simplify.max_collapse_error);
  }
  json.Key("octree_nodes").Int(report.poisson.octree_nodes).Key("unknowns").Int(report.poisson.unknowns);
  json.Key("watertight_gaps").Int(static_cast<long long>(report.poisson.cells_skipped));
  json.Key("seconds").Double(report.seconds);
  json.Key("peak_rss_mib").Double(Mib(report.peak_rss_bytes));
  json.Key("files").BeginArray();
  for (const std::string& path : report.paths) json.String(path);
  json.EndArray();
  json.EndObject();
  return json.str() + "\n";
}

}  // namespace reconar
