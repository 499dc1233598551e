#include "core/pipeline/live_reconstruction.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "core/base/atomic_file.h"
#include "core/base/json_writer.h"
#include "core/base/median.h"
#include "core/features/sift/sift_io.h"
#include "core/pipeline/reconstruct.h"
#include "core/pipeline/sfm_stage.h"
#include "core/pipeline/stage_record.h"
#include "core/sfm/model_io.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kCoverageSectors = 12;

double SecondsBetween(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

// The value under which `fraction` of the sorted values lie (nearest rank).
double Percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t rank = static_cast<size_t>(std::ceil(fraction * static_cast<double>(values.size())));
  return values[std::min(values.size(), std::max<size_t>(rank, 1)) - 1];
}

}  // namespace

std::vector<bool> ViewCoverage(const Reconstruction& model, int sectors) {
  std::vector<bool> covered(static_cast<size_t>(std::max(sectors, 0)), false);
  std::vector<double> xs, ys, zs;
  for (const SfmPoint& point : model.points) {
    if (point.deleted) continue;
    xs.push_back(point.position.x());
    ys.push_back(point.position.y());
    zs.push_back(point.position.z());
  }
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> centres;
  for (const SfmImage& image : model.images) {
    if (!image.registered) continue;
    up += image.cam_from_world.rotation.transpose() * Eigen::Vector3d(0.0, -1.0, 0.0);
    centres.push_back(image.Center());
  }
  if (sectors <= 0 || xs.empty() || centres.size() < 2 || up.norm() < 1e-9) return covered;
  up.normalize();
  const Eigen::Vector3d object(Median(xs), Median(ys), Median(zs));
  // Azimuths in the plane across `up`, from the first camera's direction.
  Eigen::Vector3d axis_x = centres[0] - object;
  axis_x -= axis_x.dot(up) * up;
  if (axis_x.norm() < 1e-12) axis_x = up.unitOrthogonal();
  axis_x.normalize();
  const Eigen::Vector3d axis_y = up.cross(axis_x);
  constexpr double kTwoPi = 6.283185307179586;
  for (const Eigen::Vector3d& centre : centres) {
    const Eigen::Vector3d d = centre - object;
    // Sector 0 centred on the first camera, so that no camera sits on a sector's edge by design.
    double azimuth = std::atan2(d.dot(axis_y), d.dot(axis_x)) + 0.5 * kTwoPi / sectors;
    if (azimuth < 0.0) azimuth += kTwoPi;
    if (azimuth >= kTwoPi) azimuth -= kTwoPi;
    const int sector = std::min(sectors - 1, static_cast<int>(azimuth / kTwoPi * sectors));
    covered[static_cast<size_t>(sector)] = true;
  }
  return covered;
}

LiveReconstructionOptions::LiveReconstructionOptions() {
  const ReconstructOptions reconstruct;
  features = reconstruct.features;
  matching = reconstruct.matching;
  mapper = reconstruct.sfm.mapper;
}

LiveReconstruction::LiveReconstruction(const Project& project, const LiveReconstructionOptions& options)
    : project_(project),
      options_(options),
      worker_threads_(options.worker_threads > 0 ? options.worker_threads
                                                 : std::max(1, ThreadPool::ResolveThreadCount(0) - 1)),
      start_(Clock::now()),
      extractor_(options.features) {
  growth_.final_adjustment = false;
  worker_ = std::thread([this] { Work(); });
}

LiveReconstruction::~LiveReconstruction() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void LiveReconstruction::AddKeyframe(const std::string& path) {
  LiveKeyframe keyframe;
  keyframe.path = path;
  keyframe.taken_seconds = SecondsBetween(start_, Clock::now());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queued_.push_back(std::move(keyframe));
  }
  wake_.notify_all();
}

std::vector<int> LiveReconstruction::TakeNewlyRegistered() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<int> taken;
  taken.swap(newly_registered_);
  return taken;
}

int LiveReconstruction::NumKeyframes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(queued_.size());
}

