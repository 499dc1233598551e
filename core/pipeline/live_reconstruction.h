#pragma once
// A sparse model that grows while photos arrive (`reconar capture`, issue 18). A worker thread
// takes the keyframes in the order they were taken, one at a time:
//   1. features, as the feature stage extracts them, written to PROJECT/features/ at once;
//   2. matches against the earlier keyframes PairSelector chooses (every one up to its exhaustive
//      limit, then a sequential window plus retrieval), verified as the match stage verifies them:
//      the same pairs, as the rule depends only on the keyframes so far;
//   3. the model grown by ContinueIncrementalMapper (core/sfm/mapper.h) from the last one, or
//      started once two keyframes make an initial pair: the new keyframe gets a local bundle
//      adjustment, the whole model a global one when it has grown by a quarter, and the final
//      adjustment (the intrinsics model chosen, then adjusted to convergence) runs in Finish().
// One keyframe at a time in a fixed order makes the result independent of how far the worker
// lags behind the camera: a replay that resumes after a crash ends with the same model.
//
// Finish() drains the queue and leaves a project `reconar reconstruct PROJECT/images PROJECT`
// continues from: features/ and images.txt, matches/matches.txt, their stages recorded under the
// settings the reconstruction would use (so it reuses them), and the live model in PROJECT/live/
// (COLMAP text) with PROJECT/live/report.json (when each keyframe registered).
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/base/status.h"
#include "core/base/thread_pool.h"
#include "core/features/matcher.h"
#include "core/features/pair_selection.h"
#include "core/math/camera_intrinsics.h"
#include "core/pipeline/feature_stage.h"
#include "core/pipeline/match_stage.h"
#include "core/pipeline/project.h"
#include "core/sfm/localization_map.h"
#include "core/sfm/localizer.h"
#include "core/sfm/mapper.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

struct LiveReconstructionOptions {
  // As `reconar reconstruct` runs them (ReconstructOptions' defaults), so that it reuses them.
  LiveReconstructionOptions();
  FeatureStageOptions features;
  MatchStageOptions matching;
  MapperOptions mapper;
  // Threads that match and verify a keyframe's pairs (the worker's main cost); the rest of the
  // worker is one thread. The model does not depend on the count. <= 0: one per core but one,
  // which the capturing thread keeps (at least one).
  int worker_threads = 0;
  // Publish the model as a localisation map (LatestMap) when it starts, at each of its global
  // adjustments, and once map_every_keyframes more keyframes have registered since the last map
  // (<= 0: not), for following the camera against it while it grows.
  bool publish_map = false;
  // The camera is lost a few metres past a map's last keyframe, and the global adjustments come
  // further apart as the model grows. On the 1000-frame corridor walk (bench_live_model) maps at
  // the global adjustments alone posed 723 of the frames (19 maps); with one every 5 keyframes as
  // well, 982 (57 maps), for 8.2 s of the worker's time (a map and its localizer each; capture 210 s).
  int map_every_keyframes = 5;
  MapBuildOptions map;  // num_threads is the worker's one
  // Each published map comes with its localizer (LiveMap::localizer), built by the worker with
  // these options: the camera's tracker takes it as it is instead of building its search index.
  LocalizerOptions localizer;
};

// The live model as a localisation map (core/sfm/localization_map.h) for tracking the camera
// against it (tracker/map_tracker.h). Between two maps only the newest keyframes' local
// adjustments changed the model; a map is built from all of it.
struct LiveMap {
  std::shared_ptr<const LocalizationMap> map;  // null before the first model
  std::shared_ptr<const Localizer> localizer;  // over `map` (which must outlive it)
  CameraIntrinsics intrinsics;                 // the model's camera, at the keyframes' size
  int version = 0;                             // maps published so far
  int keyframes = 0;                           // keyframes processed when it was built
};

struct LiveKeyframe {
  std::string path;
  double taken_seconds = 0.0;        // since the live reconstruction started
  double registered_seconds = -1.0;  // when it first registered; < 0: not (yet)
  int num_features = 0;
  std::string failure;  // an unreadable keyframe's reason
};

struct LiveReconstructionReport {
  std::vector<LiveKeyframe> keyframes;
  int registered = 0;  // in the final model
  int points = 0;
  double median_latency_seconds = 0.0;  // taken -> registered, over the keyframes that registered
  double p95_latency_seconds = 0.0;
  double seconds_features = 0.0, seconds_matching = 0.0, seconds_mapping = 0.0;  // the worker's time
  double seconds_vocabulary = 0.0;  // of seconds_matching: training the pair rule's vocabulary
  int pairs_matched = 0;
  double seconds_final_adjustment = 0.0;                                         // in Finish()
  int maps_published = 0;     // LiveReconstructionOptions::publish_map
  double seconds_maps = 0.0;  // the worker's time building them
  std::string error;  // a failure that stopped the worker (the keyframes stay on disk)
  // The keyframes' matches stand as the match stage's (`reconstruct` reuses them); false when the
  // match stage would extract some keyframe again (PhotosToExtractAgain), so that it matches anew.
  bool matches_reusable = true;
};

