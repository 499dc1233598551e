#include "core/pipeline/reconstruct.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <thread>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/base/json_writer.h"
#include "core/base/memory_usage.h"
#include "core/base/thread_pool.h"
#include "core/io/image_io.h"
#include "core/pipeline/map_stage.h"
#include "core/pipeline/project_lock.h"
#include "core/pipeline/stage_record.h"
#include "core/pipeline/weak_registrations.h"
#include "core/sfm/model_io.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;


bool Exists(const std::string& path) {
  std::error_code error;
  return std::filesystem::exists(path, error);
}

// The decoded photo, its grey copy and SIFT's first doubled octave are what one feature worker
// holds beyond its arena: about 8 bytes per pixel of the largest photo (measured by the arena's own
// sizing, RequiredArenaBytes, for the pyramid itself).
constexpr size_t kFeatureBytesPerPixel = 8;

// Pixels of the first readable photo, from its header: a project's photos usually come from one
// camera.
size_t TypicalPixelCount(const std::vector<std::string>& paths) {
  for (const std::string& path : paths) {
    auto header = ReadImageHeader(path);
    if (header.ok()) return static_cast<size_t>(header->width) * static_cast<size_t>(header->height);
  }
  return 0;
}

double NumberAt(const JsonValue* object, const char* key) {
  if (object == nullptr) return 0.0;
  const JsonValue* value = object->Find(key);
  return value != nullptr && value->is_number() ? value->number() : 0.0;
}

class StageRunner {
 public:
  StageRunner(const Project& project, const ReconstructOptions& options, ReconstructReport* report)
      : options_(options), report_(report), record_(project) {
    // What an earlier run measured for the stages this one reuses.
    if (auto previous = ReadJsonFile(project.ReportPath()); previous.ok()) {
      const JsonValue* stages = previous->Find("stages");
      for (size_t i = 0; stages != nullptr && i < stages->size(); ++i) {
        const JsonValue& stage = (*stages)[i];
        const JsonValue* name = stage.Find("name");
        if (name == nullptr || !name->is_string()) continue;
        StageSummary& summary = previous_[name->string()];
        summary.seconds = NumberAt(&stage, "seconds");
        summary.peak_rss_bytes = static_cast<size_t>(NumberAt(&stage, "peak_rss_mib") * (1 << 20));
        const JsonValue* note = stage.Find("note");
        if (note != nullptr && note->is_string()) summary.note = note->string();
      }
    }
  }

  // Runs `body` unless the stage finished with these settings (and `outputs_present`); records it
  // unless the stage records itself (the map stage).
  Status Run(const std::string& name, const std::string& settings, bool outputs_present, bool force_redo,
             const std::function<Status(StageSummary*)>& body, bool records_itself = false) {
    StageSummary summary;
    summary.name = name;
    const bool reuse = !options_.force && !force_redo && outputs_present && record_.Finished(name, settings);
    ++index_;
    if (reuse) {
      if (const auto it = previous_.find(name); it != previous_.end()) summary = it->second;
      summary.name = name;
      summary.reused = true;
      if (options_.show_progress)
        std::fprintf(stderr, "reconstruct: [%d] %s: finished earlier, reused\n", index_, name.c_str());
      Add(summary);
      return Status::Ok();
    }
    // No later stage reads a side stage's outputs; of the tags' only mapping does (the caller's).
    if (!IsSideStage(name) && name != "tags") redone_ = true;
    if (options_.show_progress) std::fprintf(stderr, "reconstruct: [%d] %s\n", index_, name.c_str());
    ReleaseFreeHeapMemory();
    ResetPeakResidentBytes();
    const auto start = Clock::now();
    RECONAR_RETURN_IF_ERROR(body(&summary).WithContext(name));
    summary.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    // A stage that resets the peak itself (per phase) reports its own maximum in the summary.
    summary.peak_rss_bytes = std::max(summary.peak_rss_bytes, PeakResidentBytes());
    if (!records_itself) RECONAR_RETURN_IF_ERROR(record_.Record(name, settings));
    Add(summary);
    return Status::Ok();
  }
  // A stage redone in this run: the ones after it must be redone too.
  bool redone() const { return redone_; }