std::vector<bool> LiveReconstruction::Coverage() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return coverage_;
}

int LiveReconstruction::NumProcessed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(done_);
}

LiveMap LiveReconstruction::LatestMap() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return maps_.empty() ? LiveMap() : maps_.back();
}

int LiveReconstruction::MapVersion() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return maps_.empty() ? 0 : maps_.back().version;
}

LiveMap LiveReconstruction::MapAsOf(int keyframes) {
  std::unique_lock<std::mutex> lock(mutex_);
  const size_t wanted = std::min(static_cast<size_t>(std::max(keyframes, 0)), queued_.size());
  wake_.wait(lock, [&] { return done_ >= wanted || stopping_ || worker_stopped_; });
  for (auto map = maps_.rbegin(); map != maps_.rend(); ++map) {
    if (map->keyframes <= keyframes) return *map;
  }
  return LiveMap();
}

int LiveReconstruction::NumRegistered() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return registered_now_;
}

void LiveReconstruction::Work() {
  while (true) {
    size_t index = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || finishing_ || done_ < queued_.size(); });
      if (stopping_ || done_ == queued_.size()) return;  // finishing with nothing left
      index = done_;
    }
    const Status status = ProcessKeyframe(index);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++done_;
      if (!status.ok()) {
        worker_error_ = status;
        worker_stopped_ = true;
      }
    }
    wake_.notify_all();  // MapAsOf waits for done_
    if (!status.ok()) return;
  }
}

