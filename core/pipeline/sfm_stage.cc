#include "core/pipeline/sfm_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include "core/base/atomic_file.h"
#include "core/base/elapsed.h"
#include "core/base/fnv_hash.h"
#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/features/sift/sift_io.h"
#include "core/io/image_io.h"
#include "core/pipeline/matches_file.h"
#include "core/pipeline/stage_record.h"
#include "core/sfm/mapper_adjustment.h"
#include "core/sfm/model_io.h"
#include "core/sfm/tag_layout.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

// Each point takes the colour of the pixel under its first observation.
Status ColourPoints(const std::vector<ProjectImage>& list, int num_threads, Reconstruction* rec) {
  std::vector<std::vector<std::pair<int, int>>> wanted(rec->images.size());  // (point, keypoint)
  for (size_t p = 0; p < rec->points.size(); ++p) {
    const SfmPoint& point = rec->points[p];
    if (point.deleted || point.track.empty()) continue;
    wanted[static_cast<size_t>(point.track.front().image_id)].emplace_back(static_cast<int>(p),
                                                                           point.track.front().keypoint_id);
  }
  std::vector<Status> errors(rec->images.size());
  ThreadPool pool(ThreadPool::ResolveThreadCount(num_threads));
  pool.ParallelFor(0, rec->images.size(), [&](size_t i, int) {
    if (wanted[i].empty()) return;
    auto decoded = ReadImage(list[i].path);
    if (!decoded.ok()) {
      errors[i] = decoded.status();
      return;
    }
    const Image<uint8_t>& rgb = decoded->rgb;
    for (const auto& [point_id, keypoint] : wanted[i]) {
      const Eigen::Vector2d& x = rec->images[i].keypoints[static_cast<size_t>(keypoint)];
      const int u = std::clamp(static_cast<int>(std::lround(x.x())), 0, rgb.width() - 1);
      const int v = std::clamp(static_cast<int>(std::lround(x.y())), 0, rgb.height() - 1);
      const uint8_t* pixel = rgb.row(v) + 3 * u;
      rec->points[static_cast<size_t>(point_id)].color = {pixel[0], pixel[1], pixel[2]};
    }
  });
  for (const Status& status : errors) RECONAR_RETURN_IF_ERROR(status);
  return Status::Ok();
}

void FocalStatistics(const Reconstruction& rec, SfmStageReport* report) {
  std::vector<double> ratios;
  for (const SfmImage& image : rec.images) {
    if (!image.registered) continue;
    const SfmCamera& camera = rec.cameras[static_cast<size_t>(image.camera_id)];
    ratios.push_back(camera.focal / std::max(camera.width, camera.height));
  }
  if (ratios.empty()) return;
  double mean = 0.0;
  for (double r : ratios) mean += r;
  mean /= static_cast<double>(ratios.size());
  double squares = 0.0;
  for (double r : ratios) squares += (r - mean) * (r - mean);
  report->mean_focal_ratio = mean;
  report->rmse_focal_ratio = std::sqrt(squares / static_cast<double>(ratios.size()));
  report->focal_35mm_equivalent = 36.0 * mean;  // the long side of a 36 x 24 mm frame
}

void LiveModelNotUsed(SfmStageReport* report, const std::string& reason) {
  report->live_model = SfmStageReport::LiveModel::kNotUsed;
  report->live_model_reason = reason;
}

// The capture's live model (PROJECT/live/) when options allow and it can seed the mapper, without
// the photos the project no longer holds (`index_of`: the project's photos by name); else an
// error, with the report saying why when there is a model.
Result<Reconstruction> LiveModel(const Project& project, const SfmStageOptions& options,
                                 const std::map<std::string, int>& index_of, SfmStageReport* report) {
  report->live_model = SfmStageReport::LiveModel::kNone;
  report->live_model_reason.clear();
  const std::string dir = project.LiveDir();
  std::error_code error;
  if (!options.continue_from_live || !std::filesystem::exists(dir + "/points3D.txt", error))
    return NotFound(dir + ": no live model");
  Result<Reconstruction> live = ReadColmapTextModel(dir);
  if (!live.ok()) {
    LiveModelNotUsed(report, live.status().message());
    return live.status();
  }
  for (SfmImage& image : live->images) image.registered = image.registered && index_of.count(image.name) > 0;
  if (live->NumRegisteredImages() < 2) {
    LiveModelNotUsed(report, dir + " holds fewer than two of the photos");
    return FailedPrecondition(report->live_model_reason);
  }
  return live;
}

