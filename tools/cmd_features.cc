#include <cstdio>
#include <optional>

#include "core/base/json_writer.h"
#include "core/pipeline/feature_stage.h"
#include "core/pipeline/project.h"
#include "tools/commands.h"

namespace reconar::tools {

namespace {

constexpr char kHelp[] =
    "usage: reconar features IMAGE|DIR... [--project DIR] [--key OUT] [--first-octave -1|0]\n"
    "                        [--max-features N] [--sift-memory-mib M] [--threads N]\n"
    "\n"
    "Finds SIFT keypoints and descriptors (Lowe 2004) in each photo (JPEG or PNG; a directory\n"
    "contributes all of its .jpg/.jpeg/.png files). Unreadable photos are skipped with a warning.\n"
    "  --project DIR       write DIR/features/<name>.rfeat and DIR/features/images.txt\n"
    "  --key OUT           also write Lowe's ASCII .key format (a file for one image, else a directory)\n"
    "  --first-octave N    -1 (default) doubles the image first for more small-scale features; 0 does not\n"
    "  --max-features N    keep the N strongest per image (default 16384, 0 = all)\n"
    "  --contrast-threshold C  DoG contrast threshold before division by the 3 levels (default 0.04, Lowe)\n"

    "  --sift-memory-mib M working-memory bound per thread (default 512); larger photos fall back to\n"
    "                      first octave 0 with a warning\n"
    "  --threads N         photos processed in parallel (default: one per core)\n"
    "  --json              print the per-image results as JSON on stdout\n";

void PrintJson(const FeatureStageReport& report) {
  JsonWriter json(2);
  json.BeginObject().Key("images").BeginArray();
  for (const ImageFeatureSummary& s : report.extracted) {
    json.BeginObject().Key("name").String(s.image.name).Key("path").String(s.image.path);
    json.Key("width").Int(s.image.width).Key("height").Int(s.image.height).Key("features").Int(s.num_features);
    json.Key("focal_px").Double(s.image.focal_px).Key("focal_source").String(s.image.focal_source);
    json.Key("seconds").Double(s.seconds).EndObject();
  }
  json.EndArray().Key("skipped").BeginArray();
  for (const std::string& skipped : report.skipped) json.String(skipped);
  json.EndArray().Key("seconds").Double(report.seconds).EndObject();
  std::printf("%s\n", json.str().c_str());
}

}  // namespace

Result<SiftOptions> SiftOptionsFromArgs(const Args& args) {
  SiftOptions options;
  RECONAR_ASSIGN_OR_RETURN(options.first_octave, args.GetInt("first-octave", options.first_octave, -1, 0));
  RECONAR_ASSIGN_OR_RETURN(options.max_features, args.GetInt("max-features", options.max_features, 0, 1 << 24));
  RECONAR_ASSIGN_OR_RETURN(const int mib,
                           args.GetInt("sift-memory-mib", static_cast<int>(options.arena_bytes >> 20), 16, 1 << 16));
  options.arena_bytes = static_cast<size_t>(mib) << 20;
  RECONAR_ASSIGN_OR_RETURN(options.contrast_threshold,
                           args.GetDouble("contrast-threshold", options.contrast_threshold, 1e-4, 1.0));
  return options;
}

Result<FeatureStageOptions> FeatureStageOptionsFromArgs(const Args& args) {
  FeatureStageOptions options;
  RECONAR_ASSIGN_OR_RETURN(options.sift, SiftOptionsFromArgs(args));
  return options;
}

int RunFeatures(int argc, char** argv, int first) {
  std::set<std::string> valued = kSiftValuedOptions;
  valued.insert({"project", "key", "threads"});
  Args args(valued, {"json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 1, SIZE_MAX)) return *exit_code;
  if (!args.Has("project") && !args.Has("key")) {
    return Fail(InvalidArgument("nothing to write: give --project DIR and/or --key OUT"));
  }
  auto stage_options = FeatureStageOptionsFromArgs(args);
  if (!stage_options.ok()) return Fail(stage_options.status());
  FeatureStageOptions options = *stage_options;
  auto threads = args.GetThreads();
  if (!threads.ok()) return Fail(threads.status());
  options.num_threads = *threads;
  options.key_output = args.Get("key");

  auto paths = CollectImagePaths(args.positionals());
  if (!paths.ok()) return Fail(paths.status());
  std::optional<Project> project;
  if (args.Has("project")) project.emplace(args.Get("project"));
  auto report = RunFeatureStage(*paths, project ? &*project : nullptr, options);
  if (!report.ok()) return Fail(report.status());

  for (const std::string& skipped : report->skipped) std::fprintf(stderr, "warning: skipped %s\n", skipped.c_str());
  if (args.Has("json")) {
    PrintJson(*report);
    return 0;
  }
  size_t total = 0;
  bool default_focal_said = false;
  for (const ImageFeatureSummary& s : report->extracted) {
    std::printf("%-24s %5dx%-5d %6d features  %.2fs  focal %.1f px (%s)\n", s.image.name.c_str(), s.image.width,
                s.image.height, s.num_features, s.seconds, s.image.focal_px, s.image.focal_source.c_str());
    for (const std::string& w : s.warnings) std::fprintf(stderr, "warning: %s: %s\n", s.image.path.c_str(), w.c_str());
    if (s.image.focal_source == "default" && !default_focal_said) {
      std::fprintf(stderr, "note: %s\n", s.focal_explanation.c_str());
      default_focal_said = true;
    }
    total += static_cast<size_t>(s.num_features);
  }
  std::printf("features: %zu images, %zu skipped, %zu features, %.1fs%s%s\n", report->extracted.size(),
              report->skipped.size(), total, report->seconds, project ? ", written to " : "",
              project ? project->FeaturesDir().c_str() : "");
  return 0;
}

}  // namespace reconar::tools