Status LiveReconstruction::ProcessKeyframe(size_t index) {
  std::string path;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    path = queued_[index].path;
  }
  auto start = Clock::now();
  SiftFeatures features;
  Result<ImageFeatureSummary> summary = extractor_.Extract(path, &features);
  if (!summary.ok()) {
    std::lock_guard<std::mutex> lock(mutex_);
    queued_[index].failure = summary.status().message();
    return Status::Ok();
  }
  RECONAR_RETURN_IF_ERROR(CreateDirectories(project_.FeaturesDir()));
  RECONAR_RETURN_IF_ERROR(WriteFeatureFile(project_.FeaturePath(summary->image.name),
                                           FeatureFile{summary->image.width, summary->image.height, features}));
  if (!match_pool_) {
    match_pool_ = std::make_unique<ThreadPool>(worker_threads_);
    MatchOptions one_thread = options_.matching.match;
    one_thread.num_threads = 1;
    matchers_.resize(static_cast<size_t>(match_pool_->num_threads()));
    for (std::unique_ptr<Matcher>& matcher : matchers_) {
      RECONAR_ASSIGN_OR_RETURN(matcher, Matcher::Create(one_thread));
    }
    PairSelectionOptions pairs_on_one_thread = options_.matching.pairs;
    pairs_on_one_thread.vocabulary.num_threads = 1;
    RECONAR_ASSIGN_OR_RETURN(pair_selector_, PairSelector::Create(pairs_on_one_thread));
  }
  const int image = static_cast<int>(images_.size());
  images_.push_back(summary->image);
  keyframe_of_image_.push_back(index);
  mapper_images_.push_back(ToMapperImage(summary->image, features.keypoints));
  features_.push_back(std::move(features));
  for (std::unique_ptr<Matcher>& matcher : matchers_) {
    RECONAR_RETURN_IF_ERROR(matcher->AddImage(image, features_.back().descriptors.data(),
                                              static_cast<int>(features_.back().keypoints.size())));
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queued_[index].num_features = summary->num_features;
  }
  const auto matching_start = Clock::now();
  seconds_features_ += SecondsBetween(start, matching_start);

  // Against the earlier keyframes the pair rule chooses, as the match stage matches them (the
  // earlier image queries).
  RECONAR_ASSIGN_OR_RETURN(
      const std::vector<int> partners,
      pair_selector_->Add(features_.back().descriptors.data(), static_cast<int>(features_.back().keypoints.size())));
  pairs_matched_ += static_cast<int>(partners.size());
  const ProjectImage& mine = images_.back();
  // In the partners' order whatever the threads, so that the model does not depend on their count.
  std::vector<std::optional<VerifiedPair>> verified_pairs(partners.size());
  std::vector<Status> errors(partners.size());
  match_pool_->ParallelFor(0, partners.size(), [&](size_t k, int thread) {
    const ProjectImage& theirs = images_[static_cast<size_t>(partners[k])];
    Result<std::vector<FeatureMatch>> putative = matchers_[static_cast<size_t>(thread)]->Match(partners[k], image);
    if (!putative.ok()) {
      errors[k] = putative.status().WithContext(theirs.name + " / " + mine.name);
      return;
    }
    Result<VerifiedPair> verified =
        VerifyMatches(features_[static_cast<size_t>(partners[k])], theirs.width, theirs.height, features_.back(),
                      mine.width, mine.height, *putative, options_.matching.two_view);
    if (verified.ok()) {
      verified_pairs[k] = std::move(verified).value();
    } else {
      errors[k] = verified.status().WithContext(theirs.name + " / " + mine.name);
    }
  });
  for (size_t k = 0; k < partners.size(); ++k) {
    RECONAR_RETURN_IF_ERROR(errors[k]);
    const int other = partners[k];
    std::optional<VerifiedPair>& verified = verified_pairs[k];
    if (verified->geometry.config == TwoViewGeometry::Config::kTooFewInliers) continue;
    verified->image_a = other;
    verified->image_b = image;
    mapper_pairs_.push_back(ToMapperPair(other, image, verified->inlier_matches,
                                         verified->geometry.config == TwoViewGeometry::Config::kPlanarOrRotation));
    pairs_.push_back(std::move(verified).value());
  }
  const auto mapping_start = Clock::now();
  seconds_matching_ += SecondsBetween(matching_start, mapping_start);

  // The new keyframe gets the local adjustment; the whole model a global one at growth milestones.
  const int registered_at_last_global = growth_.registered_at_last_global;
  Result<Reconstruction> grown =
      has_model_ ? ContinueIncrementalMapper(mapper_images_, mapper_pairs_, MapperOnOneThread(), model_, &growth_)
                 : RunIncrementalMapper(mapper_images_, mapper_pairs_, MapperOnOneThread(), nullptr);
  bool started_afresh = !has_model_;
  if (has_model_ && grown.ok() && 2 * grown->NumRegisteredImages() < static_cast<int>(images_.size())) {
    // A model that holds under half the keyframes may have started from a poor pair (the first two
    // keyframes of a walk forward): the mapper from scratch chooses its pair among all of them.
    Result<Reconstruction> fresh = RunIncrementalMapper(mapper_images_, mapper_pairs_, MapperOnOneThread(), nullptr);
    if (fresh.ok() && fresh->NumRegisteredImages() > grown->NumRegisteredImages()) {
      grown = std::move(fresh);
      started_afresh = true;
    }
  }
  seconds_mapping_ += SecondsBetween(mapping_start, Clock::now());
  if (!grown.ok()) {
    // No initial pair among the keyframes so far: the next keyframe may give one.
    if (grown.status().code() == StatusCode::kFailedPrecondition) return Status::Ok();
    return grown.status();
  }
  // A model from scratch has had its global adjustments: the milestones count from it.
  if (started_afresh) growth_.registered_at_last_global = grown->NumRegisteredImages();
  model_ = std::move(grown).value();
  has_model_ = true;
  model_final_ = false;
  PublishModel();
  const bool map_due = started_afresh || growth_.registered_at_last_global != registered_at_last_global ||
                       (options_.map_every_keyframes > 0 &&
                        model_.NumRegisteredImages() - registered_at_last_map_ >= options_.map_every_keyframes);
  if (options_.publish_map && map_due) PublishMap();
  return Status::Ok();
}

