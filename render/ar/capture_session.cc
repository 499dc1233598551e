#include "render/ar/capture_session.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>

#include "core/base/atomic_file.h"
#include "core/base/json_writer.h"
#include "core/base/median.h"
#include "core/io/exif.h"
#include "core/io/focal_prior.h"
#include "core/io/image_write.h"
#include "render/ar/capture_preview.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

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

CaptureSession::CaptureSession(const CaptureOptions& options)
    : options_(options),
      keyframe_gate_(options.gate),
      map_follower_(options.map_tracker),
      tags_in_view_(16) {}

CaptureSession::~CaptureSession() = default;

Result<std::unique_ptr<CaptureSession>> CaptureSession::Open(const CaptureOptions& options,
                                                             std::function<void(const CaptureEvent&)> on_event) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  std::unique_ptr<CaptureSession> session(new CaptureSession(options));
  session->on_event_ = std::move(on_event);
  session->images_dir_ = (fs::path(options.project_dir) / "images").string();
  std::error_code error;
  fs::create_directories(session->images_dir_, error);
  if (error) return IoError(session->images_dir_ + ": cannot create the directory: " + error.message());
  // What a capture killed mid-write left (a keyframe or feature file in flight).
  RECONAR_RETURN_IF_ERROR(RemoveStaleTemporaryFiles(options.project_dir).status());
  FrameSourceOptions source_options = options.source_options;
  source_options.want_rgb = true;
  RECONAR_ASSIGN_OR_RETURN(session->source_, OpenFrameSource(options.source, source_options));

  CaptureReport& report = session->report_;
  report.source = session->source_->Describe();
  session->on_disk_ = KeyframesOnDisk(session->images_dir_);
  session->replay_ = IsReplay(options.source);
  // A replay meets its keyframes again from the first; a live camera goes on after them.
  session->ordinal_ = session->replay_ ? 0 : session->on_disk_;
  report.keyframes = session->on_disk_;
  for (int k = 1; k <= session->on_disk_; ++k)
    report.keyframe_files.push_back((fs::path(session->images_dir_) / KeyframeName(k)).string());
  if (options.max_keyframes > 0 && report.keyframes >= options.max_keyframes && !session->replay_) {
    report.stop_reason = "--max-keyframes reached";
    session->ended_ = true;
    return session;
  }
  if (options.reconstruct_live) {
    LiveReconstructionOptions live_options = options.live;
    live_options.publish_map = live_options.publish_map || options.track_map;
    live_options.localizer = options.map_tracker.localizer;
    session->live_ = std::make_unique<LiveReconstruction>(Project(options.project_dir), live_options);
  }
  // A camera goes on after the keyframes an earlier run took, and the live model grows from them.
  if (!session->replay_) {
    report.keyframes_kept = session->on_disk_;
    if (session->live_) {
      for (const std::string& path : report.keyframe_files) {
        session->live_->AddKeyframe(path);
        session->live_paths_.push_back(path);
        session->keyframe_registered_.push_back(false);
      }
    }
  }
  session->replay_start_ = std::chrono::steady_clock::now();
  if (!options.preview_dir.empty()) {
    fs::create_directories(options.preview_dir, error);
    if (error) return IoError(options.preview_dir + ": cannot create the directory: " + error.message());
  }
  session->previewing_ = !options.preview_dir.empty() || options.show_preview;
  if (session->previewing_ && !options.preview_tag_family.empty()) {
    RECONAR_ASSIGN_OR_RETURN(const TagFamily family, ParseTagFamily(options.preview_tag_family));
    TagDetectorOptions detector_options;
    detector_options.family = family;
    RECONAR_ASSIGN_OR_RETURN(session->tag_detector_, TagDetector::Create(detector_options));
  }
  return session;
}

void CaptureSession::Emit(CaptureEvent event) const {
  event.frames = report_.frames;
  event.keyframes = report_.keyframes;
  if (on_event_) on_event_(event);
}