 private:
  // A stage run a second time (matching and mapping, for the photos mapped weakly) is one entry:
  // its times added, its peak the higher, its notes joined.
  void Add(const StageSummary& summary) {
    for (StageSummary& earlier : report_->stages) {
      if (earlier.name != summary.name) continue;
      earlier.reused = earlier.reused && summary.reused;
      earlier.seconds += summary.seconds;
      earlier.peak_rss_bytes = std::max(earlier.peak_rss_bytes, summary.peak_rss_bytes);
      if (!summary.note.empty() && summary.note != earlier.note)
        earlier.note += (earlier.note.empty() ? "" : "; then ") + summary.note;
      return;
    }
    report_->stages.push_back(summary);
  }

  const ReconstructOptions& options_;
  ReconstructReport* report_;
  StageRecord record_;
  std::map<std::string, StageSummary> previous_;
  int index_ = 0;
  bool redone_ = false;
};

std::string ReadOr(const std::string& path, const std::string& fallback) {
  auto text = ReadFileToString(path);
  return text.ok() ? *text : fallback;
}

struct StageReports {
  std::string matching_text, sparse_text, tags_text, dense_text, mesh_text;
};

StageReports ReadStageReports(const Project& project) {
  return {ReadOr(project.MatchesDir() + "/report.json", "null"), ReadOr(project.SparseDir() + "/report.json", "null"), ReadOr(project.TagsJsonPath(), "null"),
          ReadOr(project.root() + "/dense/report.json", "null"), ReadOr(project.MeshDir() + "/report.json", "null")};
}

Table1 Table1From(const StageReports& reports) {
  const auto sparse = ParseJson(reports.sparse_text, "sparse/report.json");
  const auto dense = ParseJson(reports.dense_text, "dense/report.json");
  const auto mesh = ParseJson(reports.mesh_text, "mesh/report.json");
  const JsonValue* s = sparse.ok() ? &*sparse : nullptr;
  Table1 table;
  table.images = static_cast<int>(NumberAt(s, "images"));
  table.registered = static_cast<int>(NumberAt(s, "registered"));
  table.sparse_points = static_cast<int>(NumberAt(s, "points"));
  table.mean_focal_ratio = NumberAt(s, "mean_focal_ratio");
  table.rmse_focal_ratio = NumberAt(s, "rmse_focal_ratio");
  table.focal_35mm_equivalent_mm = NumberAt(s, "focal_35mm_equivalent_mm");
  table.dense_points = static_cast<long long>(NumberAt(dense.ok() ? &*dense : nullptr, "points"));
  table.mesh_vertices = static_cast<long long>(NumberAt(mesh.ok() ? &*mesh : nullptr, "vertices"));
  table.mesh_faces = static_cast<long long>(NumberAt(mesh.ok() ? &*mesh : nullptr, "triangles"));
  return table;
}

std::string ReportJson(const StageReports& reports, const ReconstructOptions& options,
                       const ReconstructReport& report) {
  const Table1& table = report.table1;
  JsonWriter json(2);
  json.BeginObject();
  json.Key("table1").BeginObject();  // the paper's Table 1 columns
  json.Key("images").Int(table.images);
  json.Key("registered").Int(table.registered);
  json.Key("sparse_points").Int(table.sparse_points);
  json.Key("mean_focal_ratio").Double(table.mean_focal_ratio);
  json.Key("rmse_focal_ratio").Double(table.rmse_focal_ratio);
  json.Key("focal_35mm_equivalent_mm").Double(table.focal_35mm_equivalent_mm);
  json.Key("dense_points").Int(table.dense_points);
  json.Key("mesh_vertices").Int(table.mesh_vertices);
  json.Key("mesh_faces").Int(table.mesh_faces);
  json.EndObject();
  json.Key("metric").Bool(report.metric);
  json.Key("scale").String(report.metric ? "metres, world frame of the reference tag (tags.json)" : report.scale_note);
  json.Key("memory_budget_mib").Double(Mib(options.memory_budget_bytes));
  size_t peak = 0;
  double seconds = 0.0;
  json.Key("stages").BeginArray();
  for (const StageSummary& stage : report.stages) {
    json.BeginObject().Key("name").String(stage.name).Key("reused").Bool(stage.reused);
    json.Key("seconds").Double(stage.seconds).Key("peak_rss_mib").Double(Mib(stage.peak_rss_bytes));
    if (!stage.note.empty()) json.Key("note").String(stage.note);
    json.EndObject();
    peak = std::max(peak, stage.peak_rss_bytes);
    seconds += stage.seconds;
  }
  json.EndArray();
  json.Key("seconds").Double(seconds).Key("peak_rss_mib").Double(Mib(peak));
  const auto raw_or_null = [](const std::string& text, const char* name) {
    return ParseJson(text, name).ok() ? text : std::string("null");
  };
  json.Key("matching").Raw(raw_or_null(reports.matching_text, "matches/report.json"));
  json.Key("sparse").Raw(raw_or_null(reports.sparse_text, "sparse/report.json"));
  json.Key("tags").Raw(raw_or_null(reports.tags_text, "tags.json"));
  json.Key("dense").Raw(raw_or_null(reports.dense_text, "dense/report.json"));
  json.Key("mesh").Raw(raw_or_null(reports.mesh_text, "mesh/report.json"));
  json.EndObject();
  return json.str() + "\n";
}

}  // namespace

