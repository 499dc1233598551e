#include "core/pipeline/dense_stage.h"

#include <algorithm>
#include <cstdio>
#include <chrono>
#include <map>
#include <memory>

#include "core/base/atomic_file.h"
#include "core/base/json_writer.h"
#include "core/base/keep_masked.h"
#include "core/base/memory_usage.h"
#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/io/image_io.h"
#include "core/mesh/mesh.h"
#include "core/mesh/mesh_io.h"
#include "core/mvs/dense_memory.h"
#include "core/mvs/merge_points.h"
#include "core/mvs/undistort.h"
#include "core/pipeline/project_lock.h"
#include "core/pipeline/stage_record.h"
#include "core/sfm/model_io.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

// Times one phase segment and folds its peak RSS into the phase; a phase may have many segments
// (undistortion and PMVS alternate over the clusters).
class PhaseTimer {
 public:
  explicit PhaseTimer(DensePhase* phase) : phase_(phase), start_(Clock::now()) { ResetPeakResidentBytes(); }
  ~PhaseTimer() {
    phase_->seconds += std::chrono::duration<double>(Clock::now() - start_).count();
    phase_->peak_rss_bytes = std::max(phase_->peak_rss_bytes, PeakResidentBytes());
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  DensePhase* phase_;
  Clock::time_point start_;
};

void AddReports(const PatchMatchReport& part, PatchMatchReport* sum) {
  sum->views += part.views;
  sum->depth_pixels += part.depth_pixels;
  sum->consistent_pixels += part.consistent_pixels;
  sum->map_bytes = std::max(sum->map_bytes, part.map_bytes);
  sum->fused_points += part.fused_points;
  sum->seconds_selection += part.seconds_selection;
  sum->seconds_propagation += part.seconds_propagation;
  sum->seconds_consistency += part.seconds_consistency;
  sum->seconds_fusion += part.seconds_fusion;
}

// The model's points that some image of `cluster` (sorted ids) observed: what PatchMatch takes its
// depth ranges and source views from.
std::vector<Eigen::Vector3d> ClusterSparsePoints(const Reconstruction& model, const std::vector<int>& cluster) {
  std::vector<Eigen::Vector3d> points;
  for (const SfmPoint& point : model.points) {
    if (point.deleted) continue;
    for (const TrackElement& element : point.track) {
      if (std::binary_search(cluster.begin(), cluster.end(), element.image_id)) {
        points.push_back(point.position);
        break;
      }
    }
  }
  return points;
}

void AddReports(const PatchMvsReport& part, PatchMvsReport* sum) {
  sum->features += part.features;
  sum->initial_patches += part.initial_patches;
  sum->expanded_patches += part.expanded_patches;
  sum->final_patches += part.final_patches;
  sum->seconds_features += part.seconds_features;
  sum->seconds_matching += part.seconds_matching;
  sum->seconds_expansion += part.seconds_expansion;
  sum->seconds_filtering += part.seconds_filtering;
}

// Before cluster `current` is loaded: drops the cached views no cluster from `current` on needs
// (`clusters` lists only the clusters that run), and of the views a later cluster needs keeps
// those needed soonest while their bytes fit `spare_bytes`, so that a photo shared by clusters
// is decoded once when the memory budget allows.
void KeepViewsForLaterClusters(const std::vector<std::vector<int>>& clusters, size_t current, size_t spare_bytes,
                               std::map<int, std::unique_ptr<DenseView>>* cache) {
  std::vector<std::pair<size_t, int>> later;  // (the next cluster that needs it, view id)
  for (auto it = cache->begin(); it != cache->end();) {
    size_t next = clusters.size();
    for (size_t k = current; k < clusters.size() && next == clusters.size(); ++k) {
      if (std::binary_search(clusters[k].begin(), clusters[k].end(), it->first)) next = k;
    }
    if (next == clusters.size()) {
      it = cache->erase(it);
      continue;
    }
    if (next > current) later.emplace_back(next, it->first);
    ++it;
  }
  std::sort(later.begin(), later.end());
  size_t kept_bytes = 0;
  for (const auto& [next, id] : later) {
    const DenseView& view = *cache->at(id);
    kept_bytes += view.rgb.size_bytes() + view.gray.size_bytes();
    if (kept_bytes > spare_bytes) cache->erase(id);
  }
}

// Decodes and undistorts the views of `cluster` that `cache` lacks.
Status LoadClusterViews(const std::vector<int>& cluster, const Reconstruction& model,
                        const std::vector<std::string>& paths, int level, ThreadPool* pool, Progress* progress,
                        std::map<int, std::unique_ptr<DenseView>>* cache, size_t* loaded) {
  std::vector<int> missing;
  for (int id : cluster) {
    if (cache->count(id) == 0) missing.push_back(id);
  }
  std::vector<std::unique_ptr<DenseView>> views(missing.size());
  std::vector<Status> errors(missing.size());
  pool->ParallelFor(0, missing.size(), [&](size_t k, int) {
    const int id = missing[k];
    const SfmImage& image = model.images[static_cast<size_t>(id)];
    const std::string& path = paths[static_cast<size_t>(id)];
    auto decoded = ReadImage(path);
    if (!decoded.ok()) {
      errors[k] = decoded.status();
    } else {
      auto view = UndistortView(decoded->rgb, model.cameras[static_cast<size_t>(image.camera_id)], image.cam_from_world, level);
      if (!view.ok()) {
        errors[k] = view.status().WithContext(path);
      } else {
        view->name = image.name;
        view->image_id = id;
        views[k] = std::make_unique<DenseView>(std::move(*view));
      }
    }
    if (progress != nullptr) progress->Advance();
  });
  for (const Status& status : errors) RECONAR_RETURN_IF_ERROR(status);
  for (size_t k = 0; k < missing.size(); ++k) (*cache)[missing[k]] = std::move(views[k]);
  *loaded += missing.size();
  return Status::Ok();
}

Mesh ToPointCloud(const OrientedPoints& points) {
  Mesh mesh;
  mesh.positions = points.positions;
  mesh.normals = points.normals;
  mesh.colors.reserve(points.size());
  for (const std::array<uint8_t, 3>& c : points.colors) mesh.colors.push_back({c[0], c[1], c[2], 255});
  return mesh;
}

void PhaseJson(const char* name, const DensePhase& phase, JsonWriter* json) {
  json->Key(name).BeginObject();
  json->Key("seconds").Double(phase.seconds);
  json->Key("peak_rss_mib").Double(Mib(phase.peak_rss_bytes));
  json->EndObject();
}

}  // namespace