void CaptureSession::EmitRegistered(int64_t frame_index, double video_seconds) {
  if (!live_) return;
  for (const int k : live_->TakeNewlyRegistered()) {
    keyframe_registered_[static_cast<size_t>(k)] = true;
    CaptureEvent event;
    event.kind = CaptureEvent::Kind::kRegistered;
    event.frame_index = frame_index;
    event.video_seconds = video_seconds;
    event.path = live_paths_[static_cast<size_t>(k)];
    event.registered = live_->NumRegistered();
    Emit(event);
  }
}

// The camera followed against the live model's newest map.
Status CaptureSession::FollowMap(const Frame& frame, CaptureEvent* event) {
  if (!live_ || !options_.track_map) return Status::Ok();
  LiveMap newest;
  if (replay_) {
    newest = live_->MapAsOf(live_->NumKeyframes() - options_.map_lag_keyframes);
  } else if (live_->MapVersion() != map_follower_.version()) {
    newest = live_->LatestMap();
  }
  if (newest.version != map_follower_.version() && newest.map) {
    const bool keyframe_in_old_map =
        map_follower_.following() && keyframe_gate_.keyframe_map_version() == map_follower_.version();
    Result<MapSwitch> switched = map_follower_.TakeUp(newest.version, newest.map, newest.localizer,
                                                      newest.intrinsics, frame.width, frame.height);
    if (!switched.ok()) return switched.status().WithContext("following the live model");
    const MapSwitch& taken_up = *switched;
    // The gate's last keyframe, posed in the old map, carried into the new one.
    if (keyframe_in_old_map && taken_up.new_from_old) keyframe_gate_.MoveKeyframeToMap(newest.version, *taken_up.new_from_old);
    ++report_.maps_used;
    report_.max_map_switch_ms = std::max(report_.max_map_switch_ms, taken_up.milliseconds);
    report_.total_map_switch_ms += taken_up.milliseconds;
  }
  if (!map_follower_.following()) return Status::Ok();
  RECONAR_RETURN_IF_ERROR(map_follower_.Track(frame.gray, &map_report_));
  map_track_ms_.push_back(map_report_.track_ms);
  event->map_version = map_follower_.version();
  event->map_state = map_report_.state;
  event->map_pose_found = map_report_.found;
  event->cam_from_world = map_report_.cam_from_world;
  event->map_inliers = map_report_.inliers;
  if (map_report_.found) ++report_.frames_map_posed;
  return Status::Ok();
}

void CaptureSession::DrawOverlay() {
  preview_ = last_view_;
  CapturePreviewState state;
  state.verdict = last_verdict_;
  state.advice = last_advice_;
  state.keyframe_registered = keyframe_registered_;
  if (live_) state.coverage = live_->Coverage();
  state.tags = last_tags_;
  DrawCapturePreview(state, &preview_);
}

// The overlay on the last frame previewed, as `name` and as latest.png.
Status CaptureSession::DrawPreview(const char* name) {
  DrawOverlay();
  if (name != nullptr)
    RECONAR_RETURN_IF_ERROR(WritePng((fs::path(options_.preview_dir) / name).string(), preview_.view(), 3));
  RECONAR_RETURN_IF_ERROR(WritePng((fs::path(options_.preview_dir) / "latest.png").string(), preview_.view(), 3));
  ++report_.previews;
  return Status::Ok();
}

void CaptureSession::TakeView(const Frame& frame, const GateFrameReport& gate, bool find_tags) {
  if (last_view_.width() != frame.width || last_view_.height() != frame.height)
    last_view_ = Image<uint8_t>(frame.width, frame.height, 3);
  for (int y = 0; y < frame.height; ++y)
    std::copy(frame.rgb.row(y), frame.rgb.row(y) + 3 * frame.width, last_view_.row(y));
  last_verdict_ = gate.verdict;
  last_advice_ = gate.advice;
  if (!find_tags) return;
  last_tags_.clear();
  if (tag_detector_ && tag_detector_->Detect(frame.gray, &tags_in_view_).ok()) {
    for (const TagDetection& tag : tags_in_view_)
      last_tags_.push_back({tag.corners[0], tag.corners[1], tag.corners[2], tag.corners[3]});
  }
}

