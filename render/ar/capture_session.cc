#include "render/ar/capture_session.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <thread>

#include "core/base/atomic_file.h"
#include "core/base/median.h"
#include "core/io/exif.h"
#include "core/io/focal_prior.h"
#include "core/io/image_write.h"
#include "render/ar/capture_preview.h"
#include "tracker/tag_detector.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

// The similarity taking map `from`'s frame into map `to`'s, from the centres of the keyframes both
// hold (by name). Unset with fewer than 3 shared (or all on one spot).
std::optional<Sim3> MapFromMap(const LocalizationMap& to, const LocalizationMap& from) {
  std::map<std::string, Eigen::Vector3d> from_centres;
  for (const MapKeyframe& keyframe : from.keyframes)
    from_centres[keyframe.name] = CameraCenterInWorld(keyframe.cam_from_world);
  std::vector<Eigen::Vector3d> from_points, to_points;
  for (const MapKeyframe& keyframe : to.keyframes) {
    const auto found = from_centres.find(keyframe.name);
    if (found == from_centres.end()) continue;
    from_points.push_back(found->second);
    to_points.push_back(CameraCenterInWorld(keyframe.cam_from_world));
  }
  if (from_points.size() < 3) return std::nullopt;
  Result<Sim3> to_from_from = AlignSimilarity(from_points, to_points);
  if (!to_from_from.ok()) return std::nullopt;
  return *to_from_from;
}

std::string KeyframeName(int ordinal) {
  char name[32];
  std::snprintf(name, sizeof(name), "keyframe_%05d.jpg", ordinal);
  return name;
}

// Keyframes 1..K already in `images_dir` (the first missing number ends the run of them).
int KeyframesOnDisk(const std::string& images_dir) {
  int count = 0;
  while (fs::exists(fs::path(images_dir) / KeyframeName(count + 1))) ++count;
  return count;
}

// A folder or a recording replays the same frames on every run; a device does not.
bool IsReplay(const std::string& source) {
  std::error_code error;
  return fs::is_directory(source, error) || (source.size() > 7 && source.compare(source.size() - 7, 7, ".frames") == 0);
}

}  // namespace

CaptureOptions::CaptureOptions() {
  // The map lags the person: frames beyond it are the usual case, not a failure to recover from
  // at once. A relocalisation (SIFT on the frame) costs ~40 ms at 640x480; once every ten frames
  // keeps the capture at video rate while it waits for the map to reach the view.
  map_tracker.lost_relocalise_interval = 10;
}

Status CaptureOptions::Check() const {
  if (source.empty()) return InvalidArgument("capture: no source");
  if (project_dir.empty()) return InvalidArgument("capture: no project directory");
  if (max_keyframes < 0) return InvalidArgument("capture: max_keyframes < 0");
  if (jpeg_quality < 1 || jpeg_quality > 100) return InvalidArgument("capture: jpeg_quality must be in [1, 100]");
  if (!(focal_px >= 0.0)) return InvalidArgument("capture: focal_px < 0");
  if (max_corrupt_frames_in_a_row < 1) return InvalidArgument("capture: max_corrupt_frames_in_a_row < 1");
  if (map_lag_keyframes < 0) return InvalidArgument("capture: map_lag_keyframes < 0");
  return gate.Check();
}

