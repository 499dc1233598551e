// `reconar mesh`: Poisson surface reconstruction of oriented points: the mesh stage
// (core/pipeline/mesh_stage.h) on any points file.
#include <cstdio>
#include <string>

#include "core/base/thread_pool.h"
#include "core/mesh/mesh_file.h"
#include "core/pipeline/mesh_stage.h"
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
    "  --json               print the report as JSON on stdout (the keys of PROJECT/mesh/report.json)\n";

}  // namespace

int RunMesh(int argc, char** argv, int first) {
  Args args({"depth", "trim", "point-weight", "threads"}, {"estimate-normals", "remove-outliers", "ascii", "json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 2, 2)) return *exit_code;
  const std::string input = args.positionals()[0];
  const std::string output = args.positionals()[1];
  // The mesh stage on any points file, with Poisson's own defaults and the depth as given.
  MeshStageOptions options;
  options.depth_from_spacing = false;
  PoissonOptions& poisson = options.poisson;
  auto depth = args.GetInt("depth", poisson.depth, 1, 30);
  auto trim = args.GetDouble("trim", poisson.trim, 0.0, 100.0);
  auto point_weight = args.GetDouble("point-weight", poisson.point_weight, 0.0, 1e6);
  auto threads = args.GetThreads();
  for (const Status& s : {depth.status(), trim.status(), point_weight.status(), threads.status()}) {
    if (!s.ok()) return Fail(s);
  }
  poisson.depth = *depth;
  poisson.trim = *trim;
  poisson.point_weight = *point_weight;
  poisson.num_threads = ThreadPool::ResolveThreadCount(*threads);
  poisson.show_progress = true;
  options.remove_outliers = args.Has("remove-outliers");
  options.estimate_normals = args.Has("estimate-normals");
  if (Status s = poisson.Check(); !s.ok()) return Fail(s);
  MeshFileOptions file_options;
  file_options.ply_ascii = args.Has("ascii");
  auto output_format = MeshFileFormatOf(output);
  if (!output_format.ok()) return Fail(output_format.status());
  if (file_options.ply_ascii && *output_format != MeshFileFormat::kPly) {
    return Fail(InvalidArgument(output + ": --ascii applies only to .ply output"));
  }

  auto report = MeshPointsFile(input, {output}, options, file_options);
  if (!report.ok()) return Fail(report.status());
  if (args.Has("json")) {
    std::fputs(MeshReportJson(*report).c_str(), stdout);
    return 0;
  }
  const MeshStageReport& r = *report;
  const OutlierFilterReport& o = r.outliers;
  std::printf("read %s: %zu points\n", input.c_str(), r.points);
  if (options.remove_outliers) {
    std::printf("outliers: %zu isolated and %zu in %d small pieces removed, %zu points kept\n", o.isolated_removed,
                o.small_piece_removed, o.pieces - o.pieces_kept, o.kept_points());
  }
  if (r.normals_estimated) std::printf("normals: estimated\n");
  const PoissonReport& p = r.poisson;
  std::printf(
      "poisson: depth %d, %d grid nodes, %d unknowns, %d CG iterations; octree %.2fs, solve %.2fs, "
      "extract %.2fs, trim %.2fs\n",
      r.depth, p.octree_nodes, p.unknowns, p.solver_iterations, p.seconds_octree, p.seconds_solve, p.seconds_extract,
      p.seconds_trim);
  if (p.cells_skipped > 0) {
    std::fprintf(stderr, "warning: %zu crossing cells left open at the edge of the solved band\n", p.cells_skipped);
  }
  std::printf("wrote %s: %zu vertices, %zu triangles in %.1fs\n", output.c_str(), r.vertices, r.faces, r.seconds);
  return 0;
}

}  // namespace reconar::tools
