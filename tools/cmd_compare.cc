// `reconar compare`: the built thing against its design, element by element (core/compare).
#include <cmath>
#include <cstdio>
#include <string>

#include "core/compare/compare_project.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar compare PROJECT DESIGN [--control FILE] [--tolerance M] [--max-distance M]\n"
    "                       [--similarity] [--no-icp] [--threads N] [--json]\n"
    "\n"
    "Compares what a reconstructed project shows with its design (as planned), element by element.\n"
    "DESIGN: glTF 2.0 (.glb, .gltf: each node with a mesh is an element, by its name), OBJ (each\n"
    "group) or PLY (one element). The design is placed in the project's world frame by --control,\n"
    "then refined by point-to-plane ICP against the dense points where the two overlap. Each dense\n"
    "point's signed distance to the nearest design surface (positive: outside it) gives per element\n"
    "the points, mean, RMS, 95th percentile and share within the tolerance; the element's own rigid\n"
    "fit to its points says how far it was moved or turned; the verdict is as_designed, deviates,\n"
    "missing (the photos saw past where it should stand), unknown (they looked, but nothing was\n"
    "reconstructed there nor behind it) or not_seen.\n"
    "  --control FILE      the design coordinates of some of the project's tags, one line per tag:\n"
    "                      'ID X Y Z' (its centre) or 'ID' and its 4 corners' X Y Z (libapriltag's\n"
    "                      order); or of picked points: 'point X Y Z WX WY WZ' (design, then world\n"
    "                      coordinates, e.g. from `reconar measure`); '#' comments. The design's units\n"
    "                      (m, cm, mm, in, ft) are told from the tags' scale; a project without tags\n"
    "                      takes its metres from the design, read as metres. Without control the design\n"
    "                      is taken as drawn in the world frame.\n"
    "  --tolerance M       as designed within M metres (default 0.01)\n"
    "  --max-distance M    points farther than M from every design surface belong to none (default 0.1)\n"
    "  --similarity        fit the design's scale instead of recognising its unit (lengths are then\n"
    "                      in the world's units)\n"
    "  --no-icp            keep the control's placement\n"
    "  --threads N         worker threads (default: one per core)\n"
    "  --json              print compare/report.json on stdout\n"
    "Writes PROJECT/compare/report.json, deviation.ply (the points coloured: blue inside, white on,\n"
    "red outside the design, saturated at 3 x the tolerance; grey on no element) and\n"
    "design_registered.glb (the design in the world frame, one node per element), deviation.glb (the\n"
    "coloured points and the colour scale as a strip) and report.png (a histogram, a top view and the\n"
    "table, to read on site).\n";

}  // namespace

int RunCompare(int argc, char** argv, int first) {
  Args args({"control", "tolerance", "max-distance", "threads"}, {"similarity", "no-icp", "json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 2, 2)) return *exit_code;
  CompareOptions options;
  options.control_path = args.Get("control");
  Result<double> tolerance = args.GetDouble("tolerance", 0.01, 1e-6, 100.0);
  if (!tolerance.ok()) return Fail(tolerance.status());
  Result<double> max_distance = args.GetDouble("max-distance", 0.1, 1e-6, 1000.0);
  if (!max_distance.ok()) return Fail(max_distance.status());
  options.deviation.tolerance = *tolerance;
  options.deviation.max_distance = *max_distance;
  options.registration.max_distance = *max_distance;
  options.registration.similarity = args.Has("similarity");
  options.registration.refine = !args.Has("no-icp");
  Result<int> threads = args.GetThreads();
  if (!threads.ok()) return Fail(threads.status());
  options.registration.num_threads = *threads;
  options.deviation.num_threads = *threads;
  Result<CompareReport> report = CompareWithDesign(Project(args.positionals()[0]), args.positionals()[1], options);
  if (!report.ok()) return Fail(report.status());
  for (const std::string& warning : report->warnings) std::fprintf(stderr, "reconar compare: warning: %s\n", warning.c_str());
  if (args.Has("json")) {
    std::fputs(CompareReportJson(*report, options).c_str(), stdout);
    return 0;
  }
  const DesignRegistration& r = report->registration;
  std::printf("design %s: %zu elements, units %s; control: %d tags, %d picked points, RMS %.1f mm\n",
              report->design_path.c_str(), report->deviation.elements.size(), r.units.c_str(), report->control_tags,
              report->control_points, 1000.0 * r.control_rms_m);
  if (report->units_assumed) {
    std::printf("the project has no metric scale (no tags): the design is taken as drawn in metres, 1 m = %.4g of "
                "the model's units\n",
                report->world_units_per_metre);
  }
  if (!r.icp_rejected.empty()) std::printf("ICP not taken: %s; the control's placement kept\n", r.icp_rejected.c_str());
  if (r.refined) {
    std::printf("ICP: %d of the as-built points used (overlap %.0f %%), RMS %.1f mm, moved %.2f deg and %.1f mm from the "
                "control's placement\n",
                r.points_used, 100.0 * r.overlap, 1000.0 * r.icp_rms_m, r.icp_turn_deg, 1000.0 * r.icp_shift_m);
  }
  std::printf("%-24s %8s %9s %9s %9s %8s  %s\n", "element", "points", "mean mm", "rms mm", "p95 mm", "within", "verdict");
  for (const ElementDeviation& e : report->deviation.elements) {
    std::string verdict = e.verdict;
    if (e.verdict == "deviates") {
      char detail[96];
      std::snprintf(detail, sizeof(detail), " (moved %.1f mm, turned %.2f deg)", 1000.0 * e.shift_m.norm(), e.turn_deg);
      verdict += detail;
    }
    std::printf("%-24s %8d %9.1f %9.1f %9.1f %7.0f%%  %s\n", e.name.c_str(), e.points, 1000.0 * e.mean_m,
                1000.0 * e.rms_m, 1000.0 * e.p95_m, 100.0 * e.within_tolerance, verdict.c_str());
  }
  std::printf("written to %s (report.json, report.png, deviation.ply, deviation.glb, design_registered.glb)\n",
              report->out_dir.c_str());
  return 0;
}

}  // namespace reconar::tools
