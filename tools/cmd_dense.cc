#include <sys/stat.h>

#include <cstdio>
#include <set>
#include <string>

#include "core/base/memory_usage.h"
#include "core/pipeline/dense_stage.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar dense PROJECT_DIR [options]\n"
    "\n"
    "Dense multi-view stereo on a project made by `reconar sfm`: every registered photo is\n"
    "undistorted at the chosen resolution level and gets a depth and a normal per pixel by\n"
    "PatchMatch over its neighbouring photos; the depths that other views confirm are fused into\n"
    "oriented points (or, with --method pmvs, the paper's PMVS grows patches from matched features\n"
    "in overlapping view clusters, CMVS). Reads PROJECT_DIR/sparse and PROJECT_DIR/features/\n"
    "images.txt, writes:\n"
    "  dense/points.ply      binary PLY: position, normal, RGBA colour per point\n"
    "  dense/report.json     level, clusters, counts, seconds and peak memory per phase\n"
    "  --method patchmatch|pmvs  PatchMatch depth maps (default) or PMVS's patches (the paper's\n"
    "                         method, our reference; several times slower)\n"
    "  --level 0|1|2|auto     image resolution: full, half, quarter; auto (default) takes the finest\n"
    "                         within --max-image-size whose memory estimate fits --memory-budget\n"
    "  --max-image-size N     auto level: longest image side at most N pixels (default 2400, as\n"
    "                         COLMAP's; 0: no limit)\n"
    "  --max-cluster-size N   images per PMVS run (default 20; smaller needs less memory); PatchMatch\n"
    "                         takes as many views at once as the budget holds\n"
    "  --memory-budget SIZE   memory the run may use: MiB, or 512K, 1500M, 1G (default 2560M)\n"
    "  --no-fill              PatchMatch: leave texture-poor pixels (white walls) empty instead of\n"
    "                         giving them the plane their textured surroundings agree on\n"
    "  --keep-outliers        keep isolated points and small floating pieces (removed by default)\n"
    "  --threads N            worker threads (default: one per core)\n"
    "  --json                 print the report as JSON instead of a summary\n";

bool IsDirectory(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}


void PrintSummary(const DenseStageReport& r) {
  std::printf("dense: level %d (%s), %d of %d images kept (%d redundant), %d clusters of at most %d images%s\n",
              r.level, r.level_auto ? "auto" : "given", r.kept_images, r.images, r.removed_images, r.clusters,
              r.max_cluster_size, r.cluster_size_reduced ? " (reduced for the memory budget)" : "");
  if (r.clusters_from_cameras) std::printf("dense: no sparse points; clusters from camera positions\n");
  if (r.method == DenseMethod::kPatchMatch) {
    const PatchMatchReport& m = r.patchmatch;
    std::printf(
        "dense: %zu points (%zu before merging clusters) by PatchMatch: %zu depth maps, %zu depth pixels, "
        "%zu fused; %.1fs selection, %.1fs propagation, %.1fs consistency, %.1fs fusion\n",
        r.points, r.points_before_merge, m.views, m.depth_pixels, m.fused_points, m.seconds_selection,
        m.seconds_propagation, m.seconds_consistency, m.seconds_fusion);
  } else {
    std::printf(
        "dense: %zu points (%zu before merging clusters), %zu PMVS features, %zu initial + %zu expanded patches\n",
        r.points, r.points_before_merge, r.pmvs.features, r.pmvs.initial_patches, r.pmvs.expanded_patches);
  }
  if (r.outliers.input_points > 0) {
    std::printf("dense: outliers removed: %zu isolated, %zu in %d small pieces (median spacing %.4g)\n",
                r.outliers.isolated_removed, r.outliers.small_piece_removed, r.outliers.pieces - r.outliers.pieces_kept,
                r.outliers.median_spacing);
  }
  const struct {
    const char* name;
    const DensePhase& phase;
  } phases[] = {{"load", r.load}, {"clustering", r.clustering}, {"undistort", r.undistort},
                {"mvs", r.mvs},   {"merge", r.merge},           {"outliers", r.outlier_filter},
                {"write", r.write}};
  double total = 0.0;
  for (const auto& p : phases) total += p.phase.seconds;
  std::printf("dense: %.1fs:", total);
  for (const auto& p : phases) std::printf(" %s %.1fs (peak %.0f MiB)", p.name, p.phase.seconds, Mib(p.phase.peak_rss_bytes));
  std::printf("%s\n", r.peak_rss_resettable ? "" : " [peaks since process start]");
  std::printf("dense: estimated %.0f MiB per cluster; written to %s and %s\n", Mib(r.estimated_bytes),
              r.points_path.c_str(), r.report_path.c_str());
}

}  // namespace

int RunDense(int argc, char** argv, int first) {
  std::set<std::string> valued = {"max-cluster-size", "threads", "memory-budget"};
  valued.insert(kDenseValuedOptions.begin(), kDenseValuedOptions.end());
  Args args(valued, {"json", "keep-outliers", "no-fill"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 1, 1)) return *exit_code;
  const Project project(args.positionals()[0]);
  if (!IsDirectory(project.root())) {
    return Fail(NotFound(project.root() + ": no such project directory (make one with `reconar sfm`)"));
  }
  DenseStageOptions options;
  if (const Status status = ReadDenseArgs(args, &options); !status.ok()) return Fail(status);
  auto cluster_size = args.GetInt("max-cluster-size", options.clustering.max_cluster_size, 3, 10000);
  if (!cluster_size.ok()) return Fail(cluster_size.status());
  options.clustering.max_cluster_size = *cluster_size;
  auto threads = args.GetThreads();
  if (!threads.ok()) return Fail(threads.status());
  options.num_threads = *threads;
  auto budget = args.GetMemoryBudget(options.memory_budget_bytes);
  if (!budget.ok()) return Fail(budget.status());
  options.memory_budget_bytes = *budget;
  const bool json = args.Has("json");
  options.remove_outliers = !args.Has("keep-outliers");
  options.show_progress = true;

  auto report = RunDenseStage(project, options);
  if (!report.ok()) return Fail(report.status());
  if (json) {
    std::fputs(DenseReportJson(*report).c_str(), stdout);
  } else {
    PrintSummary(*report);
  }
  return 0;
}

}  // namespace reconar::tools
