#include <cstdio>

#include "core/base/atomic_file.h"
#include "core/base/json_writer.h"
#include "core/pipeline/match_stage.h"
#include "tools/commands.h"

namespace reconar::tools {

namespace {

constexpr char kHelp[] =
    "usage: reconar match IMAGE_A IMAGE_B [--pairs OUT.txt] [options]\n"
    "       reconar match --project DIR [options]\n"
    "\n"
    "Matches SIFT descriptors with a randomized kd-forest and Lowe's ratio test, then keeps the\n"
    "matches consistent with a fundamental matrix (normalised 8-point in LO-RANSAC, threshold\n"
    "0.6 % of the larger image side) and screens for planar/rotation-only pairs with a homography.\n"
    "  --pairs OUT.txt   write the verified matches, one 'xa ya xb yb' per line (pixels)\n"
    "  --project DIR     match the pairs of a project made by `reconar features --project DIR`;\n"
    "                    writes DIR/matches/matches.txt\n"
    "  --memory-budget SIZE  with --project: memory for features and kd-forests (MiB, or 512K, 1500M,\n"
    "                    1G; default 2560M); when all images do not fit, blocks of images are matched two\n"
    "                    at a time (same result)\n"
    "  --ratio R         Lowe ratio (default 0.6)   --checks N  leaf checks per query (default 200)\n"
    "  --min-inliers N   inliers a pair needs (default 100)\n"
    "  --f-threshold T   F inlier threshold as a fraction of the larger image side (default 0.006)\n"
    "  --threads N       worker threads (default: one per core)\n"
    "  --json            print the result as JSON on stdout\n"
    "  plus the SIFT options of `reconar features` for the two-image form; with --project, the pairs:\n"
    "  --exhaustive-up-to N  every pair of the first N images (default 50); each later image is\n"
    "  --window W            matched with the W before it (default 10) and the R earlier images most\n"
    "  --retrieved R         like it by vocabulary-tree retrieval (default 40)\n";

}  // namespace

Status ReadMatchArgs(const Args& args, MatchStageOptions* options) {
  RECONAR_ASSIGN_OR_RETURN(options->match.max_ratio, args.GetDouble("ratio", options->match.max_ratio, 0.01, 1.0));
  RECONAR_ASSIGN_OR_RETURN(options->match.max_leaf_checks,
                           args.GetInt("checks", options->match.max_leaf_checks, 1, 1 << 20));
  RECONAR_ASSIGN_OR_RETURN(options->two_view.min_inliers,
                           args.GetInt("min-inliers", options->two_view.min_inliers, 8, 1 << 20));
  RECONAR_ASSIGN_OR_RETURN(options->two_view.f_threshold_fraction,
                           args.GetDouble("f-threshold", options->two_view.f_threshold_fraction, 1e-5, 0.1));
  PairSelectionOptions& pairs = options->pairs;
  RECONAR_ASSIGN_OR_RETURN(pairs.exhaustive_up_to, args.GetInt("exhaustive-up-to", pairs.exhaustive_up_to, 2, 1 << 24));
  RECONAR_ASSIGN_OR_RETURN(pairs.sequential_window, args.GetInt("window", pairs.sequential_window, 0, 1 << 24));
  RECONAR_ASSIGN_OR_RETURN(pairs.retrieved, args.GetInt("retrieved", pairs.retrieved, 0, 1 << 24));
  RECONAR_ASSIGN_OR_RETURN(options->num_threads, args.GetThreads());
  options->match.num_threads = options->num_threads;
  return Status::Ok();
}

namespace {

int MatchProject(const Args& args, MatchStageOptions options) {
  const Project project(args.Get("project"));
  auto budget = args.GetMemoryBudget(kDefaultMemoryBudgetBytes);
  if (!budget.ok()) return Fail(budget.status());
  options.memory_budget_bytes = *budget;
  auto report = RunMatchStage(project, options);
  if (!report.ok()) return Fail(report.status());
  if (args.Has("json")) {
    JsonWriter json(2);
    json.BeginObject().Key("images").Int(report->num_images).Key("pairs").Int(report->num_pairs);
    json.Key("verified").Int(report->num_verified).Key("planar").Int(report->num_planar);
    json.Key("rejected").Int(report->num_rejected).Key("blocks").Int(report->num_blocks);
    json.Key("seconds_pair_selection").Double(report->seconds_pair_selection);
    json.Key("seconds").Double(report->seconds).Key("matches").String(project.MatchesPath()).EndObject();
    std::printf("%s\n", json.str().c_str());
    return 0;
  }
  std::printf("matching: %d images, %d pairs: %d verified, %d planar or rotation-only, %d rejected; %.1fs\n",
              report->num_images, report->num_pairs, report->num_verified, report->num_planar, report->num_rejected,
              report->seconds);
  if (report->num_blocks > 1) {
    std::printf("matched in %d blocks of images, two at a time (estimated peak %.0f MiB)\n", report->num_blocks,
                report->estimated_peak_bytes / (1 << 20));
  }
  std::printf("written to %s\n", project.MatchesPath().c_str());
  return 0;
}

int MatchTwo(const Args& args, const MatchStageOptions& options) {
  auto sift = SiftOptionsFromArgs(args);
  if (!sift.ok()) return Fail(sift.status());
  auto match = MatchTwoPhotos(args.positionals()[0], args.positionals()[1], *sift, options);
  if (!match.ok()) return Fail(match.status());
  const ProjectImage& a = match->images[0];
  const ProjectImage& b = match->images[1];
  const size_t features_a = match->features[0].keypoints.size();
  const size_t features_b = match->features[1].keypoints.size();
  const VerifiedPair& verified = match->pair;
  const TwoViewGeometry& g = verified.geometry;
  if (args.Has("json")) {
    JsonWriter json(2);
    json.BeginObject().Key("image_a").String(a.name).Key("features_a").Int(static_cast<long long>(features_a));
    json.Key("image_b").String(b.name).Key("features_b").Int(static_cast<long long>(features_b));
    json.Key("ratio").Double(options.match.max_ratio).Key("putative").Int(verified.num_putative);
    json.Key("f_threshold_px").Double(g.f_threshold_px).Key("f_inliers").Int(g.num_f_inliers);
    json.Key("h_threshold_px").Double(g.h_threshold_px).Key("h_inliers").Int(g.num_h_inliers);
    json.Key("result").String(TwoViewConfigName(g.config)).Key("reason").String(g.reason).EndObject();
    std::printf("%s\n", json.str().c_str());
  } else {
    std::printf("%s: %zu features, %s: %zu features\n", a.name.c_str(), features_a, b.name.c_str(), features_b);
    std::printf("putative matches (ratio %.2f): %d\n", options.match.max_ratio, verified.num_putative);
    std::printf("F-inliers (threshold %.2f px): %d, H-inliers among them (%.2f px): %d, ratio %.2f\n", g.f_threshold_px,
                g.num_f_inliers, g.h_threshold_px, g.num_h_inliers, g.h_to_f_inlier_ratio);
    std::printf("result: %s%s%s\n", TwoViewConfigName(g.config), g.reason.empty() ? "" : " - ", g.reason.c_str());
  }
  if (args.Has("pairs")) {
    if (Status s = WriteFileAtomically(args.Get("pairs"), MatchedPositionsText(*match)); !s.ok()) return Fail(s);
    if (!args.Has("json")) {
      std::printf("wrote %zu matches to %s\n", verified.inlier_matches.size(), args.Get("pairs").c_str());
    }
  }
  return g.config == TwoViewGeometry::Config::kTooFewInliers ? 1 : 0;
}

}  // namespace

int RunMatch(int argc, char** argv, int first) {
  std::set<std::string> valued = kSiftValuedOptions;
  valued.insert(kMatchValuedOptions.begin(), kMatchValuedOptions.end());
  valued.insert({"project", "pairs", "memory-budget"});
  Args args(valued, {"json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 0, SIZE_MAX)) return *exit_code;
  MatchStageOptions options;  // the library's defaults: ratio 0.6, 100 inliers (sfm and reconstruct: 0.8, 30)
  if (Status s = ReadMatchArgs(args, &options); !s.ok()) return Fail(s);
  if (args.Has("project")) {
    if (!args.positionals().empty()) return Fail(InvalidArgument("give either --project DIR or two images, not both"));
    return MatchProject(args, options);
  }
  if (args.positionals().size() != 2) return UsageError(kHelp);
  return MatchTwo(args, options);
}

}  // namespace reconar::tools
