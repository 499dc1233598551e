// `reconar mesh`: Poisson surface reconstruction of oriented points (core/mesh/poisson).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "core/base/json_writer.h"
#include "core/base/keep_masked.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/poisson/point_normals.h"
#include "core/mesh/poisson/point_outliers.h"
#include "core/mesh/poisson/poisson.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar mesh INPUT.ply OUTPUT.{ply,obj,glb,wrl} [options]\n"
    "\n"
    "Screened Poisson surface reconstruction (Kazhdan & Hoppe 2013) of oriented points, e.g. the\n"
    "dense points of `reconar dense` (PROJECT/dense/points.ply): positions with outward unit normals,\n"
    "optional colours (carried over to the mesh). INPUT may also be .obj or .glb; OUTPUT's extension\n"
    "chooses the format (see `reconar export --help`). Progress goes to stderr.\n"
    "  --depth N            finest grid 2^N cells per edge of the bounding cube (default 8)\n"
    "  --trim T             drop surface whose sample density depth is below T, e.g. where Poisson\n"
    "                       closed holes in the data (default 0: keep everything; try depth - 1)\n"
    "  --point-weight W     screening weight: how closely the surface follows the points (default 1, as COLMAP)\n"
    "  --remove-outliers    drop isolated points and small floating pieces first (core/mesh/poisson/\n"
    "                       point_outliers.h; `reconar dense` already does this to its output)\n"
    "  --estimate-normals   estimate normals from the nearest neighbours (replaces normals in INPUT)\n"
    "  --threads N          worker threads (default: one per core)\n"
    "  --ascii              write .ply as ASCII\n"
    "  --json               print a JSON report on stdout\n";

double Seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

struct MeshRun {
  std::string input, output;
  size_t points = 0;
  bool normals_estimated = false;
  OutlierFilterReport outliers;
  PoissonOptions options;
  PoissonReport report;
  double seconds_read = 0.0, seconds_normals = 0.0, seconds_poisson = 0.0, seconds_write = 0.0;
};

std::string ReportJson(const MeshRun& run) {
  const PoissonReport& r = run.report;
  JsonWriter json(2);
  json.BeginObject();
  json.Key("input").String(run.input).Key("output").String(run.output);
  json.Key("points").Int(static_cast<long long>(run.points)).Key("normals_estimated").Bool(run.normals_estimated);
  json.Key("outliers_removed").Int(static_cast<long long>(run.outliers.input_points - run.outliers.kept_points()));
  json.Key("depth").Int(run.options.depth).Key("point_weight").Double(run.options.point_weight);
  json.Key("trim").Double(run.options.trim).Key("threads").Int(run.options.num_threads);
  json.Key("vertices").Int(static_cast<long long>(r.vertices)).Key("triangles").Int(static_cast<long long>(r.triangles));
  json.Key("octree_nodes").Int(r.octree_nodes).Key("unknowns").Int(r.unknowns);
  json.Key("solver_iterations").Int(r.solver_iterations);
  json.Key("cells_skipped").Int(static_cast<long long>(r.cells_skipped)).Key("iso_value").Double(r.iso_value);
  json.Key("seconds").BeginObject();
  json.Key("read").Double(run.seconds_read).Key("normals").Double(run.seconds_normals);
  json.Key("octree").Double(r.seconds_octree).Key("solve").Double(r.seconds_solve);
  json.Key("extract").Double(r.seconds_extract).Key("trim").Double(r.seconds_trim);
  json.Key("poisson").Double(run.seconds_poisson).Key("write").Double(run.seconds_write);
  json.EndObject();
  json.EndObject();
  return json.str();
}

}  // namespace