void LiveReconstruction::PublishMap() {
  const auto start = Clock::now();
  const ImageDescriptorLoader load = [this](const SfmImage& image) -> Result<std::vector<uint8_t>> {
    for (size_t i = 0; i < images_.size(); ++i) {
      if (images_[i].name == image.name) return features_[i].descriptors;
    }
    return NotFound("live model: no features of " + image.name);
  };
  MapBuildOptions map_options = options_.map;
  map_options.num_threads = 1;
  Result<LocalizationMap> map = BuildLocalizationMap(model_, load, "arbitrary", false, map_options);
  if (!map.ok()) return;  // a model without points yet: the capture keeps the last map
  LiveMap published;
  published.map = std::make_shared<const LocalizationMap>(std::move(map).value());
  Result<Localizer> localizer = Localizer::Create(published.map.get(), options_.localizer);
  seconds_maps_ += SecondsBetween(start, Clock::now());
  if (!localizer.ok()) return;
  published.localizer = std::make_shared<const Localizer>(std::move(localizer).value());
  published.intrinsics = model_.cameras.front().Intrinsics();
  published.version = ++maps_published_;
  registered_at_last_map_ = model_.NumRegisteredImages();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    published.keyframes = static_cast<int>(done_) + 1;
    maps_.push_back(std::move(published));
    if (maps_.size() > kMapsKept) maps_.pop_front();
  }
  wake_.notify_all();
}

MapperOptions LiveReconstruction::MapperOnOneThread() const {
  MapperOptions mapper = options_.mapper;
  mapper.num_threads = 1;
  return mapper;
}

void LiveReconstruction::PublishModel() {
  const double now = SecondsBetween(start_, Clock::now());
  std::vector<bool> coverage = ViewCoverage(model_, kCoverageSectors);
  std::lock_guard<std::mutex> lock(mutex_);
  registered_now_ = model_.NumRegisteredImages();
  coverage_ = std::move(coverage);
  for (size_t i = 0; i < model_.images.size(); ++i) {
    LiveKeyframe& keyframe = queued_[keyframe_of_image_[i]];
    if (model_.images[i].registered && keyframe.registered_seconds < 0.0) {
      keyframe.registered_seconds = now;
      newly_registered_.push_back(static_cast<int>(keyframe_of_image_[i]));
    }
  }
}

Status LiveReconstruction::AdjustFinally() {
  if (!has_model_ || model_final_) return Status::Ok();
  const auto start = Clock::now();
  Result<Reconstruction> adjusted =
      ContinueIncrementalMapper(mapper_images_, mapper_pairs_, MapperOnOneThread(), model_);
  seconds_final_adjustment_ += SecondsBetween(start, Clock::now());
  if (!adjusted.ok()) return adjusted.status().WithContext("the live model's final adjustment");
  model_ = std::move(adjusted).value();
  model_final_ = true;
  PublishModel();
  return Status::Ok();
}

