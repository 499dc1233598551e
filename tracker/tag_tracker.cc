#include "tracker/tag_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

struct TagTracker::FollowedTag {
  int id = -1;
  TagTrackState state = TagTrackState::kSearching;
  int missed_frames = 0;
  bool measured = false;
  bool reacquired = false;
  bool found_in_region = false;
  // Raw measurements: the last one and, when has_previous, the one in the frame just before it.
  Rigid3 last;
  Rigid3 previous;
  bool has_previous = false;
  // Filter state.
  Rigid3 smoothed;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // translation change per frame
  TagDetection detection;
  TagPose pose;
};

const char* TagTrackStateName(TagTrackState state) {
  switch (state) {
    case TagTrackState::kTracking: return "tracking";
    case TagTrackState::kSearching: return "searching";
    case TagTrackState::kLost: return "lost";
  }
  return "unknown";
}

const char* SearchName(TagTrackerFrameReport::Search search) {
  switch (search) {
    case TagTrackerFrameReport::Search::kRegions: return "regions";
    case TagTrackerFrameReport::Search::kFullFrame: return "full_frame";
    case TagTrackerFrameReport::Search::kRegionsThenFullFrame: return "regions_then_full_frame";
  }
  return "unknown";
}

Status TagTrackerOptions::Check() const {
  RECONAR_RETURN_IF_ERROR(detector.Check());
  if (!(region_max_quad_decimate >= 1.0f) || !std::isfinite(region_max_quad_decimate)) {
    return InvalidArgument("TagTrackerOptions.region_max_quad_decimate must be >= 1");
  }
  if (!(region_min_decimated_edge_px > 0.0) || !std::isfinite(region_min_decimated_edge_px)) {
    return InvalidArgument("TagTrackerOptions.region_min_decimated_edge_px must be > 0");
  }
  if (!intrinsics.valid()) return InvalidArgument("TagTrackerOptions.intrinsics need fx > 0 and fy > 0");
  if (!(tag_size > 0.0) || !std::isfinite(tag_size)) {
    return InvalidArgument("TagTrackerOptions.tag_size must be > 0 (metres), got " + std::to_string(tag_size));
  }
  if (max_tags < 1) return InvalidArgument("TagTrackerOptions.max_tags must be >= 1");
  if (!(region_margin >= 0.0) || region_margin_px < 0) {
    return InvalidArgument("TagTrackerOptions.region_margin and region_margin_px must be >= 0");
  }
  if (lost_after_missed_frames < 1) return InvalidArgument("TagTrackerOptions.lost_after_missed_frames must be >= 1");
  if (full_frame_interval < 0) return InvalidArgument("TagTrackerOptions.full_frame_interval must be >= 0");
  const auto in_unit = [](double v) { return v > 0.0 && v <= 1.0; };
  if (!in_unit(translation_alpha) || !in_unit(rotation_alpha) || !(translation_beta >= 0.0 && translation_beta <= 1.0)) {
    return InvalidArgument("TagTrackerOptions: translation_alpha and rotation_alpha must be in (0, 1], "
                           "translation_beta in [0, 1]");
  }
  return pose.Check();
}

TagTracker::TagTracker(const TagTrackerOptions& options) : options_(options) {}
TagTracker::~TagTracker() = default;

Result<std::unique_ptr<TagTracker>> TagTracker::Create(const TagTrackerOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  std::unique_ptr<TagTracker> tracker(new TagTracker(options));
  RECONAR_ASSIGN_OR_RETURN(tracker->full_detector_, TagDetector::Create(options.detector));
  RECONAR_ASSIGN_OR_RETURN(tracker->region_detector_, TagDetector::Create(options.detector));
  tracker->tracks_.reserve(static_cast<size_t>(options.max_tags));
  // Several tags (and false quads of other ids) may share a region or the frame.
  tracker->scratch_ = TagDetectionList(4 * options.max_tags + 16);
  return tracker;
}

TagTracker::FollowedTag* TagTracker::FindTrack(int id) {
  for (FollowedTag& track : tracks_) {
    if (track.id == id) return &track;
  }
  return nullptr;
}

