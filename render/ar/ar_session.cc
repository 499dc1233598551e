#include "render/ar/ar_session.h"

#include "render/ar/ar_project.h"

namespace reconar {

Result<std::unique_ptr<ArSession>> ArSession::Open(const ArSessionOptions& options) {
  std::unique_ptr<ArSession> session(new ArSession());
  session->max_frames_ = options.max_frames;
  RECONAR_ASSIGN_OR_RETURN(session->source_, OpenFrameSource(options.source, options.frames));
  Result<FrameHandle> first = session->source_->Next();
  if (!first.ok()) {
    if (IsEndOfStream(first.status())) return FailedPrecondition(options.source + ": no frames");
    return first.status();
  }
  session->frame_ = std::move(*first);
  session->first_frame_pending_ = true;
  session->width_ = session->frame_->width;
  session->height_ = session->frame_->height;
  FusedPoseSourceOptions pose_options;
  pose_options.tags = options.pose;
  if (!options.photo_cameras.empty()) {
    RECONAR_ASSIGN_OR_RETURN(pose_options.tags.tracker.intrinsics,
                             PhotoCameraForFrame(options.photo_cameras, session->width_, session->height_));
  }
  session->map_ = options.map;
  pose_options.map = session->map_.get();
  pose_options.track_tags = options.track_tags;
  pose_options.map_tracking = options.map_tracking;
  RECONAR_ASSIGN_OR_RETURN(session->pose_source_, FusedPoseSource::Create(pose_options));
  return session;
}

ArSession::~ArSession() = default;

Result<bool> ArSession::Step() {
  if (max_frames_ > 0 && frames_ >= max_frames_) return false;
  if (first_frame_pending_) {
    first_frame_pending_ = false;
  } else {
    frame_.reset();  // give the buffer back before asking for the next
    Result<FrameHandle> next = source_->Next();
    if (!next.ok()) {
      if (IsEndOfStream(next.status())) return false;
      return next.status();
    }
    frame_ = std::move(*next);
  }
  frame_start_ = std::chrono::steady_clock::now();
  if (Status s = pose_source_->Track(frame_->gray, &pose_); !s.ok()) return s.WithContext(std::string(frame_->name));
  ++frames_;
  return true;
}

}  // namespace reconar
