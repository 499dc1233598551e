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
  bool found_by_prediction = false;
  // State and missed count at the start of the frame (SearchPredicted undoes the frame's miss).
  TagTrackState state_at_start = TagTrackState::kSearching;
  int missed_at_start = 0;
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
  if (!(predicted_min_edge_px >= 0.0) || !std::isfinite(predicted_min_edge_px)) {
    return InvalidArgument("TagTrackerOptions.predicted_min_edge_px must be >= 0");
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
  // The box holds the predicted square and the last detected one.
  return SquareRegion(predicted, track.detection.corners, width, height, region, shortest_edge_px, nullptr);
}

bool TagTracker::SquareRegion(const Rigid3& cam_from_tag, const Eigen::Vector2d* last_corners, int width, int height,
                              int region[4], double* shortest_edge_px, bool* in_view) const {
  const std::array<Eigen::Vector3d, 4> corners = TagCornersInTagFrame(options_.tag_size);
  Eigen::Vector2d projected[4];
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d X = cam_from_tag * corners[k];
    if (!(X.z() > 0.0)) return false;
    projected[k] = options_.intrinsics.Project(X);
    if (!projected[k].allFinite()) return false;
    if (in_view != nullptr) {
      *in_view = (X.head<2>() / X.z()).squaredNorm() <= options_.intrinsics.Camera().FoldRadiusSquared();
      if (!*in_view) return false;
    }
  }
  Eigen::Vector2d lo = projected[0];
  Eigen::Vector2d hi = lo;
  *shortest_edge_px = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k) {
    lo = lo.cwiseMin(projected[k]);
    hi = hi.cwiseMax(projected[k]);
    *shortest_edge_px = std::min(*shortest_edge_px, (projected[(k + 1) % 4] - projected[k]).norm());
    if (last_corners != nullptr) {
      lo = lo.cwiseMin(last_corners[k]);
      hi = hi.cwiseMax(last_corners[k]);
      *shortest_edge_px = std::min(*shortest_edge_px, (last_corners[(k + 1) % 4] - last_corners[k]).norm());
    }
  }
  const double margin = options_.region_margin * (hi - lo).maxCoeff() + options_.region_margin_px;
  if (in_view != nullptr) {
    // The whole box in the frame, up to the margin (the error the prediction may have).
    *in_view = lo.x() >= -0.5 - margin && lo.y() >= -0.5 - margin && hi.x() <= width - 0.5 + margin &&
               hi.y() <= height - 0.5 + margin;
  }
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

float TagTracker::RegionDecimate(double shortest_edge_px, float min_decimate) const {
  return std::clamp(static_cast<float>(std::floor(shortest_edge_px / options_.region_min_decimated_edge_px)),
                    min_decimate, std::max(min_decimate, options_.region_max_quad_decimate));
}

Status TagTracker::DetectRegion(ImageView<const uint8_t> image, const int region[4], float decimate,
                                TagTrackerFrameReport* report) {
  region_detector_->SetQuadDecimate(decimate);
  const Clock::time_point detect_start = Clock::now();
  RECONAR_RETURN_IF_ERROR(
      region_detector_->DetectInRegion(image, region[0], region[1], region[2], region[3], &scratch_));
  report->detect_ms += MillisecondsSince(detect_start);
  report->detections += scratch_.size();
  return Status::Ok();
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
  report->predicted_searched = 0;
  report->predicted_found = 0;
  report->detect_ms = 0.0;
  report->pose_ms = 0.0;

  bool any_followed = false;
  for (FollowedTag& track : tracks_) {
    track.measured = false;
    track.reacquired = false;
    track.found_in_region = false;
    track.found_by_prediction = false;
    track.state_at_start = track.state;
    track.missed_at_start = track.missed_frames;
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
        RECONAR_RETURN_IF_ERROR(
            DetectRegion(image, region, RegionDecimate(shortest_edge_px, options_.detector.quad_decimate), report));
        ++report->regions_searched;
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
        StartTrack(detection, false, report);
      } else if (!track->measured) {
        Measure(*track, detection, false, &report->pose_ms);
      }
    }
  }

  for (FollowedTag& track : tracks_) {
    if (!track.measured) {
      ++track.missed_frames;
      if (track.state != TagTrackState::kLost) {
        track.state = track.missed_frames >= options_.lost_after_missed_frames ? TagTrackState::kLost
                                                                               : TagTrackState::kSearching;
      }
    }
  }
  FillReport(report);
  report->total_ms = MillisecondsSince(start);
  return Status::Ok();
}

