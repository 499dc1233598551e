#include "tools/reconstruct_command.h"

#include <cstdio>
#include <string>

#include "core/base/atomic_file.h"
#include "core/base/memory_usage.h"
#include "core/sfm/tag_layout.h"
#include "tools/commands.h"
#include "tracker/photo_tags.h"
#ifdef RECONAR_HAVE_VIEW
#include "render/ar/photo_render.h"
#endif

namespace reconar::tools {
namespace {

const std::set<std::string> kFlags = {"no-tags-in-ba", "no-preview",           "force",           "json",
                                      "fixed-distortion", "no-fill",          "strict-registration",
                                      "separate-models", "no-reextraction"};

std::set<std::string> ValuedOptions() {
  std::set<std::string> valued = kSiftValuedOptions;
  valued.insert(kMatchValuedOptions.begin(), kMatchValuedOptions.end());
  valued.insert(kDenseValuedOptions.begin(), kDenseValuedOptions.end());
  valued.insert({"tag-size", "tag-family", "world-tag", "scale-tags", "layout", "memory-budget", "stages", "depth", "trim",
                 "max-faces", "formats", "principal-point", "max-error"});
  return valued;
}

Status ReadStages(const Args& args, ReconstructOptions* options) {
  if (!args.Has("stages")) return Status::Ok();
  options->run_sparse = options->run_dense = options->run_mesh = options->run_texture = false;
  for (const std::string& stage : SplitCommas(args.Get("stages"))) {
    if (stage == "sparse") {
      options->run_sparse = true;
    } else if (stage == "dense") {
      options->run_dense = true;
    } else if (stage == "mesh") {
      options->run_mesh = true;
    } else if (stage == "texture") {
      options->run_mesh = options->run_texture = true;
    } else {
      return InvalidArgument("--stages: unknown stage '" + stage + "' (sparse, dense, mesh, texture)");
    }
  }
  return Status::Ok();
}

Status ReadMapperArgs(const Args& args, MapperOptions* mapper) {
  const std::string pp = args.Get("principal-point", "auto");
  if (pp == "fixed") {
    mapper->principal_point = MapperOptions::PrincipalPoint::kFixed;
  } else if (pp == "refine") {
    mapper->principal_point = MapperOptions::PrincipalPoint::kRefine;
  } else if (pp != "auto") {
    return InvalidArgument("--principal-point must be fixed, auto or refine, got '" + pp + "'");
  }
  if (args.Has("fixed-distortion")) mapper->refine_distortion = false;
  if (args.Has("separate-models")) mapper->merge_models = false;
  if (args.Has("strict-registration")) {
    mapper->registration_min_verified_inliers = mapper->registration_min_inliers;
    mapper->registration_min_baseline_points = 0;
  }
  RECONAR_ASSIGN_OR_RETURN(mapper->max_reprojection_error_px,
                           args.GetDouble("max-error", mapper->max_reprojection_error_px, 0.1, 100.0));
  mapper->registration_max_error_px =
      args.Has("max-error") ? mapper->max_reprojection_error_px : mapper->registration_max_error_px;
  return Status::Ok();
}

}  // namespace

Status ReadDenseArgs(const Args& args, DenseStageOptions* dense) {
  const std::string level = args.Get("level", "auto");
  if (level == "auto") {
    dense->level = -1;
  } else if (level == "0" || level == "1" || level == "2") {
    dense->level = level[0] - '0';
  } else {
    return InvalidArgument("--level must be 0, 1, 2 or auto, got '" + level + "'");
  }
  RECONAR_ASSIGN_OR_RETURN(dense->max_image_size, args.GetInt("max-image-size", dense->max_image_size, 0, 1 << 20));
  if (args.Has("no-fill")) dense->patchmatch.fill_min_support = 0;
  if (args.Has("method")) {
    RECONAR_ASSIGN_OR_RETURN(dense->method, ParseDenseMethod(args.Get("method")));
  }
  return Status::Ok();
}

namespace {

Status ReadDenseAndMeshArgs(const Args& args, ReconstructOptions* options) {
  RECONAR_RETURN_IF_ERROR(ReadDenseArgs(args, &options->dense));
  MeshStageOptions& mesh = options->mesh;
  RECONAR_ASSIGN_OR_RETURN(mesh.poisson.depth, args.GetInt("depth", mesh.poisson.depth, 5, 11));
  RECONAR_ASSIGN_OR_RETURN(mesh.poisson.trim, args.GetDouble("trim", mesh.poisson.trim, 0.0, 20.0));
  RECONAR_ASSIGN_OR_RETURN(const int max_faces, args.GetInt("max-faces", static_cast<int>(mesh.max_faces), 0, 1 << 30));
  mesh.max_faces = static_cast<size_t>(max_faces);
  if (args.Has("formats")) mesh.formats = SplitCommas(args.Get("formats"));
  return Status::Ok();
}

}  // namespace

Result<ReconstructOptions> ReconstructOptionsFromArgs(const Args& args) {
  ReconstructOptions options;
  RECONAR_ASSIGN_OR_RETURN(options.features, FeatureStageOptionsFromArgs(args));
  RECONAR_RETURN_IF_ERROR(ReadMatchArgs(args, &options.matching));
  RECONAR_RETURN_IF_ERROR(ReadMapperArgs(args, &options.sfm.mapper));
  RECONAR_ASSIGN_OR_RETURN(options.tag_size_m, args.GetDouble("tag-size", 0.0, 0.0, 100.0));
  if (args.Has("tag-size") && !(options.tag_size_m > 0.0)) return InvalidArgument("--tag-size must be positive");
  RECONAR_ASSIGN_OR_RETURN(options.sfm.tags.registration.world_tag, args.GetInt("world-tag", -1, -1, 1 << 20));
  options.sfm.tags.in_adjustment = !args.Has("no-tags-in-ba");
  RECONAR_ASSIGN_OR_RETURN(options.sfm.tags.registration.scale_tags, args.GetIdList("scale-tags"));
  if (!options.sfm.tags.registration.scale_tags.empty() && !args.Has("tag-size")) {
    return InvalidArgument("--scale-tags needs --tag-size");
  }
  if (args.Has("layout")) {
    if (!args.Has("tag-size")) return InvalidArgument("--layout needs --tag-size");
    if (args.Has("world-tag")) return InvalidArgument("--layout and --world-tag both choose the world frame: give one");
    RECONAR_ASSIGN_OR_RETURN(options.sfm.tags.registration.layout, ReadTagLayout(args.Get("layout")));
  }
  RECONAR_ASSIGN_OR_RETURN(options.num_threads, args.GetThreads());
  RECONAR_ASSIGN_OR_RETURN(options.memory_budget_bytes, args.GetMemoryBudget(options.memory_budget_bytes));
  RECONAR_RETURN_IF_ERROR(ReadDenseAndMeshArgs(args, &options));
  RECONAR_RETURN_IF_ERROR(ReadStages(args, &options));
  options.force = args.Has("force");
  if (args.Has("no-reextraction")) {
    options.extract_weak_photos_again = false;
    options.matching.poorly_matched.min_partners = 0;
  }
  options.tag_family = args.Get("tag-family", options.tag_family);
  PhotoTagOptions tag_options;
  RECONAR_ASSIGN_OR_RETURN(tag_options.family, ParseTagFamily(options.tag_family));
  tag_options.num_threads = options.num_threads;
  options.detect_tags = [tag_options](const std::vector<std::string>& paths) {
    return DetectTagsInPhotos(paths, tag_options);
  };
#ifdef RECONAR_HAVE_VIEW
  if (!args.Has("no-preview")) options.render_preview = WriteModelPreview;
#endif
  return options;
}

namespace {

void PrintReport(const ReconstructReport& report, const Project& project) {
  for (const StageSummary& stage : report.stages) {
    std::printf("%-9s %s %7.1fs  peak %6.0f MiB%s%s\n", stage.name.c_str(), stage.reused ? "reused " : "done   ",
                stage.seconds, Mib(stage.peak_rss_bytes), stage.note.empty() ? "" : "  ",
                stage.note.c_str());
  }
  const Table1& t = report.table1;
  if (t.images > 0) {
    std::printf(
        "model: %d of %d images registered, %d sparse points; focal ratio (focal / long side) mean %.4f, "
        "rmse %.4f (35 mm equivalent %.1f mm)\n",
        t.registered, t.images, t.sparse_points, t.mean_focal_ratio, t.rmse_focal_ratio, t.focal_35mm_equivalent_mm);
  }
  if (t.dense_points > 0) std::printf("dense: %lld points\n", t.dense_points);
  if (t.mesh_faces > 0) std::printf("mesh: %lld vertices, %lld faces\n", t.mesh_vertices, t.mesh_faces);
  std::printf("scale: %s\n", report.metric ? "metres (tags.json)" : report.scale_note.c_str());
  std::printf("written to %s (report.json%s)\n", project.root().c_str(),
              report.preview_path.empty() ? "" : ", preview.png");
}

}  // namespace

int RunReconstructCommand(int argc, char** argv, int first, const char* help, bool sparse_only) {
  std::set<std::string> valued = ValuedOptions();
  if (sparse_only) valued.erase("stages");
  Args args(valued, kFlags);
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, help, 2, SIZE_MAX)) return *exit_code;
  std::vector<std::string> inputs = args.positionals();
  const Project project(inputs.back());
  inputs.pop_back();
  auto options = ReconstructOptionsFromArgs(args);
  if (!options.ok()) return Fail(options.status());
  if (sparse_only) {
    options->run_dense = options->run_mesh = options->run_texture = false;
    options->render_preview = nullptr;
  }
  auto paths = CollectImagePaths(inputs);
  if (!paths.ok()) return Fail(paths.status());
  return ReconstructAndPrint(*paths, project, *options, args.Has("json"));
}

int ReconstructAndPrint(const std::vector<std::string>& paths, const Project& project,
                        const ReconstructOptions& options, bool json) {
  auto report = RunReconstruct(paths, project, options);
  if (!report.ok()) return Fail(report.status());
  if (!report->preview_error.empty()) std::fprintf(stderr, "warning: no preview: %s\n", report->preview_error.c_str());
  if (json) {
    auto text = ReadFileToString(report->report_path);
    if (!text.ok()) return Fail(text.status());
    std::fputs(text->c_str(), stdout);
    return 0;
  }
  PrintReport(*report, project);
  return 0;
}

}  // namespace reconar::tools