const char* DenseMethodName(DenseMethod method) { return method == DenseMethod::kPatchMatch ? "patchmatch" : "pmvs"; }

Result<DenseMethod> ParseDenseMethod(const std::string& name) {
  if (name == "pmvs") return DenseMethod::kPmvs;
  if (name == "patchmatch") return DenseMethod::kPatchMatch;
  return InvalidArgument("dense method must be pmvs or patchmatch, got '" + name + "'");
}

Status DenseStageOptions::Check() const {
  if (level < -1 || level > kMaxDenseLevel) {
    return InvalidArgument("dense: level must be -1 (auto), 0, 1 or 2, got " + std::to_string(level));
  }
  if (memory_budget_bytes == 0) return InvalidArgument("dense: the memory budget must be positive");
  if (max_image_size < 0) return InvalidArgument("dense: max_image_size must be 0 (none) or positive");
  RECONAR_RETURN_IF_ERROR(clustering.Check());
  RECONAR_RETURN_IF_ERROR(outliers.Check());
  RECONAR_RETURN_IF_ERROR(patchmatch.Check());
  return mvs.Check();
}

std::string DenseStageSettings(const DenseStageOptions& options) {
  std::string settings =
      StageRecord::Settings({{"level", options.level},
                             {"max_image_size", options.max_image_size},
                             {"max_cluster_size", options.clustering.max_cluster_size},
                             {"budget_mib", Mib(options.memory_budget_bytes)},
                             {"remove_outliers", options.remove_outliers ? 1.0 : 0.0}});
  // PMVS records no method, so that the projects made before the choice existed stay finished.
  if (options.method != DenseMethod::kPmvs) {
    settings += " " + StageRecord::Settings({{"method", static_cast<double>(options.method)},
                                             {"fill_min_support", options.patchmatch.fill_min_support}});
  }
  return settings;
}