Result<Reconstruction> ContinueFromLiveModel(const Reconstruction& live, const std::vector<MapperImage>& images,
                                             const std::vector<MapperPair>& pairs, const MapperOptions& options,
                                             const MapperProgress& progress, SfmStageReport* report) {
  Result<Reconstruction> continued =
      ContinueIncrementalMapper(images, pairs, options, live, nullptr, &report->mapper, progress);
  if (!continued.ok()) {
    LiveModelNotUsed(report, continued.status().message());
    return continued;
  }
  report->live_model = SfmStageReport::LiveModel::kContinued;
  MapperReport::Model summary;
  for (const SfmImage& image : continued->images) {
    if (image.registered) summary.images.push_back(image.name);
  }
  summary.num_points = continued->NumPoints();
  summary.initial_pair = "continued from the live model";
  report->mapper.initial_pair = summary.initial_pair;
  report->mapper.models = {std::move(summary)};
  return continued;
}

}  // namespace

MapperImage ToMapperImage(const ProjectImage& image, const std::vector<SiftKeypoint>& keypoints) {
  MapperImage out;
  out.name = image.name;
  out.width = image.width;
  out.height = image.height;
  out.focal_prior = image.focal_px;
  out.focal_from_exif = image.focal_source.rfind("exif", 0) == 0;
  out.keypoints.reserve(keypoints.size());
  out.keypoint_scales.reserve(keypoints.size());
  for (const SiftKeypoint& k : keypoints) {
    out.keypoints.emplace_back(k.x, k.y);
    out.keypoint_scales.push_back(k.scale);
  }
  return out;
}

MapperPair ToMapperPair(int image_a, int image_b, const std::vector<FeatureMatch>& matches, bool planar) {
  MapperPair pair;
  pair.matches.image_a = image_a;
  pair.matches.image_b = image_b;
  pair.matches.matches = matches;
  pair.planar = planar;
  return pair;
}

std::string SfmStageSettings(const SfmStageOptions& options) {
  const MapperOptions& mapper = options.mapper;
  const bool with_tags = options.tags.enabled;
  std::string settings =
      StageRecord::Settings({{"principal_point", static_cast<double>(mapper.principal_point)},
                             {"min_verified_inliers", static_cast<double>(mapper.registration_min_verified_inliers)},
                             {"min_baseline_points", static_cast<double>(mapper.registration_min_baseline_points)},
                             {"min_inlier_spread", mapper.registration_min_inlier_spread},
                             {"max_models", static_cast<double>(mapper.max_models)},
                             {"min_model_images", static_cast<double>(mapper.min_model_images)},
                             {"max_starts", static_cast<double>(mapper.init_max_starts)},
                             {"merge_models", mapper.merge_models ? 1.0 : 0.0},
                             {"max_error", mapper.max_reprojection_error_px},
                             {"refine_distortion", mapper.refine_distortion ? 1.0 : 0.0},
                             {"tag_size", with_tags ? options.tags.registration.tag_size_m : 0.0},
                             {"world_tag", options.tags.registration.world_tag},
                             {"tags_in_ba", options.tags.in_adjustment ? 1.0 : 0.0}});
  // Tag projects map differently since images register by their known tags and the world tag is
  // fitted as a square (version 2), and since the adjustments hold the scale tags to squares and
  // only adjusted tags set the scale (version 3): their recorded mapping is not reused. Others are
  // unchanged.
  if (with_tags) {
    settings += " " + StageRecord::Settings({{"tag_mapping", 3.0}, {"tag_square_sigma", mapper.tag_square_sigma}});
    std::string ids;
    for (int id : options.tags.registration.scale_tags) ids += (ids.empty() ? "" : ",") + std::to_string(id);
    if (!ids.empty()) settings += " scale_tags=" + ids;
    const TagLayout& layout = options.tags.registration.layout;
    if (!layout.empty()) {
      Fnv1a64 hash;
      hash.Add(FormatTagLayout(layout.tags()));
      char text[40];
      std::snprintf(text, sizeof(text), " layout=%zu:%016llx", layout.tags().size(),
                    static_cast<unsigned long long>(hash.value()));
      settings += text;
    }
  }
  return settings;
}