int RunMesh(int argc, char** argv, int first) {
  Args args({"depth", "trim", "point-weight", "threads"}, {"estimate-normals", "remove-outliers", "ascii", "json"});
  if (Status s = args.Parse(argc, argv, first); !s.ok()) return Fail(s);
  if (args.Has("help")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (args.positionals().size() != 2) {
    std::fputs(kHelp, stderr);
    return 2;
  }
  MeshRun run;
  run.input = args.positionals()[0];
  run.output = args.positionals()[1];
  PoissonOptions& options = run.options;
  auto depth = args.GetInt("depth", options.depth, 1, 30);
  auto trim = args.GetDouble("trim", options.trim, 0.0, 100.0);
  auto point_weight = args.GetDouble("point-weight", options.point_weight, 0.0, 1e6);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  auto threads = args.GetInt("threads", cores, 1, 1024);
  for (const Status& s : {depth.status(), trim.status(), point_weight.status(), threads.status()}) {
    if (!s.ok()) return Fail(s);
  }
  options.depth = *depth;
  options.trim = *trim;
  options.point_weight = *point_weight;
  options.num_threads = *threads;
  options.show_progress = true;
  if (Status s = options.Check(); !s.ok()) return Fail(s);
  // Both extensions are checked before the (long) reconstruction.
  if (auto format = ReadableMeshFileFormatOf(run.input); !format.ok()) return Fail(format.status());
  auto output_format = MeshFileFormatOf(run.output);
  if (!output_format.ok()) return Fail(output_format.status());
  MeshFileOptions file_options;
  file_options.ply_ascii = args.Has("ascii");
  if (file_options.ply_ascii && *output_format != MeshFileFormat::kPly) {
    return Fail(InvalidArgument(run.output + ": --ascii applies only to .ply output"));
  }

  auto t0 = std::chrono::steady_clock::now();
  auto points = ReadMeshFile(run.input);
  if (!points.ok()) return Fail(points.status());
  run.points = points->positions.size();
  auto t1 = std::chrono::steady_clock::now();
  run.seconds_read = Seconds(t0, t1);
  if (!args.Has("json")) PrintMeshSummary("read", run.input, *points);
  if (args.Has("remove-outliers")) {
    points->triangles.clear();
    OutlierFilterOptions outlier_options;
    outlier_options.num_threads = options.num_threads;
    auto keep = FindInlierPoints(points->positions, outlier_options, &run.outliers);
    if (!keep.ok()) return Fail(keep.status().WithContext(run.input));
    KeepMasked(*keep, &points->positions);
    KeepMasked(*keep, &points->normals);
    KeepMasked(*keep, &points->colors);
    std::fprintf(stderr, "outliers: %zu isolated and %zu in %d small pieces removed, %zu points kept\n",
                 run.outliers.isolated_removed, run.outliers.small_piece_removed,
                 run.outliers.pieces - run.outliers.pieces_kept, points->positions.size());
  }
  if (args.Has("estimate-normals")) {
    points->triangles.clear();
    if (Status s = EstimateNormals(&*points, NormalEstimationOptions()); !s.ok()) return Fail(s.WithContext(run.input));
    run.normals_estimated = true;
    t0 = t1;
    t1 = std::chrono::steady_clock::now();
    run.seconds_normals = Seconds(t0, t1);
    std::fprintf(stderr, "normals: estimated for %zu points in %.2fs\n", run.points, run.seconds_normals);
  } else if (points->normals.empty()) {
    return Fail(FileError(StatusCode::kInvalidArgument, run.input,
                          "the points have no normals (Poisson needs oriented points); pass --estimate-normals"));
  }

  auto surface = ReconstructPoissonSurface(*points, options, &run.report);
  if (!surface.ok()) return Fail(surface.status().WithContext(run.input));
  t0 = t1;
  t1 = std::chrono::steady_clock::now();
  run.seconds_poisson = Seconds(t0, t1);
  if (Status s = CreateParentDirectory(run.output); !s.ok()) return Fail(s);
  if (Status s = WriteMeshFile(run.output, *surface, file_options); !s.ok()) return Fail(s);
  run.seconds_write = Seconds(t1, std::chrono::steady_clock::now());

  if (args.Has("json")) {
    std::printf("%s\n", ReportJson(run).c_str());
    return 0;
  }
  const PoissonReport& r = run.report;
  std::printf("poisson: depth %d, %d grid nodes, %d unknowns, %d CG iterations; octree %.2fs, solve %.2fs, "
              "extract %.2fs, trim %.2fs\n",
              options.depth, r.octree_nodes, r.unknowns, r.solver_iterations, r.seconds_octree, r.seconds_solve,
              r.seconds_extract, r.seconds_trim);
  if (r.cells_skipped > 0) {
    std::fprintf(stderr, "warning: %zu crossing cells left open at the edge of the solved band\n", r.cells_skipped);
  }
  PrintMeshSummary("wrote", run.output, *surface);
  return 0;
}

}  // namespace reconar::tools
