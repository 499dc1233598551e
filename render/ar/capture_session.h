#pragma once
// `reconar capture`'s loop (issue 18): frames from a source (live camera, folder, recording) through
// the keyframe gate (tracker/keyframe_gate.h); each keyframe written atomically as
// PROJECT/images/keyframe_NNNNN.jpg with EXIF (core/io/exif.h: the focal when it is known), so any
// tool reads them; events for the person holding the camera (a status each second of video, each
// keyframe, warnings, the end).
//
// Stopping and resuming. A keyframe is on disk whole or not at all, so a crash or SIGKILL loses at
// most the frame in flight. A folder or a recording is replayed from its start on a re-run: the
// gate is deterministic, so it takes the same keyframes, and those already on disk are kept, not
// written again; the run then goes on past them. A live camera's keyframes are numbered on after
// the last one on disk.
#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/pipeline/live_reconstruction.h"
#include "platform/camera/frame_source.h"
#include "tracker/keyframe_gate.h"
#include "tracker/map_follower.h"
#include "tracker/map_tracker.h"
#include "tracker/tag_detector.h"

namespace reconar {

struct CaptureOptions {
  CaptureOptions();
  std::string source;  // OpenFrameSource specification
  FrameSourceOptions source_options;
  std::string project_dir;
  KeyframeGateOptions gate;
  int max_keyframes = 0;  // stop after this many keyframes in all (those kept included); 0: no limit
  int jpeg_quality = 92;
  double focal_px = 0.0;  // > 0: written into each keyframe's EXIF (ExifForFocal)
  // Corrupt frames in a row (a damaged recording) after which the capture stops.
  int max_corrupt_frames_in_a_row = 25;
  // The sparse model grown in the background from the keyframes (live_reconstruction.h).
  bool reconstruct_live = true;
  LiveReconstructionOptions live;
  // Follow the camera against the live model (its localisation map, rebuilt when the model starts
  // and at its global adjustments: LiveReconstructionOptions::publish_map): each frame's pose in
  // the model's frame. map_tracker.intrinsics is the model's camera, scaled to the frame. A live
  // camera is followed against the newest map; a replay against the newest built from all
  // keyframes but the last map_lag_keyframes, waiting for the worker to get there, so that its
  // frames meet the same maps, and get the same poses, on every run.
  bool track_map = true;
  int map_lag_keyframes = 1;
  MapTrackerOptions map_tracker;
  // A kFrame event for every frame no other event reports (for a caller that wants every pose).
  bool frame_events = false;
  // A folder or recording replayed at the pace of its timestamps, as a camera would deliver it
  // (for measuring the live model's latency); false: as fast as the gate goes.
  bool replay_in_real_time = false;
  // Not empty: a preview (capture_preview.h) of each keyframe and of one frame per second of video,
  // written there as preview_FFFFFF.png (F the frame index) and latest.png.
  std::string preview_dir;
  std::string preview_tag_family = "tag36h11";  // tags outlined in the preview; "" none
  // Set: the preview of every frame is shown through it (a window: render/ar/capture_window.h), on
  // the capturing thread. It returns false when the person asked to stop (the capture then ends as
  // on SIGINT), an error when it can no longer show (the capture ends as when a camera
  // disconnects: what was captured stays).
  std::function<Result<bool>(const Image<uint8_t>& rgb)> show_preview;

  Status Check() const;
};

struct CaptureEvent {
  enum class Kind { kStatus, kKeyframe, kRegistered, kWarning, kFrame };
  Kind kind = Kind::kStatus;
  int64_t frame_index = 0;
  double video_seconds = 0.0;  // the frame's timestamp since the first frame
  GateFrameReport gate;        // the frame's judgement (kStatus, kKeyframe)
  std::string path;            // the keyframe's file (kKeyframe, kRegistered)
  bool kept = false;           // the keyframe was already on disk (a resumed replay)
  std::string message;         // kWarning
  int frames = 0, keyframes = 0;
  int registered = 0;  // keyframes in the live model
  // The frame against the live model's map (kStatus, kKeyframe, kFrame; map_version 0: no map yet).
  int map_version = 0;
  MapTrackingState map_state = MapTrackingState::kLost;
  bool map_pose_found = false;
  Rigid3 cam_from_world;  // in the live model's frame, when map_pose_found
  int map_inliers = 0;
};

struct CaptureReport {
  std::string source;  // the source's Describe()
  int frames = 0;
  int keyframes = 0;       // in PROJECT/images at the end
  int keyframes_kept = 0;  // of which already there from an earlier run
  int blurred = 0, bad_exposure = 0, too_close = 0, lost = 0, corrupt = 0;
  double median_gate_ms = 0.0;
  // "end of the recording", "--max-keyframes reached", "stopped", "window closed", or the source's
  // or the window's error.
  std::string stop_reason;
  bool source_failed = false;  // the source ended with an error (a camera that disconnected)
  bool window_failed = false;  // CaptureOptions::show_preview ended with an error (a display that went away)
  std::vector<std::string> keyframe_files;
  int previews = 0;   // pictures written to CaptureOptions::preview_dir
  // Following the live model's map (CaptureOptions::track_map): frames posed, maps used, the
  // median time per frame tracked (relocalisations included).
  int frames_map_posed = 0;
  int frames_map_motion = 0;  // whose baseline the gate measured from the map poses
  int maps_used = 0;
  double median_map_track_ms = 0.0;
  // The capturing thread's time to take up a new map (the tracker made for it), largest and total:
  // a frame that waits for it is late.
  double max_map_switch_ms = 0.0;
  double total_map_switch_ms = 0.0;
  bool live = false;  // CaptureOptions::reconstruct_live: `live_model` holds the live model's report
  LiveReconstructionReport live_model;
};

// The capture, a frame at a time (the shape of ArSession, render/ar/ar_session.h):
//
//   RECONAR_ASSIGN_OR_RETURN(auto session, CaptureSession::Open(options, on_event));
//   for (;;) {
//     RECONAR_ASSIGN_OR_RETURN(const bool more, session->Step());
//     if (!more) break;
//   }
//   RECONAR_ASSIGN_OR_RETURN(const CaptureReport report, session->Finish());
//
// Events reach on_event from Step() and Finish() on the caller's thread.
class CaptureSession {
 public:
  // Errors: bad options, a source that cannot be opened, a project directory that cannot be made.
  static Result<std::unique_ptr<CaptureSession>> Open(const CaptureOptions& options,
                                                      std::function<void(const CaptureEvent&)> on_event);
  ~CaptureSession();