Result<SfmStageReport> RunSfmStage(const Project& project, const SfmStageOptions& options,
                                   Reconstruction* reconstruction_out) {
  SfmStageReport report;
  auto start = Clock::now();
  RECONAR_ASSIGN_OR_RETURN(const std::vector<ProjectImage> list, project.ReadImageList());
  std::map<std::string, int> index_of;
  std::vector<MapperImage> images(list.size());
  for (size_t i = 0; i < list.size(); ++i) {
    index_of[list[i].name] = static_cast<int>(i);
    const std::string path = project.MatchedFeaturePath(list[i].name);
    RECONAR_ASSIGN_OR_RETURN(const FeatureFile features, ReadFeatureFile(path));
    if (features.image_width != list[i].width || features.image_height != list[i].height) {
      return FileError(StatusCode::kCorruptData, path, "image size differs from " + project.ImageListPath());
    }
    images[i] = ToMapperImage(list[i], features.features.keypoints);
  }
  RECONAR_ASSIGN_OR_RETURN(const std::vector<MatchesFilePair> matches, ReadMatchesFile(project.MatchesPath()));
  std::vector<MapperPair> pairs;
  pairs.reserve(matches.size());
  for (const MatchesFilePair& m : matches) {
    const auto a = index_of.find(m.name_a), b = index_of.find(m.name_b);
    if (a == index_of.end() || b == index_of.end()) {
      return FileError(StatusCode::kCorruptData, project.MatchesPath(),
                       "pair " + m.name_a + " " + m.name_b + " names an image missing from " + project.ImageListPath());
    }
    pairs.push_back(ToMapperPair(a->second, b->second, m.matches, m.config == "planar"));
  }
  std::vector<std::vector<TagObservation>> tag_observations;
  std::vector<TagCornerKeypoint> corner_keypoints;
  std::string tag_family;
  if (options.tags.enabled) {
    RECONAR_RETURN_IF_ERROR(options.tags.registration.Check());
    RECONAR_ASSIGN_OR_RETURN(const TagDetectionsFile detections, ReadTagDetections(project.TagDetectionsPath()));
    tag_family = detections.family;
    tag_observations.resize(images.size());
    for (const ImageTagObservations& image : detections.images) {
      const auto it = index_of.find(image.image_name);
      if (it == index_of.end()) {
        return FileError(StatusCode::kCorruptData, project.TagDetectionsPath(),
                         "image " + image.image_name + " is missing from " + project.ImageListPath());
      }
      tag_observations[static_cast<size_t>(it->second)] = image.tags;
    }
    const TagLayout& layout = options.tags.registration.layout;
    if (!layout.empty()) {
      std::set<int> detected;
      for (const ImageTagObservations& image : detections.images) {
        for (const TagObservation& tag : image.tags) detected.insert(tag.tag_id);
      }
      if (std::none_of(detected.begin(), detected.end(), [&](int id) { return layout.Find(id) != nullptr; })) {
        return InvalidArgument("the layout holds none of the tags detected in the photos (" +
                               std::to_string(detected.size()) + " ids, " + project.TagDetectionsPath() + ")");
      }
    }
    if (options.tags.in_adjustment) {
      corner_keypoints = AddTagCorrespondences(tag_observations, options.mapper.base_scale_px, kTagCornerWeight,
                                               &images, &pairs);
    }
  }
  report.seconds_load = SecondsSince(start);
  // The scale tags are the squares the adjustments hold (tag_squares.h); the others check them.
  MapperOptions mapper_options = options.mapper;
  mapper_options.square_tags = options.tags.registration.scale_tags;

  start = Clock::now();
  std::unique_ptr<Progress> progress;
  size_t shown = 0;
  if (options.show_progress) progress = std::make_unique<Progress>("mapping", images.size());
  const MapperProgress on_progress = [&](int registered, int) {
    if (!progress) return;
    const auto done = static_cast<size_t>(registered);
    if (done > shown) progress->Advance(done - shown);
    shown = std::max(shown, done);
  };
  std::vector<Reconstruction> other_models;
  Result<Reconstruction> reconstruction = LiveModel(project, options, index_of, &report);
  if (reconstruction.ok()) {
    reconstruction = ContinueFromLiveModel(*reconstruction, images, pairs, mapper_options, on_progress, &report);
  }
  if (!reconstruction.ok() || 2 * reconstruction->NumRegisteredImages() < static_cast<int>(images.size())) {
    MapperReport scratch_report;
    std::vector<Reconstruction> scratch_others;
    auto scratch = RunIncrementalMapper(images, pairs, mapper_options, &scratch_report, on_progress, &scratch_others);
    if (!reconstruction.ok() ||
        (scratch.ok() && scratch->NumRegisteredImages() > reconstruction->NumRegisteredImages())) {
      if (reconstruction.ok()) LiveModelNotUsed(&report, "the mapper from scratch registered more photos");
      reconstruction = std::move(scratch);
      report.mapper = std::move(scratch_report);
      other_models = std::move(scratch_others);
    }
  }
  if (progress) progress->Finish();
  if (!reconstruction.ok()) return reconstruction.status();
  if (options.tags.enabled) {
    report.tags_used = true;
    const std::vector<double> square_check = CrossCheckTagSquares(*reconstruction, images, mapper_options, &report.mapper);
    RECONAR_ASSIGN_OR_RETURN(report.tags, RegisterToTags(tag_observations, corner_keypoints,
                                                         options.tags.registration, &*reconstruction));
    report.tags.square_check = square_check;
  }
  report.seconds_mapping = SecondsSince(start);
  FocalStatistics(*reconstruction, &report);

  start = Clock::now();
  RECONAR_RETURN_IF_ERROR(ColourPoints(list, options.mapper.num_threads, &*reconstruction));
  report.seconds_colour = SecondsSince(start);

  start = Clock::now();
  const std::string sparse = project.SparseDir();
  RECONAR_RETURN_IF_ERROR(CreateDirectories(sparse));
  // An earlier model's marker goes first: a write that fails midway leaves no finished-looking mix.
  RECONAR_RETURN_IF_ERROR(RemoveFileIfPresent(sparse + "/points3D.txt"));
  std::vector<std::string> paths;
  for (const ProjectImage& image : list) paths.push_back(image.path);
  RECONAR_RETURN_IF_ERROR(WriteBundlerModel(*reconstruction, sparse + "/bundle.out", sparse + "/list.txt", paths));
  RECONAR_RETURN_IF_ERROR(WritePointsPly(*reconstruction, sparse + "/points.ply"));
  if (report.tags_used) {
    const double size = options.tags.registration.tag_size_m;
    if (report.tags.metric) {
      RECONAR_RETURN_IF_ERROR(WriteFileAtomically(project.TagLayoutPath(), TagLayoutText(report.tags, size)));
    } else {
      RECONAR_RETURN_IF_ERROR(RemoveFileIfPresent(project.TagLayoutPath()));
    }
    RECONAR_RETURN_IF_ERROR(WriteFileAtomically(project.TagsJsonPath(), TagRegistrationJson(report.tags, tag_family, size)));
  }
  // The other models, each in sparse/model<K>/ (K as in the report's "models", the main one 1).
  for (int k = 2;; ++k) {
    const std::string dir = sparse + "/model" + std::to_string(k);
    if (static_cast<size_t>(k) <= other_models.size() + 1) {
      RECONAR_RETURN_IF_ERROR(CreateDirectories(dir));
      RECONAR_RETURN_IF_ERROR(WriteColmapTextModel(other_models[static_cast<size_t>(k - 2)], dir));
    } else {
      std::error_code error;
      if (!std::filesystem::exists(dir, error)) break;
      std::filesystem::remove_all(dir, error);
      if (error) return IoError(dir + ": cannot remove a stale model: " + error.message());
    }
  }
  // points3D.txt last: its presence marks a finished model (see the sfm command's reuse check).
  RECONAR_RETURN_IF_ERROR(WriteColmapTextModel(*reconstruction, sparse));
  report.seconds_write = SecondsSince(start);
  if (reconstruction_out != nullptr) *reconstruction_out = std::move(*reconstruction);
  return report;
}