// Each keyframe and one frame per second: the tags found again, the picture written.
Status CaptureSession::WritePreview(const Frame& frame, const GateFrameReport& gate) {
  if (!previewing_ || frame.rgb.data == nullptr) return Status::Ok();
  TakeView(frame, gate, /*find_tags=*/true);
  if (options_.preview_dir.empty()) return Status::Ok();
  char name[40];
  std::snprintf(name, sizeof(name), "preview_%06lld.png", static_cast<long long>(frame.index));
  return DrawPreview(name);
}

// Every frame in the window, with the tags last found; false: stop (the reason is set).
bool CaptureSession::ShowPreview(const Frame& frame, const GateFrameReport& gate, bool taken) {
  if (!options_.show_preview || frame.rgb.data == nullptr) return true;
  if (!taken) TakeView(frame, gate, /*find_tags=*/false);
  DrawOverlay();
  const Result<bool> shown = options_.show_preview(preview_);
  if (shown.ok() && *shown) return true;
  report_.stop_reason = shown.ok() ? "window closed" : "the window failed: " + shown.status().message();
  report_.window_failed = !shown.ok();
  return false;
}

bool CaptureSession::EndsTheCapture(const Status& status) {
  if (IsEndOfStream(status)) {
    report_.stop_reason = replay_ ? "end of the recording" : "end of the stream";
    return true;
  }
  // A damaged frame is skipped; the same damage met again (a recording cut short, which cannot
  // be read past) ends the capture like a camera that disconnected.
  const bool same_damage = status.message() == last_damage_;
  last_damage_ = status.message();
  if (status.code() == StatusCode::kCorruptData && !same_damage &&
      ++corrupt_in_a_row_ < options_.max_corrupt_frames_in_a_row) {
    ++report_.corrupt;
    CaptureEvent warning;
    warning.kind = CaptureEvent::Kind::kWarning;
    warning.message = "skipped a corrupt frame: " + status.message();
    Emit(warning);
    return false;
  }
  report_.source_failed = true;
  report_.stop_reason = status.message();
  return true;
}

Status CaptureSession::TakeKeyframe(const Frame& frame, CaptureEvent* event) {
  ++ordinal_;
  const std::string path = (fs::path(images_dir_) / KeyframeName(ordinal_)).string();
  event->kind = CaptureEvent::Kind::kKeyframe;
  event->path = path;
  if (ordinal_ <= on_disk_) {
    event->kept = true;
    ++report_.keyframes_kept;
  } else {
    ExifInfo exif =
        options_.focal_px > 0.0 ? ExifForFocal(frame.width, frame.height, options_.focal_px, "") : ExifInfo{};
    exif.make = "reconar";
    exif.model = report_.source;
    RECONAR_RETURN_IF_ERROR(WriteJpeg(path, frame.rgb, 3, options_.jpeg_quality, BuildExifApp1(exif)));
    ++report_.keyframes;
    report_.keyframe_files.push_back(path);
  }
  if (live_) {
    live_->AddKeyframe(path);
    live_paths_.push_back(path);
  }
  keyframe_registered_.push_back(false);
  return Status::Ok();
}