Result<DenseStageReport> RunDenseStage(const Project& project, const DenseStageOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_ASSIGN_OR_RETURN(const ProjectLock lock, LockProject(project));
  DenseStageReport report;
  report.method = options.method;
  report.peak_rss_resettable = ResetPeakResidentBytes();

  // Load: the sparse model and the photo of every registered image.
  Reconstruction model;
  std::vector<std::string> paths;
  {
    PhaseTimer timer(&report.load);
    RECONAR_ASSIGN_OR_RETURN(model, ReadColmapTextModel(project.SparseDir()));
    RECONAR_ASSIGN_OR_RETURN(const auto path_of, project.PhotoPathsByName());
    paths.resize(model.images.size());
    for (size_t i = 0; i < model.images.size(); ++i) {
      const SfmImage& image = model.images[i];
      if (!image.registered) continue;
      const auto it = path_of.find(image.name);
      if (it == path_of.end()) {
        return FileError(StatusCode::kNotFound, project.ImageListPath(),
                         "image " + image.name + " of " + project.SparseDir() + "/images.txt is not listed");
      }
      paths[i] = it->second;
    }
    report.images = model.NumRegisteredImages();
  }
  if (report.images == 0) return FailedPrecondition(project.SparseDir() + ": the model has no registered image");

  // Level and cluster size from the memory budget.
  const int num_threads = ThreadPool::ResolveThreadCount(options.num_threads);
  DenseMemoryInput memory;
  for (const SfmImage& image : model.images) {
    if (!image.registered) continue;
    const SfmCamera& camera = model.cameras[static_cast<size_t>(image.camera_id)];
    memory.image_sizes.emplace_back(camera.width, camera.height);
  }
  memory.max_cluster_size = options.clustering.max_cluster_size;
  const bool patchmatch = options.method == DenseMethod::kPatchMatch;
  memory.work_bytes_per_pixel =
      patchmatch ? static_cast<double>(kPatchMatchBytesPerPixel) : PmvsWorkBytesPerPixel(options.mvs.cell_size);
  memory.num_threads = num_threads;
  memory.baseline_bytes = CurrentMemoryUsage().resident_bytes;
  memory.max_image_size = options.max_image_size;
  // The fewest views a cluster needs for the method to make a point.
  const int min_views = patchmatch ? options.patchmatch.fusion_min_views + 1 : options.mvs.min_visible_views;
  const int min_cluster = std::max(options.clustering.min_views_per_point, min_views);
  RECONAR_ASSIGN_OR_RETURN(DenseLevelChoice choice,
                           ChooseDenseLevel(memory, options.level, options.memory_budget_bytes, min_cluster));
  // PatchMatch makes a depth map of every view in each cluster the view is in, so overlapping
  // clusters repeat its work: its clusters grow to what the budget holds at the chosen level.
  if (patchmatch) choice = GrowClusterToBudget(memory, choice, options.memory_budget_bytes);
  report.level = choice.level;
  report.level_auto = options.level < 0;
  report.finest_level_within_size = choice.finest_level_within_size;
  report.estimated_bytes = choice.estimated_bytes;
  report.max_cluster_size = std::max(choice.max_cluster_size, options.clustering.min_views_per_point);
  report.cluster_size_reduced = choice.reduced_cluster_size;

  ViewClustering clustering;
  {
    PhaseTimer timer(&report.clustering);
    ViewClusteringOptions clustering_options = options.clustering;
    clustering_options.max_cluster_size = report.max_cluster_size;
    RECONAR_ASSIGN_OR_RETURN(clustering, ClusterViews(model, clustering_options));
  }
  report.kept_images = static_cast<int>(clustering.kept_images.size());
  report.removed_images = static_cast<int>(clustering.removed_images.size());
  report.clusters = static_cast<int>(clustering.clusters.size());
  report.clusters_from_cameras = clustering.from_camera_geometry;
  report.sparse_points_covered = clustering.covered_fraction;

  // Per cluster: undistort its views (reusing the previous cluster's), run the multi-view stereo,
  // keep the points.
  PatchMvsOptions mvs_options = options.mvs;
  if (mvs_options.num_threads == 0) mvs_options.num_threads = num_threads;
  mvs_options.show_progress = options.show_progress;
  PatchMatchOptions patchmatch_options = options.patchmatch;
  if (patchmatch_options.num_threads == 0) patchmatch_options.num_threads = num_threads;
  patchmatch_options.show_progress = options.show_progress;
  ThreadPool pool(num_threads);
  std::map<int, std::unique_ptr<DenseView>> cache;
  // Views kept between clusters take at most half of what the budget leaves beside one cluster's
  // estimate (the merged points grow meanwhile).
  const size_t spare_bytes =
      options.memory_budget_bytes > report.estimated_bytes ? (options.memory_budget_bytes - report.estimated_bytes) / 2 : 0;
  std::vector<std::vector<int>> running_clusters;  // sorted ids, for KeepViewsForLaterClusters
  for (const std::vector<int>& cluster : clustering.clusters) {
    if (static_cast<int>(cluster.size()) < min_views) continue;
    running_clusters.push_back(cluster);
    report.views_in_clusters += cluster.size();
    std::sort(running_clusters.back().begin(), running_clusters.back().end());
  }
  std::vector<MergeInput> parts;
  size_t running = 0;
  for (size_t c = 0; c < clustering.clusters.size(); ++c) {
    const std::vector<int>& cluster = clustering.clusters[c];
    if (static_cast<int>(cluster.size()) < min_views) {
      ++report.clusters_without_points;
      continue;
    }
    KeepViewsForLaterClusters(running_clusters, running++, spare_bytes, &cache);
    // Progress: one line per phase of each cluster, "dense: cluster 2/4: undistort 5 views: ...".
    const std::string cluster_label =
        "dense: cluster " + std::to_string(c + 1) + "/" + std::to_string(clustering.clusters.size()) + ": ";
    {
      PhaseTimer timer(&report.undistort);
      size_t missing = 0;
      for (int id : cluster) missing += cache.count(id) == 0 ? 1 : 0;
      std::unique_ptr<Progress> progress;
      if (options.show_progress && missing > 0) {
        progress = std::make_unique<Progress>(
            cluster_label + "undistort " + std::to_string(missing) + " of " + std::to_string(cluster.size()) + " views",
            missing);
      }
      RECONAR_RETURN_IF_ERROR(LoadClusterViews(cluster, model, paths, report.level, &pool, progress.get(), &cache,
                                               &report.views_undistorted));
      if (progress) progress->Finish();
    }
    std::vector<const DenseView*> views;
    for (int id : cluster) views.push_back(cache.at(id).get());
    PatchMvsReport pmvs_report;
    PatchMatchReport patchmatch_report;
    Result<OrientedPoints> points = OrientedPoints();
    {
      PhaseTimer timer(&report.mvs);
      if (patchmatch) {
        patchmatch_options.progress_label = cluster_label + "PatchMatch";
        points = RunPatchMatchMvs(views, ClusterSparsePoints(model, cluster), patchmatch_options, &patchmatch_report);
      } else {
        mvs_options.progress_label = cluster_label + "patch MVS";
        points = RunPatchMvs(views, mvs_options, &pmvs_report);
      }
    }
    if (!points.ok()) {
      if (points.status().code() != StatusCode::kFailedPrecondition) {
        return points.status().WithContext("dense: cluster " + std::to_string(c + 1) + " of " +
                                           std::to_string(clustering.clusters.size()));
      }
      ++report.clusters_without_points;
      continue;
    }
    AddReports(pmvs_report, &report.pmvs);
    AddReports(patchmatch_report, &report.patchmatch);
    PhaseTimer timer(&report.merge);
    MergeInput part;
    part.footprints.reserve(points->size());
    for (const Eigen::Vector3f& position : points->positions) part.footprints.push_back(PixelFootprint(views, position));
    part.points = std::move(*points);
    report.points_before_merge += part.points.size();
    // PatchMatch fuses a point per agreeing pixel group, several per pixel footprint: thinned here,
    // each cluster's points hold a third of the memory until the merge across clusters (fountain-P11
    // at level 0 in 3 clusters under 1 GiB: the merge's peak was 1071 MiB with all of them whole).
    if (patchmatch) {
      std::vector<MergeInput> single;
      single.push_back(std::move(part));
      part = MergeInput();
      part.points = MergeOrientedPoints(single, nullptr, &part.footprints);
    }
    parts.push_back(std::move(part));
  }
  cache.clear();
  if (report.points_before_merge == 0) {
    return FailedPrecondition("dense: no cluster of " + project.SparseDir() +
                              " yielded a point (too few views per cluster, or images without texture)");
  }

  OrientedPoints merged;
  {
    PhaseTimer timer(&report.merge);
    // A single part that was thinned already would come back unchanged (same order, same tests).
    merged = patchmatch && parts.size() == 1 ? std::move(parts[0].points) : MergeOrientedPoints(parts, nullptr);
    parts.clear();
  }
  if (options.remove_outliers) {
    PhaseTimer timer(&report.outlier_filter);
    OutlierFilterOptions outlier_options = options.outliers;
    if (outlier_options.num_threads == 0) outlier_options.num_threads = num_threads;
    RECONAR_ASSIGN_OR_RETURN(const std::vector<uint8_t> keep,
                             FindInlierPoints(merged.positions, outlier_options, &report.outliers));
    KeepMasked(keep, &merged.positions);
    KeepMasked(keep, &merged.normals);
    KeepMasked(keep, &merged.colors);
    KeepMasked(keep, &merged.scores);
    if (options.show_progress) {
      std::fprintf(stderr, "dense: %zu isolated points and %zu in %d small pieces removed, %zu kept\n",
                   report.outliers.isolated_removed, report.outliers.small_piece_removed,
                   report.outliers.pieces - report.outliers.pieces_kept, merged.size());
    }
  }
  report.points = merged.size();

  const std::string dense_dir = project.root() + "/dense";
  report.points_path = dense_dir + "/points.ply";
  report.report_path = dense_dir + "/report.json";
  {
    PhaseTimer timer(&report.write);
    RECONAR_RETURN_IF_ERROR(CreateDirectories(dense_dir));
    RECONAR_RETURN_IF_ERROR(WritePly(report.points_path, ToPointCloud(merged)));
  }
  // report.json last: its presence marks a finished dense stage. Its own write is not timed.
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(report.report_path, DenseReportJson(report)));
  return report;
}

