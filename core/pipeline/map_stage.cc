#include "core/pipeline/map_stage.h"

#include <sys/stat.h>

#include <chrono>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/base/json_writer.h"
#include "core/features/sift/sift_io.h"
#include "core/pipeline/project_lock.h"
#include "core/pipeline/stage_record.h"
#include "core/sfm/model_io.h"

namespace reconar {
namespace {

// "metres, world tag N" (or the declared layout's frame) and true when tags.json says the model is metric.
std::pair<std::string, bool> ModelFrame(const Project& project) {
  auto tags = ReadJsonFile(project.TagsJsonPath());
  if (!tags.ok()) return {"arbitrary", false};
  const JsonValue* metric = tags->Find("metric");
  const JsonValue* world_tag = tags->Find("world_tag");
  if (metric == nullptr || !metric->is_bool() || !metric->bool_value()) return {"arbitrary", false};
  const JsonValue* frame = tags->Find("frame");
  if (frame != nullptr && frame->is_string() && frame->string() == "layout") return {"metres, the declared layout's frame", true};
  const int tag = world_tag != nullptr && world_tag->is_number() ? static_cast<int>(world_tag->number()) : 0;
  return {"metres, world tag " + std::to_string(tag), true};
}

}  // namespace

std::string MapStageSettings(const MapStageOptions& options) {
  return StageRecord::Settings({{"version", 1},
                                {"branching", options.build.vocabulary.branching},
                                {"depth", options.build.vocabulary.depth},
                                {"medoid_candidates", options.build.max_medoid_candidates}});
}

Result<MapStageReport> RunMapStage(const Project& project, const MapStageOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  const auto start = std::chrono::steady_clock::now();
  struct stat info {};
  if (::stat((project.SparseDir() + "/points3D.txt").c_str(), &info) != 0) {
    return FailedPrecondition(project.SparseDir() +
                              ": no sparse model (run `reconar reconstruct` or `reconar sfm` first)");
  }
  RECONAR_ASSIGN_OR_RETURN(const ProjectLock lock, LockProject(project));
  RECONAR_ASSIGN_OR_RETURN(const Reconstruction model, ReadColmapTextModel(project.SparseDir()));
  const ImageDescriptorLoader load = [&](const SfmImage& image) -> Result<std::vector<uint8_t>> {
    RECONAR_ASSIGN_OR_RETURN(FeatureFile features, ReadFeatureFile(project.MatchedFeaturePath(image.name)));
    return std::move(features.features.descriptors);
  };
  MapStageReport report;
  std::tie(report.frame, report.metric) = ModelFrame(project);
  RECONAR_ASSIGN_OR_RETURN(const LocalizationMap map, BuildLocalizationMap(model, load, report.frame, report.metric,
                                                                           options.build, &report.build));
  RECONAR_RETURN_IF_ERROR(CreateDirectories(project.MapDir()));
  report.path = project.MapPath();
  RECONAR_RETURN_IF_ERROR(WriteLocalizationMap(report.path, map));
  if (::stat(report.path.c_str(), &info) == 0) report.file_bytes = static_cast<size_t>(info.st_size);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  JsonWriter json(2);
  json.BeginObject();
  json.Key("frame").String(report.frame).Key("metric").Bool(report.metric);
  json.Key("keyframes").Int(report.build.keyframes).Key("points").Int(report.build.points);
  json.Key("observations").Int(report.build.observations).Key("words").Int(report.build.words);
  json.Key("file_bytes").Int(static_cast<long long>(report.file_bytes));
  json.Key("memory_bytes").Int(static_cast<long long>(report.build.memory_bytes));
  json.Key("seconds_descriptors").Double(report.build.seconds_descriptors);
  json.Key("seconds_vocabulary").Double(report.build.seconds_vocabulary);
  json.Key("seconds_index").Double(report.build.seconds_index);
  json.Key("seconds").Double(report.seconds);
  json.EndObject();
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(project.MapDir() + "/report.json", json.str() + "\n"));
  // The map now matches the model: a later `reconstruct` reuses it.
  RECONAR_RETURN_IF_ERROR(StageRecord(project).Record("map", MapStageSettings(options)));
  return report;
}

}  // namespace reconar
