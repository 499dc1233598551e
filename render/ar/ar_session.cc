#include "render/ar/ar_session.h"

#include <algorithm>
#include <vector>

#include "core/base/median.h"

namespace reconar {

void UseArProject(const ArProject& project, bool camera_given, ArSessionOptions* options) {
  options->pose.layout = project.layout;
  options->map = project.map;
  options->track_tags = project.has_tags;
  if (!camera_given) options->photo_cameras = project.photo_cameras;
}

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

Result<ArSessionReport> ArSession::Run(const std::function<Result<bool>(const ArSession& session)>& each_frame) {
  ArSessionReport report;
  std::vector<double> track_ms;
  for (;;) {
    RECONAR_ASSIGN_OR_RETURN(const bool more, Step());
    if (!more) break;
    if (const TagPoseSource* tag_source = tags()) {
      const TagTrackerFrameReport& tag_report = tag_source->report();
      int measured = 0;
      for (const TrackedTag& tag : tag_report.tags) measured += tag.measured ? 1 : 0;
      report.frames_with_tags += measured > 0 ? 1 : 0;
      report.tag_instances += measured;
      report.predicted_found += tag_report.predicted_found;
      report.predicted_searched += tag_report.predicted_searched;
    }
    ++report.frames_by_source[static_cast<size_t>(sources().source())];
    track_ms.push_back(pose_.track_ms);
    RECONAR_ASSIGN_OR_RETURN(const bool go_on, each_frame(*this));
    if (!go_on) break;
  }
  report.frames = frames_;
  if (!track_ms.empty()) {
    double total = 0.0;
    for (double ms : track_ms) total += ms;
    report.mean_track_ms = total / static_cast<double>(track_ms.size());
    report.max_track_ms = *std::max_element(track_ms.begin(), track_ms.end());
    report.median_track_ms = Median(std::move(track_ms));
  }
  return report;
}

}  // namespace reconar