ReconstructOptions::ReconstructOptions() {
  matching.match.max_ratio = 0.8;
  matching.two_view.min_inliers = 30;
  mesh.poisson.depth = 10;
  mesh.poisson.trim = 7.0;
  mesh.max_faces = kHandheldMaxFaces;
}

Eigen::Vector3d UpFromCameras(const Project& project) {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  if (auto model = ReadColmapTextModel(project.SparseDir()); model.ok()) {
    for (const SfmImage& image : model->images) {
      if (image.registered) up -= image.cam_from_world.rotation.row(1).transpose();
    }
  }
  return up.norm() > 1e-9 ? Eigen::Vector3d(up.normalized()) : Eigen::Vector3d(-Eigen::Vector3d::UnitY());
}

Status ReconstructOptions::Check() const {
  if (tag_size_m < 0.0 || !std::isfinite(tag_size_m)) return InvalidArgument("the tag size must be positive");
  if (tag_size_m > 0.0 && !detect_tags) return InvalidArgument("reconstruct: tags requested without a tag detector");
  if (memory_budget_bytes < (64u << 20)) return InvalidArgument("the memory budget must be at least 64 MiB");
  if (!(sfm.mapper.max_reprojection_error_px > 0.0))
    return InvalidArgument("the maximum reprojection error must be positive");
  RECONAR_RETURN_IF_ERROR(map.Check());
  RECONAR_RETURN_IF_ERROR(dense.Check());
  RECONAR_RETURN_IF_ERROR(texture.Check());
  return mesh.Check();
}