Result<LiveReconstructionReport> LiveReconstruction::Finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    finishing_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
  LiveReconstructionReport report;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!worker_error_.ok()) return worker_error_;
  }
  RECONAR_RETURN_IF_ERROR(AdjustFinally());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    report.keyframes = queued_;
  }
  report.registered = has_model_ ? model_.NumRegisteredImages() : 0;
  report.points = has_model_ ? model_.NumPoints() : 0;
  report.seconds_features = seconds_features_;
  report.seconds_matching = seconds_matching_;
  report.seconds_mapping = seconds_mapping_;
  report.seconds_final_adjustment = seconds_final_adjustment_;
  report.seconds_vocabulary = pair_selector_ ? pair_selector_->seconds_training() : 0.0;
  report.pairs_matched = pairs_matched_;
  report.maps_published = maps_published_;
  report.seconds_maps = seconds_maps_;
  std::vector<double> latencies;
  for (const LiveKeyframe& keyframe : report.keyframes) {
    if (keyframe.registered_seconds >= 0.0) latencies.push_back(keyframe.registered_seconds - keyframe.taken_seconds);
  }
  report.median_latency_seconds = Median(latencies);
  report.p95_latency_seconds = Percentile(latencies, 0.95);
  if (images_.empty()) return report;

  // What `reconstruct` reuses: the features and matches under its stage records.
  RECONAR_RETURN_IF_ERROR(project_.WriteImageList(images_));
  // In the match stage's order, so that the file is the one it would write.
  std::sort(pairs_.begin(), pairs_.end(), [](const VerifiedPair& a, const VerifiedPair& b) {
    return std::make_pair(a.image_a, a.image_b) < std::make_pair(b.image_a, b.image_b);
  });
  RECONAR_RETURN_IF_ERROR(WriteMatchesFile(project_, images_, pairs_));
  StageRecord record(project_);
  RECONAR_RETURN_IF_ERROR(record.Record("features", FeatureStageSettings(options_.features)));
  // The matches count as the match stage's only when it would not extract a keyframe again
  // (match_stage.h): otherwise `reconstruct` matches anew, as it would the same photos.
  std::vector<int> partners(images_.size(), 0), feature_counts(images_.size(), 0);
  for (const VerifiedPair& pair : pairs_) {
    if (pair.geometry.config == TwoViewGeometry::Config::kTooFewInliers) continue;
    ++partners[static_cast<size_t>(pair.image_a)];
    ++partners[static_cast<size_t>(pair.image_b)];
  }
  for (size_t i = 0; i < images_.size() && i < mapper_images_.size(); ++i)
    feature_counts[i] = static_cast<int>(mapper_images_[i].keypoints.size());
  const int min_partners =
      std::min(options_.matching.poorly_matched.min_partners, static_cast<int>(images_.size()) - 1);
  bool reextraction_needed = false;
  for (const ReextractionReason reason : PhotosToExtractAgain(partners, feature_counts, min_partners))
    reextraction_needed |= reason != ReextractionReason::kNone;
  report.matches_reusable = !reextraction_needed;
  if (!reextraction_needed) RECONAR_RETURN_IF_ERROR(record.Record("matching", MatchStageSettings(options_.matching)));

  const std::string live_dir = project_.LiveDir();
  RECONAR_RETURN_IF_ERROR(CreateDirectories(live_dir));
  if (has_model_) {
    RECONAR_RETURN_IF_ERROR(WriteColmapTextModel(model_, live_dir));
  } else {
    for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"})
      RECONAR_RETURN_IF_ERROR(RemoveFileIfPresent(live_dir + "/" + name));
  }
  JsonWriter json(2);
  json.BeginObject();
  json.Key("keyframes").Int(static_cast<long long>(report.keyframes.size()));
  json.Key("registered").Int(report.registered);
  json.Key("points").Int(report.points);
  json.Key("median_latency_s").Double(report.median_latency_seconds);
  json.Key("p95_latency_s").Double(report.p95_latency_seconds);
  json.Key("seconds_features").Double(report.seconds_features);
  json.Key("seconds_matching").Double(report.seconds_matching);
  json.Key("seconds_mapping").Double(report.seconds_mapping);
  json.Key("seconds_final_adjustment").Double(report.seconds_final_adjustment);
  json.Key("seconds_vocabulary").Double(report.seconds_vocabulary);
  json.Key("pairs_matched").Int(report.pairs_matched);
  json.Key("maps_published").Int(report.maps_published).Key("seconds_maps").Double(report.seconds_maps);
  json.Key("images").BeginArray();
  for (const LiveKeyframe& keyframe : report.keyframes) {
    json.BeginObject().Key("path").String(keyframe.path).Key("taken_s").Double(keyframe.taken_seconds);
    if (keyframe.registered_seconds >= 0.0) json.Key("registered_s").Double(keyframe.registered_seconds);
    json.Key("features").Int(keyframe.num_features);
    if (!keyframe.failure.empty()) json.Key("failure").String(keyframe.failure);
    json.EndObject();
  }
  json.EndArray().EndObject();
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(live_dir + "/report.json", json.str() + "\n"));
  return report;
}

}  // namespace reconar
