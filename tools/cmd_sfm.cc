#include <sys/stat.h>

#include <cstdio>
#include <initializer_list>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/json_writer.h"
#include "core/pipeline/feature_stage.h"
#include "core/pipeline/match_stage.h"
#include "core/pipeline/sfm_stage.h"
#include "core/pipeline/stage_record.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar sfm IMAGES_DIR|IMAGE... PROJECT_DIR [options]\n"
    "\n"
    "Structure from motion: SIFT features, kd-forest matching with two-view verification, then\n"
    "incremental mapping with bundle adjustment (focal, k1, k2 per camera: images of one size\n"
    "without EXIF, or with the same EXIF focal, share a camera; the principal point and the\n"
    "distortion are refined in the final adjustment when the data supports it). Writes into\n"
    "PROJECT_DIR:\n"
    "  features/ matches/                      the earlier stages (reused when up to date)\n"
    "  sparse/cameras.txt images.txt points3D.txt   COLMAP text model\n"
    "  sparse/bundle.out list.txt              Bundler v0.3\n"
    "  sparse/points.ply                       coloured sparse points\n"
    "  report.json                             counts, focal statistics, timings per stage\n"
    "Re-running reuses every stage finished with the same settings (PROJECT_DIR/stages.txt);\n"
    "--force redoes all of them.\n"
    "  --principal-point fixed|auto|refine   (default auto)\n"
    "  --fixed-distortion    keep k1 = k2 = 0 (for photos that are already undistorted)\n"
    "  --max-error PX        reprojection error bound for triangulation and filtering (default 4)\n"
    "  --ratio R             Lowe ratio (default 0.8 here)\n"
    "  --min-inliers N       inliers a pair needs (default 30 here)\n"
    "  --threads N           worker threads (default: one per core)\n"
    "  --force               recompute every stage\n"
    "  plus the options of `reconar features` and `reconar match`\n";

bool Exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

struct StageTiming {
  std::string name;
  bool reused = false;
  double seconds = 0.0;
};

std::string ReportJson(const SfmStageReport& sfm, const std::vector<StageTiming>& stages) {
  const MapperReport& m = sfm.mapper;
  JsonWriter json(2);
  json.BeginObject();
  WriteSfmReportFields(sfm, &json);
  json.Key("stages").BeginObject();
  for (const StageTiming& stage : stages) {
    json.Key(stage.name).BeginObject().Key("reused").Bool(stage.reused).Key("seconds").Double(stage.seconds);
    if (stage.name == "mapping") {
      json.Key("seconds_bundle_adjustment").Double(m.seconds_ba);
      json.Key("local_bundle_adjustments").Int(m.num_local_ba);
      json.Key("global_bundle_adjustments").Int(m.num_global_ba);
    }
    json.EndObject();
  }
  json.EndObject();
  json.EndObject();
  return json.str() + "\n";
}

}  // namespace