bool TagTracker::PredictRegion(FollowedTag& track, int width, int height, int region[4],
                               double* shortest_edge_px) const {
  Rigid3 predicted = track.last;
  if (options_.prediction == TagTrackerOptions::Prediction::kConstantVelocity && track.has_previous) {
    const Rigid3 motion = track.last * track.previous.Inverse();  // per frame, in the camera frame
    for (int i = 0; i <= track.missed_frames; ++i) predicted = motion * predicted;
  }
  const std::array<Eigen::Vector3d, 4> corners = TagCornersInTagFrame(options_.tag_size);
  // The box holds the predicted square and the last detected one.
  Eigen::Vector2d lo = track.detection.corners[0];
  Eigen::Vector2d hi = lo;
  Eigen::Vector2d projected[4];
  for (int k = 0; k < 4; ++k) {
    lo = lo.cwiseMin(track.detection.corners[k]);
    hi = hi.cwiseMax(track.detection.corners[k]);
    const Eigen::Vector3d X = predicted * corners[k];
    if (!(X.z() > 0.0)) return false;
    projected[k] = options_.intrinsics.Project(X);
    if (!projected[k].allFinite()) return false;
    lo = lo.cwiseMin(projected[k]);
    hi = hi.cwiseMax(projected[k]);
  }
  *shortest_edge_px = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k) {
    *shortest_edge_px = std::min({*shortest_edge_px, (projected[(k + 1) % 4] - projected[k]).norm(),
                                  (track.detection.corners[(k + 1) % 4] - track.detection.corners[k]).norm()});
  }
  const double margin = options_.region_margin * (hi - lo).maxCoeff() + options_.region_margin_px;
  // Pixel centres sit on integers, so pixel i covers [i - 0.5, i + 0.5]: the box's pixel edges are
  // lo + 0.5 and hi + 0.5 in pixel-index units.
  const double x0 = std::max(0.0, std::floor(lo.x() + 0.5 - margin));
  const double y0 = std::max(0.0, std::floor(lo.y() + 0.5 - margin));
  const double x1 = std::min(static_cast<double>(width), std::ceil(hi.x() + 0.5 + margin));
  const double y1 = std::min(static_cast<double>(height), std::ceil(hi.y() + 0.5 + margin));
  // libapriltag needs a few pixels of white border around the tag; tiny regions cannot hold one.
  constexpr double kMinRegionSide = 16.0;
  if (!(x1 - x0 >= kMinRegionSide && y1 - y0 >= kMinRegionSide)) return false;
  region[0] = static_cast<int>(x0);
  region[1] = static_cast<int>(y0);
  region[2] = static_cast<int>(x1 - x0);
  region[3] = static_cast<int>(y1 - y0);
  return true;
}

void TagTracker::Measure(FollowedTag& track, const TagDetection& detection, bool in_region, double* pose_ms) {
  const Clock::time_point start = Clock::now();
  const Result<TagPose> pose = EstimateTagPose(detection.corners, options_.tag_size, options_.intrinsics,
                                               options_.pose);
  *pose_ms += MillisecondsSince(start);
  if (!pose.ok()) return;  // a degenerate quad: counts as a miss
  const bool restart = track.state == TagTrackState::kLost || track.id < 0 || track.detection.id < 0;
  track.reacquired = track.state == TagTrackState::kLost;
  track.measured = true;
  track.found_in_region = in_region;
  track.detection = detection;
  track.pose = *pose;
  const Rigid3& measured = pose->cam_from_tag;
  if (restart) {
    track.smoothed = measured;
    track.velocity.setZero();
    track.has_previous = false;
  } else {
    track.has_previous = track.missed_frames == 0;
    track.previous = track.last;
    // Alpha-beta filter (the prediction step ran at the start of the frame).
    const Eigen::Vector3d residual = measured.translation - track.smoothed.translation;
    track.smoothed.translation += options_.translation_alpha * residual;
    track.velocity += options_.translation_beta * residual;
    const Eigen::Quaterniond from(track.smoothed.rotation);
    const Eigen::Quaterniond to(measured.rotation);
    track.smoothed.rotation = from.slerp(options_.rotation_alpha, to).normalized().toRotationMatrix();
  }
  track.last = measured;
  track.missed_frames = 0;
  track.state = TagTrackState::kTracking;
}