Result<CaptureReport> RunCapture(const CaptureOptions& options,
                                 const std::function<void(const CaptureEvent&)>& on_event,
                                 const std::atomic<bool>* stop) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  const std::string images_dir = (fs::path(options.project_dir) / "images").string();
  std::error_code error;
  fs::create_directories(images_dir, error);
  if (error) return IoError(images_dir + ": cannot create the directory: " + error.message());
  // What a capture killed mid-write left (a keyframe or feature file in flight).
  RECONAR_RETURN_IF_ERROR(RemoveStaleTemporaryFiles(options.project_dir).status());
  FrameSourceOptions source_options = options.source_options;
  source_options.want_rgb = true;
  RECONAR_ASSIGN_OR_RETURN(std::unique_ptr<FrameSource> source, OpenFrameSource(options.source, source_options));

  CaptureReport report;
  report.source = source->Describe();
  const int on_disk = KeyframesOnDisk(images_dir);
  const bool replay = IsReplay(options.source);
  // A replay meets its keyframes again from the first; a live camera goes on after them.
  int ordinal = replay ? 0 : on_disk;
  report.keyframes = on_disk;
  for (int k = 1; k <= on_disk; ++k) report.keyframe_files.push_back((fs::path(images_dir) / KeyframeName(k)).string());
  const auto emit = [&](CaptureEvent event) {
    event.frames = report.frames;
    event.keyframes = report.keyframes;
    if (on_event) on_event(event);
  };
  if (options.max_keyframes > 0 && report.keyframes >= options.max_keyframes && !replay) {
    report.stop_reason = "--max-keyframes reached";
    return report;
  }

  std::unique_ptr<LiveReconstruction> live;
  std::vector<std::string> live_paths;  // in the order given to `live`
  std::vector<bool> keyframe_registered;  // in the same order
  if (options.reconstruct_live) {
    LiveReconstructionOptions live_options = options.live;
    live_options.publish_map = live_options.publish_map || options.track_map;
    live_options.localizer = options.map_tracker.localizer;
    live = std::make_unique<LiveReconstruction>(Project(options.project_dir), live_options);
  }
  // A camera goes on after the keyframes an earlier run took, and the live model grows from them.
  if (!replay) {
    report.keyframes_kept = on_disk;
    if (live) {
      for (const std::string& path : report.keyframe_files) {
        live->AddKeyframe(path);
        live_paths.push_back(path);
        keyframe_registered.push_back(false);
      }
    }
  }
  KeyframeGate keyframe_gate(options.gate);
  // The camera followed against the live model's newest map.
  LiveMap map;
  std::unique_ptr<MapTracker> map_tracker;
  MapTrackerFrameReport map_report;
  std::vector<double> map_track_ms;
  const auto track_map = [&](const Frame& frame, CaptureEvent* event) -> Status {
    if (!live || !options.track_map) return Status::Ok();
    LiveMap newest;
    if (replay) {
      newest = live->MapAsOf(live->NumKeyframes() - options.map_lag_keyframes);
    } else if (live->MapVersion() != map.version) {
      newest = live->LatestMap();
    }
    if (newest.version != map.version && newest.map) {
      const auto switch_start = std::chrono::steady_clock::now();
      map_tracker.reset();  // it borrows the old map
      // The gate's last keyframe, posed in the old map, carried into the new one.
      if (map.map && keyframe_gate.keyframe_map_version() == map.version) {
        if (const std::optional<Sim3> new_from_old = MapFromMap(*newest.map, *map.map))
          keyframe_gate.MoveKeyframeToMap(newest.version, *new_from_old);
      }
      map = std::move(newest);
      MapTrackerOptions tracker_options = options.map_tracker;
      tracker_options.intrinsics = ScaledIntrinsics(map.intrinsics, frame.width, frame.height);
      Result<std::unique_ptr<MapTracker>> created = map.localizer ? MapTracker::Create(map.localizer, tracker_options)
                                                                  : MapTracker::Create(map.map.get(), tracker_options);
      if (!created.ok()) return created.status().WithContext("following the live model");
      map_tracker = std::move(created).value();
      ++report.maps_used;
      const double switch_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - switch_start).count();
      report.max_map_switch_ms = std::max(report.max_map_switch_ms, switch_ms);
      report.total_map_switch_ms += switch_ms;
    }
    if (!map_tracker) return Status::Ok();
    RECONAR_RETURN_IF_ERROR(map_tracker->Track(frame.gray, nullptr, &map_report));
    map_track_ms.push_back(map_report.track_ms);
    event->map_version = map.version;
    event->map_state = map_report.state;
    event->map_pose_found = map_report.found;
    event->cam_from_world = map_report.cam_from_world;
    event->map_inliers = map_report.inliers;
    if (map_report.found) ++report.frames_map_posed;
    return Status::Ok();
  };
  const auto emit_registered = [&](int64_t frame_index, double video_seconds) {
    if (!live) return;
    for (const int k : live->TakeNewlyRegistered()) {
      keyframe_registered[static_cast<size_t>(k)] = true;
      CaptureEvent event;
      event.kind = CaptureEvent::Kind::kRegistered;
      event.frame_index = frame_index;
      event.video_seconds = video_seconds;
      event.path = live_paths[static_cast<size_t>(k)];
      event.registered = live->NumRegistered();
      emit(event);
    }
  };
  const auto replay_start = std::chrono::steady_clock::now();
  if (!options.preview_dir.empty()) {
    fs::create_directories(options.preview_dir, error);
    if (error) return IoError(options.preview_dir + ": cannot create the directory: " + error.message());
  }
  std::unique_ptr<TagDetector> tag_detector;
  TagDetectionList tags_in_view(16);
  std::vector<std::array<Eigen::Vector2d, 4>> last_tags;
  const bool previewing = !options.preview_dir.empty() || options.show_preview;
  if (previewing && !options.preview_tag_family.empty()) {
    RECONAR_ASSIGN_OR_RETURN(const TagFamily family, ParseTagFamily(options.preview_tag_family));
    TagDetectorOptions detector_options;
    detector_options.family = family;
    RECONAR_ASSIGN_OR_RETURN(tag_detector, TagDetector::Create(detector_options));
  }
  Image<uint8_t> last_view, preview;  // the last frame previewed, and with the overlay drawn
  GateVerdict last_verdict = GateVerdict::kTooClose;
  const char* last_advice = "";
  const auto draw_overlay = [&]() {
    preview = last_view;
    CapturePreviewState state;
    state.verdict = last_verdict;
    state.advice = last_advice;
    state.keyframe_registered = keyframe_registered;
    if (live) state.coverage = live->Coverage();
    state.tags = last_tags;
    DrawCapturePreview(state, &preview);
  };
  // The overlay on the last frame previewed, as `name` and as latest.png.
  const auto draw_preview = [&](const char* name) -> Status {
    draw_overlay();
    if (name != nullptr)
      RECONAR_RETURN_IF_ERROR(WritePng((fs::path(options.preview_dir) / name).string(), preview.view(), 3));
    RECONAR_RETURN_IF_ERROR(WritePng((fs::path(options.preview_dir) / "latest.png").string(), preview.view(), 3));
    ++report.previews;
    return Status::Ok();
  };
  const auto take_view = [&](const Frame& frame, const GateFrameReport& gate, bool find_tags) {
    if (last_view.width() != frame.width || last_view.height() != frame.height)
      last_view = Image<uint8_t>(frame.width, frame.height, 3);
    for (int y = 0; y < frame.height; ++y)
      std::copy(frame.rgb.row(y), frame.rgb.row(y) + 3 * frame.width, last_view.row(y));
    last_verdict = gate.verdict;
    last_advice = gate.advice;
    if (!find_tags) return;
    last_tags.clear();
    if (tag_detector && tag_detector->Detect(frame.gray, &tags_in_view).ok()) {
      for (const TagDetection& tag : tags_in_view)
        last_tags.push_back({tag.corners[0], tag.corners[1], tag.corners[2], tag.corners[3]});
    }
  };
  // Each keyframe and one frame per second: the tags found again, the picture written.
  const auto write_preview = [&](const Frame& frame, const GateFrameReport& gate) -> Status {
    if (!previewing || frame.rgb.data == nullptr) return Status::Ok();
    take_view(frame, gate, /*find_tags=*/true);
    if (options.preview_dir.empty()) return Status::Ok();
    char name[40];
    std::snprintf(name, sizeof(name), "preview_%06lld.png", static_cast<long long>(frame.index));
    return draw_preview(name);
  };
  // Every frame in the window, with the tags last found; false: stop (the reason is set).
  const auto show_preview = [&](const Frame& frame, const GateFrameReport& gate, bool taken) -> bool {
    if (!options.show_preview || frame.rgb.data == nullptr) return true;
    if (!taken) take_view(frame, gate, /*find_tags=*/false);
    draw_overlay();
    const Result<bool> shown = options.show_preview(preview);
    if (shown.ok() && *shown) return true;
    report.stop_reason = shown.ok() ? "window closed" : "the window failed: " + shown.status().message();
    report.window_failed = !shown.ok();
    return false;
  };

  std::vector<double> gate_ms;
  int corrupt_in_a_row = 0;
  std::string last_damage;
  int64_t first_timestamp = -1;
  int last_status_second = -1;
  while (true) {
    if (stop != nullptr && stop->load()) {
      report.stop_reason = "stopped";
      break;
    }
    Result<FrameHandle> next = source->Next();
    if (!next.ok()) {
      if (IsEndOfStream(next.status())) {
        report.stop_reason = replay ? "end of the recording" : "end of the stream";
        break;
      }
      // A damaged frame is skipped; the same damage met again (a recording cut short, which cannot
      // be read past) ends the capture like a camera that disconnected.
      const bool same_damage = next.status().message() == last_damage;
      last_damage = next.status().message();
      if (next.status().code() == StatusCode::kCorruptData && !same_damage &&
          ++corrupt_in_a_row < options.max_corrupt_frames_in_a_row) {
        ++report.corrupt;
        CaptureEvent warning;
        warning.kind = CaptureEvent::Kind::kWarning;
        warning.message = "skipped a corrupt frame: " + next.status().message();
        emit(warning);
        continue;
      }
      report.source_failed = true;
      report.stop_reason = next.status().message();
      break;
    }
    corrupt_in_a_row = 0;
    const Frame& frame = **next;
    if (first_timestamp < 0) first_timestamp = frame.timestamp_ns;
    ++report.frames;
    CaptureEvent event;
    event.frame_index = frame.index;
    event.video_seconds = static_cast<double>(frame.timestamp_ns - first_timestamp) * 1e-9;
    if (replay && options.replay_in_real_time)
      std::this_thread::sleep_until(replay_start + std::chrono::duration<double>(event.video_seconds));
    emit_registered(event.frame_index, event.video_seconds);
    if (live) event.registered = live->NumRegistered();
    if (const Status tracked = track_map(frame, &event); !tracked.ok()) {
      return Status(tracked.code(), std::string(frame.name) + ": " + tracked.message());
    }
    GateMapPose map_pose;
    if (event.map_pose_found) {
      map_pose.map_version = event.map_version;
      map_pose.cam_from_world = event.cam_from_world;
      map_pose.points = map_report.inlier_world_points.data();
      map_pose.num_points = static_cast<int>(map_report.inlier_world_points.size());
    }
    const auto start = std::chrono::steady_clock::now();
    const Status judged = keyframe_gate.Process(frame.gray, &event.gate, &map_pose);
    gate_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    if (!judged.ok()) return Status(judged.code(), std::string(frame.name) + ": " + judged.message());
    if (event.gate.triangulation_angle_deg >= 0.0) ++report.frames_map_motion;
    switch (event.gate.verdict) {
      case GateVerdict::kBlurred:
        ++report.blurred;
        break;
      case GateVerdict::kBadExposure:
        ++report.bad_exposure;
        break;
      case GateVerdict::kTooClose:
        ++report.too_close;
        break;
      case GateVerdict::kLost:
        ++report.lost;
        break;
      case GateVerdict::kKeyframe:
        break;
    }
    if (event.gate.verdict == GateVerdict::kKeyframe) {
      ++ordinal;
      const std::string path = (fs::path(images_dir) / KeyframeName(ordinal)).string();
      event.kind = CaptureEvent::Kind::kKeyframe;
      event.path = path;
      if (ordinal <= on_disk) {
        event.kept = true;
        ++report.keyframes_kept;
      } else {
        ExifInfo exif =
            options.focal_px > 0.0 ? ExifForFocal(frame.width, frame.height, options.focal_px, "") : ExifInfo{};
        exif.make = "reconar";
        exif.model = report.source;
        RECONAR_RETURN_IF_ERROR(WriteJpeg(path, frame.rgb, 3, options.jpeg_quality, BuildExifApp1(exif)));
        ++report.keyframes;
        report.keyframe_files.push_back(path);
      }
      if (live) {
        live->AddKeyframe(path);
        live_paths.push_back(path);
      }
      keyframe_registered.push_back(false);
      emit(event);
      RECONAR_RETURN_IF_ERROR(write_preview(frame, event.gate));
      if (!show_preview(frame, event.gate, /*taken=*/true)) break;
      if (options.max_keyframes > 0 && ordinal >= options.max_keyframes) {
        report.stop_reason = "--max-keyframes reached";
        break;
      }
      continue;
    }
    const int second = static_cast<int>(event.video_seconds);
    bool taken = false;
    if (second != last_status_second) {
      last_status_second = second;
      event.kind = CaptureEvent::Kind::kStatus;
      emit(event);
      RECONAR_RETURN_IF_ERROR(write_preview(frame, event.gate));
      taken = previewing;
    } else if (options.frame_events) {
      event.kind = CaptureEvent::Kind::kFrame;
      emit(event);
    }
    if (!show_preview(frame, event.gate, taken)) break;
  }
  report.median_gate_ms = Median(gate_ms);
  report.median_map_track_ms = Median(map_track_ms);
  if (live) {
    // The worker finishes the keyframes it has not reached; its events still reach the caller.
    RECONAR_ASSIGN_OR_RETURN(report.live_model, live->Finish());
    report.live = true;
    emit_registered(-1, -1.0);
  }
  // latest.png once more, with every registration the live model made.
  if (!options.preview_dir.empty() && last_view.width() > 0) RECONAR_RETURN_IF_ERROR(draw_preview(nullptr));
  return report;
}

}  // namespace reconar
