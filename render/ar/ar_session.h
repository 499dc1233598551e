#pragma once
// ArSession: the AR runtime's loop over a video, joining a FrameSource (platform/camera) and the
// pose source (tracker/fused_pose_source.h: the tags, and a project's map when one is given; a
// project without tags: its map alone). Open() opens the source, reads the first frame (its size
// fixes the camera's), takes the project's camera for that size when asked, and creates the pose
// source.
// Each Step() gives the previous frame back, takes the next one and finds its pose:
//
//   RECONAR_ASSIGN_OR_RETURN(auto session, ArSession::Open(options));
//   for (;;) {
//     RECONAR_ASSIGN_OR_RETURN(const bool more, session->Step());
//     if (!more) break;
//     use(session->frame(), session->pose(), session->sources());
//   }
//
// Run() is that loop, with each frame handed to a callback and the run's statistics
// (ArSessionReport) gathered: `reconar track` prints what each frame found; `reconar view`
// (render/ar/ar_view.h) draws it. The frame is held (its FrameHandle) until the next Step() or the
// session's end. Steady-state Step() makes no heap allocation of its own (the source's and the
// pose source's guarantees).
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/sfm/localization_map.h"
#include "platform/camera/frame_source.h"
#include "render/ar/ar_project.h"
#include "tracker/fused_pose_source.h"
#include "tracker/pose_source.h"
#include "tracker/tag_pose_source.h"

namespace reconar {

struct ArSessionOptions {
  std::string source;  // OpenFrameSource specification
  FrameSourceOptions frames;
  TagPoseSourceOptions pose;
  // Non-empty (a project's cameras, ArProject::photo_cameras): the camera is the one of the video's
  // frame size (PhotoCameraForFrame, render/ar/ar_project.h) instead of pose.tracker.intrinsics.
  std::vector<CameraIntrinsics> photo_cameras;
  // A project's localisation map (in the world frame of pose.layout): frames are also posed from
  // it, and without tags in view by it alone. nullptr: tags only.
  std::shared_ptr<const LocalizationMap> map;
  // false (a project without tags): no tag is searched, the map alone poses the frames in its own
  // frame; only pose.tracker.intrinsics of `pose` is used. Needs a map.
  bool track_tags = true;
  MapTrackerOptions map_tracking;  // its intrinsics are the tags' (scaled with them)
  int max_frames = 0;  // Step() ends after this many frames (0: at the end of the stream)
};

// What Run() saw over the frames.
struct ArSessionReport {
  long frames = 0;
  // Tags measured (tracked tags only): frames with at least one, and over all frames; of those,
  // the ones found where a layout's pose predicted them, and the regions searched so.
  long frames_with_tags = 0;
  long tag_instances = 0;
  long predicted_found = 0;
  long predicted_searched = 0;
  PoseSourceCounts frames_by_source{};  // frames by the source of their pose (FusedPoseSource)
  // Tracking time per frame (WorldPose::track_ms), milliseconds.
  double mean_track_ms = 0.0;
  double median_track_ms = 0.0;  // the upper median
  double max_track_ms = 0.0;
};

// A project's tags (its layout; track_tags as it has them), its map, and unless `camera_given`
// (--intrinsics) its photos' cameras.
void UseArProject(const ArProject& project, bool camera_given, ArSessionOptions* options);

class ArSession {
 public:
  // Errors of the source, "SOURCE: no frames" (FailedPrecondition) for an empty stream, errors of
  // PhotoCameraForFrame and of FusedPoseSource::Create.
  static Result<std::unique_ptr<ArSession>> Open(const ArSessionOptions& options);
  ~ArSession();

  // True with the next frame and its pose; false at the end of the stream or after max_frames.
  // A tracking error names the frame.
  Result<bool> Step();
  // Step() until the stream ends, max_frames, or `each_frame` (called after every frame with the
  // session: the frame, its pose and its sources) says false or fails (its error is returned).
  Result<ArSessionReport> Run(const std::function<Result<bool>(const ArSession& session)>& each_frame);

  const Frame& frame() const { return *frame_; }
  const WorldPose& pose() const { return pose_; }
  // The tags of the frame; nullptr when tags are not tracked (track_tags false).
  const TagPoseSource* tags() const { return pose_source_->tags(); }
  // Which sources posed the frame, and the map tracker's report.
  const FusedPoseSource& sources() const { return *pose_source_; }
  const CameraIntrinsics& intrinsics() const { return pose_source_->options().tags.tracker.intrinsics; }
  // Whether the world's units are metres: tags, or a map in a tag's metric frame. False for a
  // project without tags: poses are in the model's own, arbitrary units.
  bool metric() const { return map_ == nullptr || map_->metric; }
  int width() const { return width_; }  // of the first frame
  int height() const { return height_; }
  long frames() const { return frames_; }  // frames stepped through so far
  // When the current frame had been read (and its tracking began).
  std::chrono::steady_clock::time_point frame_start() const { return frame_start_; }
  std::string Describe() const { return source_->Describe(); }

 private:
  ArSession() = default;

  int max_frames_ = 0;
  std::unique_ptr<FrameSource> source_;  // outlives frame_ (members are destroyed in reverse order)
  FrameHandle frame_;
  bool first_frame_pending_ = false;
  std::shared_ptr<const LocalizationMap> map_;  // outlives pose_source_
  std::unique_ptr<FusedPoseSource> pose_source_;
  WorldPose pose_;
  int width_ = 0;
  int height_ = 0;
  long frames_ = 0;
  std::chrono::steady_clock::time_point frame_start_;
};

}  // namespace reconar
