#include "core/pipeline/mesh_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/base/atomic_file.h"
#include "core/base/json_writer.h"
#include "core/base/memory_usage.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/poisson/point_kdtree.h"

namespace reconar {
namespace {

constexpr int kMinDepth = 5;

double Mib(size_t bytes) { return static_cast<double>(bytes) / (1 << 20); }

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
  std::nth_element(spacing.begin(), spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2), spacing.end());
  return spacing[spacing.size() / 2];
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

Result<MeshStageReport> RunMeshStage(const Project& project, const MeshStageOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  const auto start = std::chrono::steady_clock::now();
  ResetPeakResidentBytes();
  MeshStageReport report;
  auto points = ReadMeshFile(project.DensePointsPath());
  if (!points.ok()) {
    if (points.status().code() == StatusCode::kNotFound) {
      return FailedPrecondition(project.DensePointsPath() + ": no dense points; run the dense stage first");
    }
    return points.status();
  }
  points->triangles.clear();
  report.points = points->positions.size();
  if (points->normals.empty()) {
    return FileError(StatusCode::kCorruptData, project.DensePointsPath(), "the points have no normals");
  }
  report.requested_depth = report.depth = options.poisson.depth;
  Eigen::Vector3f lo = points->positions.front(), hi = lo;
  for (const Eigen::Vector3f& p : points->positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  report.median_spacing = MedianSpacing(points->positions);
  const double cube = options.poisson.scale * static_cast<double>((hi - lo).maxCoeff());
  if (report.median_spacing > 0.0 && cube > 0.0) {
    report.spacing_depth = std::max(kMinDepth, static_cast<int>(std::ceil(std::log2(cube / report.median_spacing))));
    report.depth = std::min(report.depth, report.spacing_depth);
  }

  if (options.memory_budget_bytes > 0 && report.depth > kMinDepth) {
    PoissonOptions pilot = options.poisson;
    pilot.depth = std::max(kMinDepth, report.depth - 2);
    pilot.trim = 0.0;
    pilot.show_progress = false;
    ReleaseFreeHeapMemory();
    const size_t baseline = CurrentMemoryUsage().resident_bytes;
    ResetPeakResidentBytes();
    RECONAR_RETURN_IF_ERROR(ReconstructPoissonSurface(*points, pilot, nullptr).status());
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
  if (poisson.trim > 0.0) poisson.trim = std::min(poisson.trim, static_cast<double>(report.depth - 1));
  RECONAR_ASSIGN_OR_RETURN(Mesh mesh, ReconstructPoissonSurface(*points, poisson, &report.poisson));
  if (options.max_faces > 0 && mesh.triangles.size() > options.max_faces) {
    SimplifyOptions simplify;
    simplify.target_faces = options.max_faces;
    RECONAR_ASSIGN_OR_RETURN(report.simplify, SimplifyMesh(simplify, &mesh));
    report.simplified = true;
  }
  report.vertices = mesh.positions.size();
  report.faces = mesh.triangles.size();
  RECONAR_RETURN_IF_ERROR(CreateDirectories(project.MeshDir()));
  for (const std::string& format : options.formats) {
    const std::string path = project.MeshDir() + "/mesh." + format;
    RECONAR_RETURN_IF_ERROR(WriteMeshFile(path, mesh, MeshFileOptions()));
    report.paths.push_back(path);
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.peak_rss_bytes = PeakResidentBytes();
  report.report_path = project.MeshDir() + "/report.json";
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(report.report_path, MeshReportJson(report)));
  return report;
}

std::string MeshReportJson(const MeshStageReport& report) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("points").Int(static_cast<long long>(report.points));
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