Result<ReconstructReport> RunReconstruct(const std::vector<std::string>& image_paths, const Project& project,
                                         const ReconstructOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (options.run_sparse && image_paths.size() < 2) {
    return InvalidArgument("reconstruct needs at least 2 photos, got " + std::to_string(image_paths.size()));
  }
  RECONAR_RETURN_IF_ERROR(CreateDirectories(project.root()));
  RECONAR_ASSIGN_OR_RETURN(const ProjectLock lock, LockProject(project));
  RECONAR_ASSIGN_OR_RETURN(const int stale, RemoveStaleTemporaryFiles(project.root()));
  if (stale > 0) std::fprintf(stderr, "removed %d temporary file(s) of an interrupted run\n", stale);
  ReconstructReport report;
  StageRunner runner(project, options, &report);
  const int threads = ThreadPool::ResolveThreadCount(options.num_threads);
  const size_t budget = options.memory_budget_bytes;

  if (options.run_sparse) {
    // Features: as many photos at once as the budget holds, each worker with its SIFT arena.
    FeatureStageOptions features = options.features;
    const size_t pixels = TypicalPixelCount(image_paths);
    const size_t per_photo = kFeatureBytesPerPixel * pixels;
    std::string feature_note;
    size_t arena = features.sift.arena_bytes;
    if (per_photo + arena > budget) {
      arena = budget > per_photo + (64u << 20) ? budget - per_photo : (64u << 20);
      feature_note = "SIFT arena lowered to " + std::to_string(static_cast<int>(Mib(arena))) +
                     " MiB for the memory budget (large photos start at octave 0)";
    }
    features.sift.arena_bytes = arena;
    const int fitting = static_cast<int>(std::max<size_t>(1, budget / (arena + per_photo)));
    features.num_threads = std::min(threads, fitting);
    if (features.num_threads < threads) {
      feature_note += std::string(feature_note.empty() ? "" : "; ") + std::to_string(features.num_threads) +
                      " photo(s) at a time for the memory budget";
    }
    features.show_progress = options.show_progress;
    const auto run_features = [&](StageSummary* summary) -> Status {
      summary->note = feature_note;
      RECONAR_ASSIGN_OR_RETURN(const FeatureStageReport r, RunFeatureStage(image_paths, &project, features));
      for (const std::string& skipped : r.skipped) std::fprintf(stderr, "warning: skipped %s\n", skipped.c_str());
      return Status::Ok();
    };
    RECONAR_RETURN_IF_ERROR(runner.Run("features", FeatureStageSettings(features),
                                       FeaturesUpToDate(project, image_paths), false, run_features));

    // Tags before matching: they read the photos alone, so matching again (below) keeps them.
    const bool with_tags = options.tag_size_m > 0.0;
    bool tags_redone = false;
    if (with_tags) {
      const auto run_tags = [&](StageSummary* summary) -> Status {
        RECONAR_ASSIGN_OR_RETURN(const TagDetectionsFile detections, options.detect_tags(image_paths));
        int with = 0;
        for (const ImageTagObservations& image : detections.images) with += image.tags.empty() ? 0 : 1;
        summary->note = std::to_string(with) + " of " + std::to_string(detections.images.size()) + " photos show a tag";
        RECONAR_RETURN_IF_ERROR(CreateDirectories(project.root() + "/tags"));
        return WriteTagDetections(project.TagDetectionsPath(), detections);
      };
      RECONAR_RETURN_IF_ERROR(
          runner.Run("tags", options.tag_family, Exists(project.TagDetectionsPath()), runner.redone(), run_tags));
      tags_redone = !report.stages.back().reused;
    }

    MatchStageOptions matching = options.matching;
    matching.poorly_matched.sift = features.sift;
    // Resumed after a second matching (below): continue from it.
    if (options.extract_weak_photos_again) matching.extract_again = RecordedExtractAgain(project);
    matching.num_threads = threads;
    matching.memory_budget_bytes = budget;
    matching.show_progress = options.show_progress;
    const auto run_matching = [&](StageSummary* summary) -> Status {
      RECONAR_ASSIGN_OR_RETURN(const MatchStageReport r, RunMatchStage(project, matching));
      if (r.num_blocks > 1) {
        summary->note =
            "photos matched in " + std::to_string(r.num_blocks) + " blocks, two at a time, for the memory budget";
      }
      if (!r.reextracted.empty()) {
        summary->note += std::string(summary->note.empty() ? "" : "; ") + std::to_string(r.reextracted.size()) +
                         " photo(s) extracted again at a lower contrast threshold (matches/report.json says why)";
      }
      return Status::Ok();
    };
    RECONAR_RETURN_IF_ERROR(runner.Run("matching", MatchStageSettings(matching), Exists(project.MatchesPath()),
                                       runner.redone(), run_matching));

    SfmStageOptions sfm = options.sfm;
    sfm.mapper.num_threads = threads;
    sfm.show_progress = options.show_progress;
    sfm.tags.enabled = with_tags;
    sfm.tags.registration.tag_size_m = with_tags ? options.tag_size_m : 1.0;
    const auto run_mapping = [&](StageSummary* summary) -> Status {
      RECONAR_ASSIGN_OR_RETURN(const SfmStageReport r, RunSfmStage(project, sfm));
      if (r.live_model == SfmStageReport::LiveModel::kContinued) {
        summary->note = "continued from the capture's live model";
      } else if (r.live_model == SfmStageReport::LiveModel::kNotUsed) {
        summary->note = "the capture's live model not used: " + r.live_model_reason;
      }
      if (with_tags && !r.tags.metric)
        summary->note += std::string(summary->note.empty() ? "" : "; ") + "no metric registration: " + r.tags.reason;
      if (r.mapper.models.size() > 1) {
        std::string sizes;
        for (size_t k = 1; k < r.mapper.models.size(); ++k)
          sizes += (k > 1 ? ", " : "") + std::to_string(r.mapper.models[k].images.size());
        summary->note += std::string(summary->note.empty() ? "" : "; ") + std::to_string(r.mapper.models.size()) +
                         " models: the largest in sparse/, the others (" + sizes + " images) in sparse/model2...";
      }
      if (!r.mapper.merges.empty()) {
        summary->note += std::string(summary->note.empty() ? "" : "; ") + std::to_string(r.mapper.merges.size()) +
                         (r.mapper.merges.size() == 1 ? " model" : " models") + " merged into the largest";
      }
      if (!with_tags) {
        RECONAR_RETURN_IF_ERROR(RemoveFileIfPresent(project.TagsJsonPath()));
        RECONAR_RETURN_IF_ERROR(RemoveFileIfPresent(project.TagLayoutPath()));
      }
      JsonWriter json(2);
      json.BeginObject();
      WriteSfmReportFields(r, &json);
      json.EndObject();
      return WriteFileAtomically(project.SparseDir() + "/report.json", json.str() + "\n");
    };
    const auto map_matches = [&]() {
      return runner.Run("mapping", SfmStageSettings(sfm) + ExtractAgainDigest(matching.extract_again),
                        Exists(project.SparseDir() + "/report.json"), runner.redone() || tags_redone, run_mapping);
    };
    RECONAR_RETURN_IF_ERROR(map_matches());
    // The photos the mapper registered weakly, and their partners, extracted again and matched
    // again, and the photos mapped again (weak_registrations.h): once.
    if (options.extract_weak_photos_again && matching.extract_again.empty()) {
      RECONAR_ASSIGN_OR_RETURN(const auto weak, WeaklyRegisteredPhotos(project));
      if (!weak.empty()) {
        if (options.show_progress)
          std::fprintf(stderr, "reconstruct: %zu photo(s) registered weakly or not at all, or paired with them: "
                       "extracting them again\n", weak.size());
        matching.extract_again = weak;
        RECONAR_RETURN_IF_ERROR(runner.Run("matching", MatchStageSettings(matching), Exists(project.MatchesPath()),
                                           runner.redone(), run_matching));
        RECONAR_RETURN_IF_ERROR(map_matches());
      }
    }

    MapStageOptions map = options.map;
    map.build.num_threads = threads;
    const auto run_map = [&](StageSummary* summary) -> Status {
      RECONAR_ASSIGN_OR_RETURN(const MapStageReport r, RunMapStage(project, map));
      summary->note = std::to_string(r.build.keyframes) + " keyframes, " + std::to_string(r.build.points) +
                      " points, " + std::to_string(static_cast<int>(Mib(r.file_bytes) + 0.5)) + " MiB";
      return Status::Ok();
    };
    RECONAR_RETURN_IF_ERROR(
        runner.Run("map", MapStageSettings(map), Exists(project.MapDir() + "/report.json"), runner.redone(), run_map,
                   /*records_itself=*/true));
  }

  if (options.run_dense) {
    DenseStageOptions dense = options.dense;
    dense.memory_budget_bytes = budget;
    dense.num_threads = threads;
    dense.show_progress = options.show_progress;
    const auto run_dense = [&](StageSummary* summary) -> Status {
      RECONAR_ASSIGN_OR_RETURN(const DenseStageReport r, RunDenseStage(project, dense));
      for (const DensePhase* phase :
           {&r.load, &r.clustering, &r.undistort, &r.mvs, &r.merge, &r.outlier_filter, &r.write}) {
        summary->peak_rss_bytes = std::max(summary->peak_rss_bytes, phase->peak_rss_bytes);
      }
      if (r.level_auto && r.level > 0) {
        summary->note = "level " + std::to_string(r.level) +
                        (r.level > r.finest_level_within_size ? " for the memory budget" : " for the image size limit");
      }
      if (r.cluster_size_reduced) {
        summary->note += std::string(summary->note.empty() ? "" : "; ") + "clusters of at most " +
                         std::to_string(r.max_cluster_size) + " images for the memory budget";
      }
      return Status::Ok();
    };
    RECONAR_RETURN_IF_ERROR(
        runner.Run("dense", DenseStageSettings(dense), Exists(project.root() + "/dense/report.json"), runner.redone(), run_dense));
  }

  if (options.run_mesh) {
    MeshStageOptions mesh = options.mesh;
    mesh.memory_budget_bytes = budget;
    mesh.poisson.num_threads = threads;
    mesh.poisson.show_progress = options.show_progress;
    const auto run_mesh = [&](StageSummary* summary) -> Status {
      RECONAR_ASSIGN_OR_RETURN(const MeshStageReport r, RunMeshStage(project, mesh));
      summary->peak_rss_bytes = std::max(r.peak_rss_bytes, r.pilot_peak_bytes);
      if (r.depth_lowered_for_budget) {
        summary->note = "Poisson depth " + std::to_string(r.depth) + " for the memory budget";
      }
      if (r.simplified) {
        summary->note += std::string(summary->note.empty() ? "" : "; ") + "simplified from " +
                         std::to_string(r.simplify.faces_before) + " to " + std::to_string(r.faces) + " faces";
      }
      return Status::Ok();
    };
    RECONAR_RETURN_IF_ERROR(runner.Run("mesh", MeshStageSettings(mesh), Exists(project.MeshDir() + "/report.json"), runner.redone(), run_mesh));
  }

  if (options.run_mesh && options.run_texture) {
    TextureStageOptions texture = options.texture;
    texture.memory_budget_bytes = budget;
    texture.num_threads = threads;
    texture.show_progress = options.show_progress;
    const auto run_texture = [&](StageSummary* summary) -> Status {
      const Result<TextureStageReport> r = RunTextureStage(project, texture);
      if (!r.ok()) {
        summary->note = "not textured: " + r.status().message();
        std::fprintf(stderr, "warning: the model is not textured: %s\n", r.status().ToString().c_str());
        return Status::Ok();
      }
      summary->peak_rss_bytes = r->peak_rss_bytes;
      summary->note = std::to_string(r->texture.faces) + " faces, " + std::to_string(r->texture.patches) +
                      " patches from " + std::to_string(r->texture.photos_used) + " photos";
      return Status::Ok();
    };
    RECONAR_RETURN_IF_ERROR(runner.Run("texture", TextureStageSettings(texture),
                                       Exists(TexturedModelFilesOf(project).report), runner.redone(),
                                       run_texture));
  }

  // Scale: what tags.json says.
  if (auto tags = ReadJsonFile(project.TagsJsonPath()); tags.ok()) {
    const JsonValue* metric = tags->Find("metric");
    report.metric = metric != nullptr && metric->is_bool() && metric->bool_value();
    const JsonValue* reason = tags->Find("reason");
    if (!report.metric)
      report.scale_note = reason != nullptr && reason->is_string() ? reason->string() : "no tag registered";
  } else {
    report.scale_note = "arbitrary (no --tag-size given)";
  }
  const StageReports reports = ReadStageReports(project);
  report.table1 = Table1From(reports);
  report.report_path = project.ReportPath();
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(report.report_path, ReportJson(reports, options, report)));

  if (options.render_preview) {
    // What this run made last.
    std::string model = options.run_dense ? project.DensePointsPath() : project.SparseDir() + "/points.ply";
    for (const char* format : {"ply", "glb", "obj"}) {  // the readable mesh formats, the fastest first
      const auto& formats = options.mesh.formats;
      if (options.run_mesh && std::find(formats.begin(), formats.end(), format) != formats.end()) {
        model = project.MeshDir() + "/mesh." + format;
        break;
      }
    }
    std::error_code error;
    if (options.run_mesh && options.run_texture && std::filesystem::exists(TexturedModelPath(project), error)) {
      model = TexturedModelPath(project);
    }
    const std::string png = project.root() + "/preview.png";
    if (Status s = options.render_preview(model, UpFromCameras(project), png); s.ok()) {
      report.preview_path = png;
    } else {
      report.preview_error = s.ToString();
    }
  }
  return report;
}


}  // namespace reconar