// The directions from which a model's object has been seen, for the capture's coverage indicator:
// `sectors` equal sectors of azimuth about the vertical through the points' median (vertical: the
// registered cameras' mean up direction), sector 0 centred on the first registered camera; true
// where a registered camera stands. All false for a model of fewer than two cameras or no points.
std::vector<bool> ViewCoverage(const Reconstruction& model, int sectors);

class LiveReconstruction {
 public:
  LiveReconstruction(const Project& project, const LiveReconstructionOptions& options);
  ~LiveReconstruction();  // stops the worker (what it finished stays on disk)
  LiveReconstruction(const LiveReconstruction&) = delete;
  LiveReconstruction& operator=(const LiveReconstruction&) = delete;

  // Queues a keyframe written whole at `path`; returns at once.
  void AddKeyframe(const std::string& path);
  // ViewCoverage of the model as it is now (12 sectors).
  std::vector<bool> Coverage() const;
  // Indices (in AddKeyframe order) of the keyframes registered since the last call.
  std::vector<int> TakeNewlyRegistered();
  // Keyframes queued, finished by the worker, and in the model now.
  int NumKeyframes() const;
  int NumProcessed() const;  // taken by the worker and finished
  int NumRegistered() const;
  // The newest map (LiveReconstructionOptions::publish_map); a null map before the first one.
  LiveMap LatestMap() const;
  int MapVersion() const;  // LatestMap().version, without copying it
  // The newest map built from at most the first `keyframes` keyframes, once the worker has
  // processed that many (or stopped): it waits. For a replay, whose frames must meet the same map
  // on every run however far the worker lags. The last kMapsKept maps are kept for it.
  LiveMap MapAsOf(int keyframes);
  static constexpr size_t kMapsKept = 8;

  // Waits for the queue to drain, writes the outputs above; errors name the file.
  Result<LiveReconstructionReport> Finish();

 private:
  void Work();
  Status ProcessKeyframe(size_t index);
  MapperOptions MapperOnOneThread() const;
  // Makes model_ the one the capture sees: registered count, coverage, newly registered keyframes.
  void PublishModel();
  // Builds and publishes the localisation map of model_; a failure leaves the last map.
  void PublishMap();
  // The final global adjustment of the live model, once (Finish()).
  Status AdjustFinally();

  const Project project_;
  const LiveReconstructionOptions options_;
  const int worker_threads_;  // options_.worker_threads resolved
  const std::chrono::steady_clock::time_point start_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<LiveKeyframe> queued_;   // guarded by mutex_
  size_t done_ = 0;                    // keyframes processed; guarded by mutex_
  bool stopping_ = false;              // guarded by mutex_: leave now
  bool finishing_ = false;             // guarded by mutex_: leave once the queue is empty
  std::vector<int> newly_registered_;  // guarded by mutex_
  int registered_now_ = 0;             // guarded by mutex_
  std::vector<bool> coverage_;         // guarded by mutex_
  Status worker_error_;                // guarded by mutex_
  bool worker_stopped_ = false;        // guarded by mutex_: by an error
  std::deque<LiveMap> maps_;           // guarded by mutex_: the newest last

  // The worker's own state.
  PhotoFeatureExtractor extractor_;
  std::unique_ptr<ThreadPool> match_pool_;          // worker_threads_
  std::vector<std::unique_ptr<Matcher>> matchers_;  // one per thread of match_pool_
  std::optional<PairSelector> pair_selector_;
  std::vector<ProjectImage> images_;
  std::vector<SiftFeatures> features_;
  std::vector<size_t> keyframe_of_image_;  // images_[i] is queued_[keyframe_of_image_[i]]
  std::vector<VerifiedPair> pairs_;
  std::vector<MapperImage> mapper_images_;
  std::vector<MapperPair> mapper_pairs_;
  Reconstruction model_;
  bool has_model_ = false;
  bool model_final_ = false;           // model_ has had its final adjustment
  MapperContinuation growth_;          // local adjustments; global ones at growth milestones
  double seconds_features_ = 0.0, seconds_matching_ = 0.0, seconds_mapping_ = 0.0, seconds_final_adjustment_ = 0.0;
  int pairs_matched_ = 0;
  double seconds_maps_ = 0.0;
  int maps_published_ = 0;
  int registered_at_last_map_ = 0;

  std::thread worker_;
};

}  // namespace reconar