void WriteSfmReportFields(const SfmStageReport& sfm, JsonWriter* json) {
  const MapperReport& m = sfm.mapper;
  json->Key("images").Int(m.num_images);
  json->Key("registered").Int(m.num_registered);
  json->Key("points").Int(m.num_points);
  json->Key("mean_track_length").Double(m.mean_track_length);
  json->Key("mean_reprojection_error_px").Double(m.mean_reprojection_error_px);
  json->Key("mean_focal_ratio").Double(sfm.mean_focal_ratio);
  json->Key("rmse_focal_ratio").Double(sfm.rmse_focal_ratio);
  json->Key("focal_35mm_equivalent_mm").Double(sfm.focal_35mm_equivalent);
  json->Key("initial_pair").String(m.initial_pair);
  if (sfm.live_model == SfmStageReport::LiveModel::kContinued) json->Key("live_model").String("continued");
  if (sfm.live_model == SfmStageReport::LiveModel::kNotUsed) {
    json->Key("live_model").String("not used: " + sfm.live_model_reason);
  }
  json->Key("initial_pair_relaxations").Int(m.init_relaxations);
  json->Key("initial_pairs_scored").Int(m.init_pairs_scored);
  json->Key("initial_starts").Int(m.init_starts);
  json->Key("registered_from_neighbour").Int(m.num_registered_from_neighbour);
  json->Key("principal_point_refined").Bool(m.principal_point_refined);
  json->Key("distortion_refined").Bool(m.distortion_refined);
  json->Key("aspect_refined").Bool(m.aspect_refined);
  json->Key("tracks").Int(m.num_tracks);
  json->Key("conflicting_matches_left_out").Int(m.num_conflicting_matches);
  json->Key("seconds_mapping").Double(sfm.seconds_mapping);
  json->Key("seconds_bundle_adjustment").Double(m.seconds_ba);
  json->Key("local_bundle_adjustments").Int(m.num_local_ba);
  json->Key("global_bundle_adjustments").Int(m.num_global_ba);
  json->Key("failed_bundle_adjustments").Int(m.num_failed_ba);
  if (m.num_failed_ba > 0) json->Key("first_bundle_adjustment_failure").String(m.first_ba_failure);
  json->Key("models").BeginArray();
  for (size_t k = 0; k < m.models.size(); ++k) {
    json->BeginObject();
    json->Key("directory").String(k == 0 ? "sparse" : "sparse/model" + std::to_string(k + 1));
    json->Key("registered").Int(static_cast<long long>(m.models[k].images.size()));
    json->Key("points").Int(m.models[k].num_points);
    json->Key("initial_pair").String(m.models[k].initial_pair);
    if (!m.models[k].not_merged.empty()) json->Key("not_merged").String(m.models[k].not_merged);
    json->Key("images").BeginArray();
    for (const std::string& name : m.models[k].images) json->String(name);
    json->EndArray().EndObject();
  }
  json->EndArray();
  json->Key("merged").BeginArray();
  for (const MapperReport::Merge& merge : m.merges) {
    json->BeginObject().Key("initial_pair").String(merge.initial_pair).Key("images").Int(merge.num_images);
    json->Key("shared_points").Int(merge.num_shared_points).Key("inliers").Int(merge.num_inliers);
    json->Key("aligned_by").String(merge.aligned_by).EndObject();
  }
  json->EndArray();
  json->Key("provisional").BeginArray();
  for (const MapperReport::Provisional& p : m.provisional) {
    json->BeginObject().Key("image").String(p.name).Key("evidence").String(p.evidence);
    json->Key("inliers").Int(p.inliers).Key("kept").Bool(p.kept).EndObject();
  }
  json->EndArray();
  json->Key("unregistered").BeginArray();
  for (const MapperReport::Unregistered& u : m.unregistered) {
    json->BeginObject().Key("image").String(u.name).Key("reason").String(u.reason).EndObject();
  }
  json->EndArray();
  if (sfm.tags_used) {
    json->Key("tags").BeginObject();
    json->Key("metric").Bool(sfm.tags.metric);
    if (!sfm.tags.metric) json->Key("reason").String(sfm.tags.reason);
    json->Key("world_tag").Int(sfm.tags.world_tag).Key("tags_seen").Int(sfm.tags.tags_seen);
    json->Key("tags_registered").Int(static_cast<long long>(sfm.tags.tags.size()));
    json->Key("edge_mean_m").Double(sfm.tags.edge_mean_m).Key("edge_std_m").Double(sfm.tags.edge_std_m);
    json->EndObject();
  }
}

}  // namespace reconar