Result<bool> CaptureSession::Step() {
  if (ended_) return false;
  Result<FrameHandle> next = source_->Next();
  while (!next.ok()) {
    if (EndsTheCapture(next.status())) {
      ended_ = true;
      return false;
    }
    next = source_->Next();
  }
  corrupt_in_a_row_ = 0;
  const Frame& frame = **next;
  if (first_timestamp_ < 0) first_timestamp_ = frame.timestamp_ns;
  ++report_.frames;
  CaptureEvent event;
  event.frame_index = frame.index;
  event.video_seconds = static_cast<double>(frame.timestamp_ns - first_timestamp_) * 1e-9;
  if (replay_ && options_.replay_in_real_time)
    std::this_thread::sleep_until(replay_start_ + std::chrono::duration<double>(event.video_seconds));
  EmitRegistered(event.frame_index, event.video_seconds);
  if (live_) event.registered = live_->NumRegistered();
  if (const Status tracked = FollowMap(frame, &event); !tracked.ok()) {
    return Status(tracked.code(), std::string(frame.name) + ": " + tracked.message());
  }
  GateMapPose map_pose;
  if (event.map_pose_found) {
    map_pose.map_version = event.map_version;
    map_pose.cam_from_world = event.cam_from_world;
    map_pose.points = map_report_.inlier_world_points.data();
    map_pose.num_points = static_cast<int>(map_report_.inlier_world_points.size());
  }
  const auto start = std::chrono::steady_clock::now();
  const Status judged = keyframe_gate_.Process(frame.gray, &event.gate, &map_pose);
  gate_ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  if (!judged.ok()) return Status(judged.code(), std::string(frame.name) + ": " + judged.message());
  if (event.gate.triangulation_angle_deg >= 0.0) ++report_.frames_map_motion;
  switch (event.gate.verdict) {
    case GateVerdict::kBlurred:
      ++report_.blurred;
      break;
    case GateVerdict::kBadExposure:
      ++report_.bad_exposure;
      break;
    case GateVerdict::kTooClose:
      ++report_.too_close;
      break;
    case GateVerdict::kLost:
      ++report_.lost;
      break;
    case GateVerdict::kKeyframe:
      break;
  }
  if (event.gate.verdict == GateVerdict::kKeyframe) {
    RECONAR_RETURN_IF_ERROR(TakeKeyframe(frame, &event));
    Emit(event);
    RECONAR_RETURN_IF_ERROR(WritePreview(frame, event.gate));
    if (!ShowPreview(frame, event.gate, /*taken=*/true)) {
      ended_ = true;
      return false;
    }
    if (options_.max_keyframes > 0 && ordinal_ >= options_.max_keyframes) {
      report_.stop_reason = "--max-keyframes reached";
      ended_ = true;
      return false;
    }
    return true;
  }
  const int second = static_cast<int>(event.video_seconds);
  bool taken = false;
  if (second != last_status_second_) {
    last_status_second_ = second;
    event.kind = CaptureEvent::Kind::kStatus;
    Emit(event);
    RECONAR_RETURN_IF_ERROR(WritePreview(frame, event.gate));
    taken = previewing_;
  } else if (options_.frame_events) {
    event.kind = CaptureEvent::Kind::kFrame;
    Emit(event);
  }
  if (!ShowPreview(frame, event.gate, taken)) {
    ended_ = true;
    return false;
  }
  return true;
}

Result<CaptureReport> CaptureSession::Finish() {
  if (!ended_) report_.stop_reason = "stopped";
  ended_ = true;
  report_.median_gate_ms = Median(gate_ms_);
  report_.median_map_track_ms = Median(map_track_ms_);
  if (live_) {
    // The worker finishes the keyframes it has not reached; its events still reach the caller.
    RECONAR_ASSIGN_OR_RETURN(report_.live_model, live_->Finish());
    report_.live = true;
    EmitRegistered(-1, -1.0);
  }
  // latest.png once more, with every registration the live model made.
  if (!options_.preview_dir.empty() && last_view_.width() > 0) RECONAR_RETURN_IF_ERROR(DrawPreview(nullptr));
  return report_;
}