  // The next frame through the gate (and against the live model's map). False when the capture
  // has ended: the source ended or failed, max_keyframes were reached, or the window closed
  // (report().stop_reason says which). Errors: a keyframe that cannot be written (full disk: the
  // file is named, the earlier keyframes are intact), a tracking error naming the frame.
  Result<bool> Step();

  // Ends the capture (stop_reason "stopped" when Step() had not ended it): the live model finishes
  // the keyframes it has not reached, its registrations are reported, the last preview is drawn.
  Result<CaptureReport> Finish();

  const CaptureReport& report() const { return report_; }

 private:
  explicit CaptureSession(const CaptureOptions& options);
  void Emit(CaptureEvent event) const;
  void EmitRegistered(int64_t frame_index, double video_seconds);
  Status FollowMap(const Frame& frame, CaptureEvent* event);
  // True when the source's error ends the capture (report_.stop_reason says why); false for a
  // corrupt frame that is skipped (a warning event says so).
  bool EndsTheCapture(const Status& source_error);
  Status TakeKeyframe(const Frame& frame, CaptureEvent* event);
  void DrawOverlay();
  Status DrawPreview(const char* name);
  void TakeView(const Frame& frame, const GateFrameReport& gate, bool find_tags);
  Status WritePreview(const Frame& frame, const GateFrameReport& gate);
  bool ShowPreview(const Frame& frame, const GateFrameReport& gate, bool taken);

  CaptureOptions options_;
  std::function<void(const CaptureEvent&)> on_event_;
  std::string images_dir_;
  std::unique_ptr<FrameSource> source_;
  CaptureReport report_;
  bool ended_ = false;
  bool replay_ = false;
  int on_disk_ = 0;   // keyframes found in images_dir_ at Open
  int ordinal_ = 0;   // of the last keyframe taken or met again
  std::unique_ptr<LiveReconstruction> live_;
  std::vector<std::string> live_paths_;    // in the order given to live_
  std::vector<bool> keyframe_registered_;  // in the same order
  KeyframeGate keyframe_gate_;
  MapFollower map_follower_;
  MapTrackerFrameReport map_report_;
  std::vector<double> map_track_ms_, gate_ms_;
  std::chrono::steady_clock::time_point replay_start_;
  std::unique_ptr<TagDetector> tag_detector_;
  TagDetectionList tags_in_view_;
  std::vector<std::array<Eigen::Vector2d, 4>> last_tags_;
  bool previewing_ = false;
  Image<uint8_t> last_view_, preview_;  // the last frame previewed, and with the overlay drawn
  GateVerdict last_verdict_ = GateVerdict::kTooClose;
  const char* last_advice_ = "";
  int corrupt_in_a_row_ = 0;
  std::string last_damage_;
  int64_t first_timestamp_ = -1;
  int last_status_second_ = -1;
};

// Opens a CaptureSession and steps it until it ends or *stop becomes true (SIGINT), then Finish().
// A source that fails ends the capture with the report saying so (what was captured stays).
Result<CaptureReport> RunCapture(const CaptureOptions& options,
                                 const std::function<void(const CaptureEvent&)>& on_event,
                                 const std::atomic<bool>* stop = nullptr);

// One line of `reconar capture --json`: an event, and the capture's end with its report.
std::string CaptureEventJson(const CaptureEvent& event);
std::string CaptureReportJson(const CaptureReport& report);

}  // namespace reconar
