// bench_live_model OUT_DIR [frames=300] [step_m=0.05] [pairs=50,10,40] [size=640x480] [worker_threads=0]
// [every_pair=1]: how the capture's live model keeps up as a capture grows. A walk down the rendered corridor
// (tests/support/corridor_walk.h, exact poses) is replayed through `reconar capture`'s loop at 30 frames per second, as
// a camera would deliver it; printed: the keyframes and how many registered, the time from a keyframe being written to
// its registration over the first and the last quarter of the keyframes, the worker's time per step, the final
// adjustment, and the live model's cameras against the truth; twice, with the pair rule's defaults and with every pair
// matched (every_pair=0: once); then `sfm` run offline on the first run's keyframes, whose true cameras are written to
// OUT_DIR/capture/truth/ (COLMAP text). Also the capturing thread's cost per frame (the gate;
// following the camera against the live model) and the capture's wall time against the video's: a replay waits for the
// live model when it lags more than a keyframe behind (CaptureOptions::map_lag_keyframes), a camera would not.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/base/median.h"
#include "core/pipeline/reconstruct.h"
#include "render/ar/capture_session.h"
#include "tests/support/corridor_walk.h"
#include "tests/support/sfm_evaluation.h"

namespace fs = std::filesystem;

namespace {

int Fail(const reconar::Status& status) {
  std::fprintf(stderr, "bench_live_model: %s\n", status.ToString().c_str());
  return 1;
}

// Latency (taken -> registered) of keyframes [from, to): median and maximum, seconds.
void PrintLatency(const char* what, const std::vector<reconar::LiveKeyframe>& keyframes, size_t from, size_t to) {
  std::vector<double> latency;
  for (size_t k = from; k < to && k < keyframes.size(); ++k) {
    if (keyframes[k].registered_seconds >= 0.0)
      latency.push_back(keyframes[k].registered_seconds - keyframes[k].taken_seconds);
  }
  const double max = latency.empty() ? 0.0 : *std::max_element(latency.begin(), latency.end());
  std::printf("  %s (keyframes %zu-%zu): %zu registered, latency median %.2f s, max %.2f s\n", what, from + 1,
              std::min(to, keyframes.size()), latency.size(), reconar::Median(latency), max);
}

// Mean, median and largest error: a mean far above the median is a few cameras astray. The
// rotations after the alignment by the centres, and between every two cameras (no alignment): a walk
// nearly straight leaves the alignment's roll about it to the sway (12 cm) and the centres' errors,
// so a common roll of the cameras may dominate the first.
std::string Errors(const reconar::testing::CameraPoseErrors& errors, double path_m) {
  char text[320];
  std::snprintf(text, sizeof(text),
                "centre error mean %.4f %% of the %.2f m walk (median %.4f %%, max %.4f %%), rotation mean %.3f deg "
                "(median %.3f, max %.3f), relative rotation mean %.3f deg",
                100.0 * errors.centre_mean / path_m, path_m, 100.0 * errors.centre_median / path_m,
                100.0 * errors.centre_max / path_m, errors.rotation_mean_deg, errors.rotation_median_deg,
                errors.rotation_max_deg, errors.relative_rotation_mean_deg);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: bench_live_model OUT_DIR [frames=300] [step_m=0.05] [pairs=50,10,40] [size=640x480] "
                 "[worker_threads=0] [every_pair=1]\n"
                 "  pairs: the pair rule's exhaustive limit, window and retrieved count\n"
                 "  worker_threads: LiveReconstructionOptions::worker_threads (0: one per core but one)\n"
                 "  every_pair: 0 skips the second capture (every pair matched)\n");
    return 2;
  }
  const fs::path out = argv[1];
  reconar::testing::CorridorWalkOptions walk;
  walk.frames = argc > 2 ? std::max(30, std::atoi(argv[2])) : 300;
  walk.step_m = argc > 3 ? std::atof(argv[3]) : 0.05;
  walk.length_m = std::max(walk.length_m, walk.frames * walk.step_m + 4.0);
  reconar::PairSelectionOptions pair_rule;
  if (argc > 4 && std::sscanf(argv[4], "%d,%d,%d", &pair_rule.exhaustive_up_to, &pair_rule.sequential_window,
                              &pair_rule.retrieved) != 3) {
    std::fprintf(stderr, "bench_live_model: pairs must be N,W,M, got '%s'\n", argv[4]);
    return 2;
  }
  if (argc > 5 &&
      (std::sscanf(argv[5], "%dx%d", &walk.width, &walk.height) != 2 || walk.width < 64 || walk.height < 64)) {
    std::fprintf(stderr, "bench_live_model: size must be WxH, got '%s'\n", argv[5]);
    return 2;
  }
  const int worker_threads = argc > 6 ? std::atoi(argv[6]) : 0;
  const bool with_every_pair = argc > 7 ? std::atoi(argv[7]) != 0 : true;
  walk.focal_px *= walk.width / 640.0;
  std::error_code error;
  fs::remove_all(out, error);
  const fs::path video = out / "video";
  fs::create_directories(video, error);
  if (error) return Fail(reconar::IoError(video.string() + ": cannot create the directory: " + error.message()));
  std::printf("rendering %d frames of a %.2f m walk...\n", walk.frames, walk.step_m * (walk.frames - 1));
  auto truth = reconar::testing::RenderCorridorWalk(video.string(), walk);
  if (!truth.ok()) return Fail(truth.status());
  std::vector<std::string> names;
  for (const auto& entry : *truth) names.push_back(entry.first);
  std::sort(names.begin(), names.end());

  // The capture twice over the same video: with the pair rule's defaults (retrieval beyond its
  // exhaustive limit), and matching every pair, so that the two are measured side by side.
  std::map<std::string, std::string> frame_of_keyframe, frame_of_default_keyframe;
  const auto frame_of = [&](const std::string& name) {
    const auto it = frame_of_keyframe.find(name);
    return it == frame_of_keyframe.end() ? std::string() : it->second;
  };
  const double path = walk.step_m * (walk.frames - 1);
  std::vector<std::string> keyframe_paths;
  for (const bool every_pair : {false, true}) {
    if (every_pair && !with_every_pair) break;
    reconar::CaptureOptions capture;
    capture.live.worker_threads = worker_threads;
    capture.source = video.string();
    capture.project_dir = (out / (every_pair ? "capture_every_pair" : "capture")).string();
    capture.replay_in_real_time = true;
    capture.live.matching.pairs = pair_rule;
    if (every_pair) capture.live.matching.pairs.exhaustive_up_to = 1 << 24;
    frame_of_keyframe.clear();
    const auto capture_start = std::chrono::steady_clock::now();
    auto report = reconar::RunCapture(capture, [&](const reconar::CaptureEvent& event) {
      if (event.kind != reconar::CaptureEvent::Kind::kKeyframe) return;
      frame_of_keyframe[fs::path(event.path).filename().string()] = names[static_cast<size_t>(event.frame_index)];
    });
    if (!report.ok()) return Fail(report.status());
    const double capture_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - capture_start).count();
    const reconar::LiveReconstructionReport& live = report->live_model;
    const size_t n = live.keyframes.size();
    std::printf("%s: %d frames at 30 fps: %zu keyframes, %d registered in the live model (%d points)\n",
                every_pair ? "every pair matched" : "pair rule", report->frames, n, live.registered,
                live.points);
    std::printf(
        "  %dx%d; capturing thread per frame (median): gate %.2f ms, following the live model %.2f ms (%d of %d "
        "frames posed against %d maps; baseline from the poses for %d); capture %.1f s for %.1f s of video (the "
        "final adjustment included)\n",
        walk.width, walk.height, report->median_gate_ms, report->median_map_track_ms, report->frames_map_posed,
        report->frames, report->maps_used, report->frames_map_motion, capture_seconds, walk.frames / 30.0);
    std::printf(
        "  taking up a new map on the capturing thread: max %.1f ms, total %.2f s; maps built by the worker in "
        "%.2f s\n",
        report->max_map_switch_ms, report->total_map_switch_ms / 1000.0, live.seconds_maps);
    PrintLatency("first quarter", live.keyframes, 0, n / 4);
    PrintLatency("last quarter ", live.keyframes, n - n / 4, n);
    std::printf("  latency over all: median %.2f s, p95 %.2f s\n", live.median_latency_seconds,
                live.p95_latency_seconds);
    std::printf(
        "  worker: features %.2f s, matching %.2f s (%d pairs; vocabulary %.2f s), mapping %.2f s; final "
        "adjustment %.2f s\n",
        live.seconds_features, live.seconds_matching, live.pairs_matched, live.seconds_vocabulary, live.seconds_mapping,
        live.seconds_final_adjustment);
    auto live_score = reconar::testing::ScoreModelAgainstTruth(capture.project_dir + "/live", *truth, frame_of);
    if (!live_score.ok()) return Fail(live_score.status());
    std::printf("  live model: %d registered, %s\n", live_score->registered, Errors(live_score->errors, path).c_str());
    if (every_pair && report->keyframe_files.size() != keyframe_paths.size()) {
      std::printf("  (the two captures took different keyframes: %zu and %zu)\n", keyframe_paths.size(),
                  report->keyframe_files.size());
    }
    if (!every_pair) {
      // The keyframes' true cameras as a COLMAP text model without points (OUT/capture/truth), for
      // scoring other tools or models on them.
      reconar::testing::GroundTruthByName keyframe_truth;
      for (const auto& [keyframe, frame] : frame_of_keyframe) keyframe_truth[keyframe] = truth->at(frame);
      const reconar::Status written =
          reconar::testing::WriteGroundTruthModel(keyframe_truth, capture.project_dir + "/truth");
      if (!written.ok()) return Fail(written);
      keyframe_paths = report->keyframe_files;
      frame_of_default_keyframe = frame_of_keyframe;
    }
  }
  frame_of_keyframe = frame_of_default_keyframe;  // the offline run is on the default capture's keyframes
  reconar::ReconstructOptions offline;
  offline.run_dense = offline.run_mesh = false;
  offline.show_progress = false;
  offline.matching.pairs = pair_rule;
  const auto offline_start = std::chrono::steady_clock::now();
  auto offline_report = reconar::RunReconstruct(keyframe_paths, reconar::Project((out / "offline").string()), offline);
  if (!offline_report.ok()) return Fail(offline_report.status());
  const double offline_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - offline_start).count();
  auto offline_score =
      reconar::testing::ScoreModelAgainstTruth((out / "offline" / "sparse").string(), *truth, frame_of);
  if (!offline_score.ok()) return Fail(offline_score.status());
  std::printf("offline sfm: %d registered, %s (%.1f s)\n", offline_score->registered,
              Errors(offline_score->errors, path).c_str(), offline_seconds);
  return 0;
}