std::string DenseReportJson(const DenseStageReport& report) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("method").String(DenseMethodName(report.method));
  json.Key("level").Int(report.level);
  json.Key("level_chosen_from_memory_budget").Bool(report.level_auto);
  json.Key("finest_level_within_max_image_size").Int(report.finest_level_within_size);
  json.Key("estimated_cluster_mib").Double(Mib(report.estimated_bytes));
  json.Key("max_cluster_size").Int(report.max_cluster_size);
  json.Key("cluster_size_reduced_for_budget").Bool(report.cluster_size_reduced);
  json.Key("images").Int(report.images);
  json.Key("kept_images").Int(report.kept_images);
  json.Key("removed_images").Int(report.removed_images);
  json.Key("clusters").Int(report.clusters);
  json.Key("clusters_without_points").Int(report.clusters_without_points);
  json.Key("clusters_from_camera_geometry").Bool(report.clusters_from_cameras);
  json.Key("sparse_points_covered").Double(report.sparse_points_covered);
  json.Key("views_undistorted").Int(static_cast<long long>(report.views_undistorted));
  json.Key("views_in_clusters").Int(static_cast<long long>(report.views_in_clusters));
  json.Key("points_before_merge").Int(static_cast<long long>(report.points_before_merge));
  json.Key("outliers").BeginObject();
  json.Key("isolated_removed").Int(static_cast<long long>(report.outliers.isolated_removed));
  json.Key("small_piece_removed").Int(static_cast<long long>(report.outliers.small_piece_removed));
  json.Key("pieces").Int(report.outliers.pieces).Key("pieces_kept").Int(report.outliers.pieces_kept);
  json.Key("median_spacing").Double(report.outliers.median_spacing);
  json.EndObject();
  json.Key("points").Int(static_cast<long long>(report.points));
  json.Key("pmvs").BeginObject();
  json.Key("features").Int(static_cast<long long>(report.pmvs.features));
  json.Key("initial_patches").Int(static_cast<long long>(report.pmvs.initial_patches));
  json.Key("expanded_patches").Int(static_cast<long long>(report.pmvs.expanded_patches));
  json.Key("final_patches").Int(static_cast<long long>(report.pmvs.final_patches));
  json.Key("seconds_features").Double(report.pmvs.seconds_features);
  json.Key("seconds_matching").Double(report.pmvs.seconds_matching);
  json.Key("seconds_expansion").Double(report.pmvs.seconds_expansion);
  json.Key("seconds_filtering").Double(report.pmvs.seconds_filtering);
  json.EndObject();
  json.Key("patchmatch").BeginObject();
  json.Key("views").Int(static_cast<long long>(report.patchmatch.views));
  json.Key("depth_pixels").Int(static_cast<long long>(report.patchmatch.depth_pixels));
  json.Key("consistent_pixels").Int(static_cast<long long>(report.patchmatch.consistent_pixels));
  json.Key("map_mib").Double(Mib(report.patchmatch.map_bytes));
  json.Key("fused_points").Int(static_cast<long long>(report.patchmatch.fused_points));
  json.Key("seconds_selection").Double(report.patchmatch.seconds_selection);
  json.Key("seconds_propagation").Double(report.patchmatch.seconds_propagation);
  json.Key("seconds_consistency").Double(report.patchmatch.seconds_consistency);
  json.Key("seconds_fusion").Double(report.patchmatch.seconds_fusion);
  json.EndObject();
  json.Key("peak_rss_resettable").Bool(report.peak_rss_resettable);
  json.Key("phases").BeginObject();
  PhaseJson("load", report.load, &json);
  PhaseJson("clustering", report.clustering, &json);
  PhaseJson("undistort", report.undistort, &json);
  PhaseJson("mvs", report.mvs, &json);
  PhaseJson("merge", report.merge, &json);
  PhaseJson("outlier_filter", report.outlier_filter, &json);
  PhaseJson("write", report.write, &json);
  json.EndObject();
  json.EndObject();
  return json.str() + "\n";
}

}  // namespace reconar