int RunSfm(int argc, char** argv, int first) {
  std::set<std::string> valued = kSiftValuedOptions;
  valued.insert(kMatchValuedOptions.begin(), kMatchValuedOptions.end());
  valued.insert({"principal-point", "max-error"});
  Args args(valued, {"force", "fixed-distortion"});
  if (Status s = args.Parse(argc, argv, first); !s.ok()) return Fail(s);
  if (args.Has("help")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (args.positionals().size() < 2) {
    std::fputs(kHelp, stderr);
    return 2;
  }
  std::vector<std::string> inputs = args.positionals();
  const Project project(inputs.back());
  inputs.pop_back();

  FeatureStageOptions feature_options;
  auto sift = SiftOptionsFromArgs(args);
  if (!sift.ok()) return Fail(sift.status());
  feature_options.sift = *sift;
  auto match_options = MatchOptionsFromArgs(args);
  if (!match_options.ok()) return Fail(match_options.status());
  feature_options.num_threads = match_options->num_threads;
  // Lowe's 0.8 (his paper's recommendation, and COLMAP's) rather than the stricter 0.6 of
  // `reconar match`: mapping wants the extra matches, and RANSAC plus track triangulation
  // remove the extra outliers.
  if (!args.Has("ratio")) match_options->match.max_ratio = 0.8;
  // Wide-baseline pairs with few matches still tie tracks together (COLMAP keeps pairs from 15).
  if (!args.Has("min-inliers")) match_options->two_view.min_inliers = 30;

  SfmStageOptions sfm_options;
  sfm_options.mapper.num_threads = match_options->num_threads;
  const std::string pp = args.Get("principal-point", "auto");
  if (pp == "fixed") {
    sfm_options.mapper.principal_point = MapperOptions::PrincipalPoint::kFixed;
  } else if (pp == "refine") {
    sfm_options.mapper.principal_point = MapperOptions::PrincipalPoint::kRefine;
  } else if (pp != "auto") {
    return Fail(InvalidArgument("--principal-point must be fixed, auto or refine, got '" + pp + "'"));
  }
  sfm_options.mapper.refine_distortion = !args.Has("fixed-distortion");
  auto max_error = args.GetDouble("max-error", sfm_options.mapper.max_reprojection_error_px, 0.1, 100.0);
  if (!max_error.ok()) return Fail(max_error.status());
  sfm_options.mapper.max_reprojection_error_px = *max_error;
  sfm_options.mapper.registration_max_error_px = *max_error;

  auto paths = CollectImagePaths(inputs);
  if (!paths.ok()) return Fail(paths.status());
  if (Status s = CreateDirectories(project.root()); !s.ok()) return Fail(s);
  const bool force = args.Has("force");
  std::vector<StageTiming> stages;


  StageRecord record(project);
  const auto finished = [&](const std::string& stage, const std::string& settings) {
    return !force && record.Finished(stage, settings);
  };
  const auto Settings = StageRecord::Settings;
  const SiftOptions& sift_used = feature_options.sift;
  const std::string feature_settings =
      Settings({{"first_octave", sift_used.first_octave}, {"max_features", sift_used.max_features},
                {"contrast_threshold", sift_used.contrast_threshold}});
  const std::string match_settings =
      Settings({{"ratio", match_options->match.max_ratio}, {"checks", match_options->match.max_leaf_checks},
                {"min_inliers", match_options->two_view.min_inliers},
                {"f_threshold", match_options->two_view.f_threshold_fraction}});
  const MapperOptions& mapper = sfm_options.mapper;
  const std::string mapping_settings =
      Settings({{"principal_point", static_cast<double>(mapper.principal_point)},
                {"max_error", mapper.max_reprojection_error_px},
                {"refine_distortion", mapper.refine_distortion ? 1.0 : 0.0}});

  bool redo = !finished("features", feature_settings) || !FeaturesUpToDate(project, *paths);
  if (redo) {
    auto features = RunFeatureStage(*paths, &project, feature_options);
    if (!features.ok()) return Fail(features.status());
    for (const std::string& skipped : features->skipped) std::fprintf(stderr, "warning: skipped %s\n", skipped.c_str());
    std::printf("features: %zu images, %zu skipped, %.1fs\n", features->extracted.size(), features->skipped.size(),
                features->seconds);
    stages.push_back({"features", false, features->seconds});
    if (Status s = record.Record("features", feature_settings); !s.ok()) return Fail(s);
  } else {
    std::printf("features: up to date, reused\n");
    stages.push_back({"features", true, 0.0});
  }

  redo = redo || !finished("matching", match_settings) || !Exists(project.MatchesPath());
  if (redo) {
    auto matches = RunMatchStage(project, *match_options);
    if (!matches.ok()) return Fail(matches.status());
    std::printf("matching: %d pairs: %d verified, %d planar or rotation-only; %.1fs\n", matches->num_pairs,
                matches->num_verified, matches->num_planar, matches->seconds);
    stages.push_back({"matching", false, matches->seconds});
    if (Status s = record.Record("matching", match_settings); !s.ok()) return Fail(s);
  } else {
    std::printf("matching: up to date, reused\n");
    stages.push_back({"matching", true, 0.0});
  }

  redo = redo || !finished("mapping", mapping_settings) || !Exists(project.SparseDir() + "/points3D.txt") ||
         !Exists(project.ReportPath());
  if (!redo) {
    std::printf("mapping: up to date, reused (%s); --force recomputes\n", project.ReportPath().c_str());
    return 0;
  }
  auto sfm = RunSfmStage(project, sfm_options);
  if (!sfm.ok()) return Fail(sfm.status());
  const MapperReport& m = sfm->mapper;
  stages.push_back({"mapping", false,
                    sfm->seconds_load + sfm->seconds_mapping + sfm->seconds_colour + sfm->seconds_write});
  std::printf("mapping: %d of %d images registered, %d points, mean track length %.2f, reprojection error %.3f px; "
              "%.1fs (bundle adjustment %.1fs)\n",
              m.num_registered, m.num_images, m.num_points, m.mean_track_length, m.mean_reprojection_error_px,
              sfm->seconds_mapping, m.seconds_ba);
  std::printf("focal ratio (focal / long side): mean %.4f, rmse %.4f (35 mm equivalent %.1f mm)\n",
              sfm->mean_focal_ratio, sfm->rmse_focal_ratio, sfm->focal_35mm_equivalent);
  for (const MapperReport::Unregistered& u : m.unregistered) {
    std::fprintf(stderr, "warning: %s not registered: %s\n", u.name.c_str(), u.reason.c_str());
  }
  if (Status s = WriteFileAtomically(project.ReportPath(), ReportJson(*sfm, stages)); !s.ok()) return Fail(s);
  if (Status s = record.Record("mapping", mapping_settings); !s.ok()) return Fail(s);
  std::printf("written to %s and %s\n", project.SparseDir().c_str(), project.ReportPath().c_str());
  return 0;
}

}  // namespace reconar::tools