TagTracker::FollowedTag* TagTracker::StartTrack(const TagDetection& detection, bool in_region,
                                                TagTrackerFrameReport* report) {
  FollowedTag* slot = nullptr;
  if (static_cast<int>(tracks_.size()) < options_.max_tags) {
    tracks_.emplace_back();
    slot = &tracks_.back();
  } else {
    for (FollowedTag& track : tracks_) {
      if (track.state == TagTrackState::kLost && (slot == nullptr || track.missed_frames > slot->missed_frames)) {
        slot = &track;
      }
    }
    if (slot == nullptr) {
      ++report->tags_dropped;
      return nullptr;
    }
  }
  const FollowedTag replaced = *slot;  // fixed-size, no heap
  *slot = FollowedTag();
  slot->detection.id = -1;  // marks a new track for Measure
  Measure(*slot, detection, in_region, &report->pose_ms);
  if (slot->measured) {
    slot->id = detection.id;
    return slot;
  }
  // Its pose failed: not followed.
  if (replaced.id < 0) {
    tracks_.pop_back();
  } else {
    *slot = replaced;
  }
  return nullptr;
}

void TagTracker::FillReport(TagTrackerFrameReport* report) const {
  report->tags.clear();
  if (report->tags.capacity() < static_cast<size_t>(options_.max_tags)) {
    report->tags.reserve(static_cast<size_t>(options_.max_tags));
  }
  for (const FollowedTag& track : tracks_) {
    TrackedTag out;
    out.id = track.id;
    out.state = track.state;
    out.measured = track.measured;
    out.reacquired = track.reacquired;
    out.found_in_region = track.found_in_region;
    out.found_by_prediction = track.found_by_prediction;
    out.missed_frames = track.missed_frames;
    out.detection = track.detection;
    out.pose = track.pose;
    out.cam_from_tag = track.last;
    out.smoothed_cam_from_tag = track.smoothed;
    report->tags.push_back(out);
  }
}

Status TagTracker::SearchPredicted(ImageView<const uint8_t> image, const PredictedTag* tags, int count,
                                   TagTrackerFrameReport* report) {
  const Clock::time_point start = Clock::now();
  if (count < 0 || (count > 0 && tags == nullptr)) {
    return InvalidArgument("TagTracker::SearchPredicted: count must be >= 0 with the tags given");
  }
  if (count == 0) return Status::Ok();
  if (image.empty() || image.width != width_ || image.height != height_) {
    return InvalidArgument("TagTracker::SearchPredicted: the frame is not the one of the last Track (" +
                           std::to_string(image.width) + "x" + std::to_string(image.height) + ")");
  }
  const auto measured = [this](int id) {
    const FollowedTag* track = FindTrack(id);
    return track != nullptr && track->measured;
  };
  const auto predicted = [&](int id) {
    for (int i = 0; i < count; ++i) {
      if (tags[i].id == id) return true;
    }
    return false;
  };
  const bool full_frame_searched = report->search != TagTrackerFrameReport::Search::kRegions;
  bool any_found = false;
  for (int i = 0; i < count; ++i) {
    const PredictedTag& tag = tags[i];
    if (tag.id < 0 || measured(tag.id)) continue;
    // The printed side faces the camera: its z axis points back toward the camera centre.
    if (!(tag.cam_from_tag.rotation.col(2).dot(tag.cam_from_tag.translation) < 0.0)) continue;
    int region[4];
    double shortest_edge_px = 0.0;
    bool in_view = false;
    if (!SquareRegion(tag.cam_from_tag, nullptr, image.width, image.height, region, &shortest_edge_px, &in_view) ||
        !in_view || !(shortest_edge_px >= options_.predicted_min_edge_px)) {
      continue;
    }
    // A full-frame search of this frame already looked there at the region's resolution or finer.
    const float decimate = RegionDecimate(shortest_edge_px, 1.0f);
    if (full_frame_searched && options_.detector.quad_decimate <= decimate) continue;
    RECONAR_RETURN_IF_ERROR(DetectRegion(image, region, decimate, report));
    ++report->predicted_searched;
    for (const TagDetection& detection : scratch_) {
      if (!predicted(detection.id)) continue;
      FollowedTag* track = FindTrack(detection.id);
      if (track == nullptr) {
        track = StartTrack(detection, true, report);
      } else if (!track->measured) {
        // Undo this frame's miss (Track counted it), measure, or count the miss again.
        const TagTrackState state = track->state;
        const int missed = track->missed_frames;
        track->state = track->state_at_start;
        track->missed_frames = track->missed_at_start;
        Measure(*track, detection, true, &report->pose_ms);
        if (!track->measured) {
          track->state = state;
          track->missed_frames = missed;
        }
      } else {
        continue;
      }
      if (track != nullptr && track->measured) {
        track->found_by_prediction = true;
        ++report->predicted_found;
        any_found = true;
      }
    }
  }
  if (any_found) FillReport(report);
  report->total_ms += MillisecondsSince(start);
  return Status::Ok();
}

}  // namespace reconar