Result<CaptureReport> RunCapture(const CaptureOptions& options,
                                 const std::function<void(const CaptureEvent&)>& on_event,
                                 const std::atomic<bool>* stop) {
  RECONAR_ASSIGN_OR_RETURN(std::unique_ptr<CaptureSession> session, CaptureSession::Open(options, on_event));
  while (stop == nullptr || !stop->load()) {
    RECONAR_ASSIGN_OR_RETURN(const bool more, session->Step());
    if (!more) break;
  }
  return session->Finish();
}

std::string CaptureEventJson(const CaptureEvent& event) {
  const GateFrameReport& g = event.gate;
  JsonWriter out;
  out.BeginObject();
  out.Key("event").String(event.kind == CaptureEvent::Kind::kKeyframe     ? "keyframe"
                          : event.kind == CaptureEvent::Kind::kWarning    ? "warning"
                          : event.kind == CaptureEvent::Kind::kRegistered ? "registered"
                                                                          : "status");
  out.Key("frame").Int(event.frame_index).Key("video_seconds").Double(event.video_seconds);
  out.Key("frames").Int(event.frames).Key("keyframes").Int(event.keyframes).Key("registered").Int(event.registered);
  if (event.kind == CaptureEvent::Kind::kWarning) {
    out.Key("message").String(event.message);
  } else if (event.kind == CaptureEvent::Kind::kRegistered) {
    out.Key("path").String(event.path);
  } else {
    out.Key("verdict").String(GateVerdictName(g.verdict)).Key("advice").String(g.advice);
    out.Key("sharpness").Double(g.sharpness).Key("sharpness_threshold").Double(g.sharpness_threshold);
    out.Key("mean_level").Double(g.mean_level).Key("dark_level").Double(g.dark_level);
    out.Key("bright_level").Double(g.bright_level).Key("highlights").Double(g.highlight_fraction);
    out.Key("parallax")
        .Double(g.parallax)
        .Key("overlap")
        .Double(g.overlap)
        .Key("frame_motion")
        .Double(g.frame_motion);
  }
  if (event.kind == CaptureEvent::Kind::kKeyframe) out.Key("path").String(event.path).Key("kept").Bool(event.kept);
  if ((event.kind == CaptureEvent::Kind::kStatus || event.kind == CaptureEvent::Kind::kKeyframe) &&
      event.map_version > 0) {
    out.Key("map").BeginObject().Key("version").Int(event.map_version);
    out.Key("state").String(MapTrackingStateName(event.map_state)).Key("inliers").Int(event.map_inliers);
    out.EndObject();
  }
  out.EndObject();
  return out.str();
}

std::string CaptureReportJson(const CaptureReport& report) {
  JsonWriter out;
  out.BeginObject().Key("event").String("end").Key("source").String(report.source);
  out.Key("frames").Int(report.frames).Key("keyframes").Int(report.keyframes);
  out.Key("keyframes_kept").Int(report.keyframes_kept).Key("blurred").Int(report.blurred);
  out.Key("bad_exposure").Int(report.bad_exposure).Key("too_close").Int(report.too_close);
  out.Key("lost").Int(report.lost).Key("corrupt").Int(report.corrupt);
  out.Key("median_gate_ms").Double(report.median_gate_ms).Key("stop_reason").String(report.stop_reason);
  if (report.live) {
    const LiveReconstructionReport& live = report.live_model;
    out.Key("live").BeginObject().Key("registered").Int(live.registered).Key("points").Int(live.points);
    out.Key("median_latency_s").Double(live.median_latency_seconds);
    out.Key("p95_latency_s").Double(live.p95_latency_seconds).EndObject();
    out.Key("map").BeginObject().Key("maps").Int(report.maps_used).Key("frames_posed").Int(report.frames_map_posed);
    out.Key("median_track_ms").Double(report.median_map_track_ms);
    out.Key("frames_baseline_from_map").Int(report.frames_map_motion).EndObject();
  }
  out.EndObject();
  return out.str();
}

}  // namespace reconar