Status TagTracker::Track(ImageView<const uint8_t> image, TagTrackerFrameReport* report) {
  const Clock::time_point start = Clock::now();
  if (image.empty()) return InvalidArgument("TagTracker: empty frame");
  if (image.width != width_ || image.height != height_) {
    tracks_.clear();
    width_ = image.width;
    height_ = image.height;
  }
  ++frame_index_;
  report->frame_index = frame_index_;
  report->regions_searched = 0;
  report->detections = 0;
  report->tags_dropped = 0;
  report->detect_ms = 0.0;
  report->pose_ms = 0.0;

  bool any_followed = false;
  for (FollowedTag& track : tracks_) {
    track.measured = false;
    track.reacquired = false;
    track.found_in_region = false;
    if (track.state != TagTrackState::kLost) {
      any_followed = true;
      track.smoothed.translation += track.velocity;  // alpha-beta prediction
    }
  }
  const bool periodic = options_.full_frame_interval > 0 && frame_index_ % options_.full_frame_interval == 0;
  bool search_full_frame = !any_followed || periodic;
  report->search = TagTrackerFrameReport::Search::kFullFrame;
  if (!search_full_frame) {
    report->search = TagTrackerFrameReport::Search::kRegions;
    for (FollowedTag& track : tracks_) {
      if (track.state == TagTrackState::kLost || track.measured) continue;
      int region[4];
      double shortest_edge_px = 0.0;
      if (PredictRegion(track, image.width, image.height, region, &shortest_edge_px)) {
        const float decimate = std::clamp(
            static_cast<float>(std::floor(shortest_edge_px / options_.region_min_decimated_edge_px)),
            options_.detector.quad_decimate, std::max(options_.detector.quad_decimate, options_.region_max_quad_decimate));
        region_detector_->SetQuadDecimate(decimate);
        const Clock::time_point detect_start = Clock::now();
        RECONAR_RETURN_IF_ERROR(
            region_detector_->DetectInRegion(image, region[0], region[1], region[2], region[3], &scratch_));
        report->detect_ms += MillisecondsSince(detect_start);
        ++report->regions_searched;
        report->detections += scratch_.size();
        for (const TagDetection& detection : scratch_) {
          FollowedTag* owner = FindTrack(detection.id);
          if (owner != nullptr && !owner->measured && owner->state != TagTrackState::kLost) {
            Measure(*owner, detection, true, &report->pose_ms);
          }
        }
      }
      if (!track.measured) search_full_frame = true;
    }
    if (search_full_frame) report->search = TagTrackerFrameReport::Search::kRegionsThenFullFrame;
  }
  if (search_full_frame) {
    const Clock::time_point detect_start = Clock::now();
    RECONAR_RETURN_IF_ERROR(full_detector_->Detect(image, &scratch_));
    report->detect_ms += MillisecondsSince(detect_start);
    report->detections += scratch_.size();
    for (const TagDetection& detection : scratch_) {
      FollowedTag* track = FindTrack(detection.id);
      if (track == nullptr) {
        if (static_cast<int>(tracks_.size()) >= options_.max_tags) {
          ++report->tags_dropped;
          continue;
        }
        tracks_.emplace_back();
        track = &tracks_.back();
        track->detection.id = -1;  // marks a new track for Measure
      }
      if (!track->measured) Measure(*track, detection, false, &report->pose_ms);
      if (track->id < 0) {
        if (track->measured) {
          track->id = detection.id;
        } else {
          tracks_.pop_back();  // its pose failed: not followed
        }
      }
    }
  }

  report->tags.clear();
  if (report->tags.capacity() < static_cast<size_t>(options_.max_tags)) {
    report->tags.reserve(static_cast<size_t>(options_.max_tags));
  }
  for (FollowedTag& track : tracks_) {
    if (!track.measured) {
      ++track.missed_frames;
      if (track.state != TagTrackState::kLost) {
        track.state = track.missed_frames >= options_.lost_after_missed_frames ? TagTrackState::kLost
                                                                               : TagTrackState::kSearching;
      }
    }
    TrackedTag out;
    out.id = track.id;
    out.state = track.state;
    out.measured = track.measured;
    out.reacquired = track.reacquired;
    out.found_in_region = track.found_in_region;
    out.missed_frames = track.missed_frames;
    out.detection = track.detection;
    out.pose = track.pose;
    out.cam_from_tag = track.last;
    out.smoothed_cam_from_tag = track.smoothed;
    report->tags.push_back(out);
  }
  report->total_ms = MillisecondsSince(start);
  return Status::Ok();
}

}  // namespace reconar
