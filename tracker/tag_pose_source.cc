#include "tracker/tag_pose_source.h"

#include <algorithm>

namespace reconar {

Status TagPoseSourceOptions::Check() const {
  RECONAR_RETURN_IF_ERROR(tracker.Check());
  if (tag_id < -1) return InvalidArgument("tag pose source: tag_id must be >= -1, got " + std::to_string(tag_id));
  return Status::Ok();
}

Result<std::unique_ptr<TagPoseSource>> TagPoseSource::Create(const TagPoseSourceOptions& requested) {
  RECONAR_RETURN_IF_ERROR(requested.Check());
  TagPoseSourceOptions options = requested;
  // Every layout tag can be followed at once (a room's 20 tags seen in turn keep more than 16
  // tracks searching; a new one would be dropped).
  options.tracker.max_tags = std::max(options.tracker.max_tags, static_cast<int>(options.layout.tags().size()));
  RECONAR_ASSIGN_OR_RETURN(std::unique_ptr<TagTracker> tracker, TagTracker::Create(options.tracker));
  return std::unique_ptr<TagPoseSource>(new TagPoseSource(options, std::move(tracker)));
}

TagPoseSource::TagPoseSource(const TagPoseSourceOptions& options, std::unique_ptr<TagTracker> tracker)
    : options_(options), tracker_(std::move(tracker)), measured_(options.tracker.max_tags) {
  predicted_.reserve(options_.layout.tags().size());
}

Status TagPoseSource::Track(ImageView<const uint8_t> gray, WorldPose* pose) { return Track(gray, nullptr, pose); }

Status TagPoseSource::Track(ImageView<const uint8_t> gray, const Rigid3* prior_cam_from_world, WorldPose* pose) {
  RECONAR_RETURN_IF_ERROR(tracker_->Track(gray, &report_));
  ResetPose(pose);
  if (options_.layout.empty()) {
    PoseFromOneTag(pose);
  } else {
    PoseFromLayout(pose);
    const Rigid3* cam_from_world = has_board_ ? &board_.cam_from_layout : prior_cam_from_world;
    if (options_.predict_layout_tags && cam_from_world != nullptr) {
      RECONAR_RETURN_IF_ERROR(SearchLayoutTags(gray, *cam_from_world));
      if (report_.predicted_found > 0) {
        ResetPose(pose);
        PoseFromLayout(pose);
      }
    }
  }
  pose->track_ms = report_.total_ms;
  return Status::Ok();
}

void TagPoseSource::ResetPose(WorldPose* pose) const {
  pose->found = false;
  pose->anchors_used = 0;
  pose->rms_reprojection_px = 0.0;
  if (pose->markers.capacity() < static_cast<size_t>(options_.tracker.max_tags)) {
    pose->markers.reserve(static_cast<size_t>(options_.tracker.max_tags));
  }
  pose->markers.clear();
}

Status TagPoseSource::SearchLayoutTags(ImageView<const uint8_t> gray, const Rigid3& cam_from_world) {
  predicted_.clear();
  for (const LayoutTag& tag : options_.layout.tags()) {
    const bool measured = std::any_of(report_.tags.begin(), report_.tags.end(),
                                      [&](const TrackedTag& t) { return t.measured && t.id == tag.id; });
    if (measured) continue;
    PredictedTag predicted;
    predicted.id = tag.id;
    predicted.cam_from_tag = cam_from_world * tag.layout_from_tag;
    predicted_.push_back(predicted);  // within the capacity reserved for every layout tag
  }
  return tracker_->SearchPredicted(gray, predicted_.data(), static_cast<int>(predicted_.size()), &report_);
}

void TagPoseSource::PoseFromLayout(WorldPose* pose) {
  has_board_ = false;
  measured_.Clear();
  for (const TrackedTag& tag : report_.tags) {
    if (tag.measured) measured_.Add(tag.detection);
  }
  if (measured_.empty()) return;  // no pose, and no error message built (it would allocate)
  auto board = EstimateBoardPose(options_.layout, measured_, options_.tracker.intrinsics, options_.board);
  if (!board.ok()) return;
  board_ = *board;
  has_board_ = true;
  pose->found = true;
  pose->cam_from_world = board_.cam_from_layout;
  pose->anchors_used = board_.tags_used;
  pose->rms_reprojection_px = board_.rms_reprojection_px;
  for (const LayoutTag& tag : options_.layout.tags()) {
    const bool seen = std::any_of(measured_.begin(), measured_.end(),
                                  [&](const TagDetection& detection) { return detection.id == tag.id; });
    if (seen && pose->markers.size() < pose->markers.capacity()) pose->markers.push_back(tag);
  }
}

void TagPoseSource::PoseFromOneTag(WorldPose* pose) const {
  const TrackedTag* chosen = nullptr;
  for (const TrackedTag& tag : report_.tags) {
    if (tag.state == TagTrackState::kLost || !tag.measured) continue;
    if (options_.tag_id >= 0 && tag.id != options_.tag_id) continue;
    if (chosen == nullptr || tag.id < chosen->id) chosen = &tag;
  }
  if (chosen == nullptr) return;
  pose->found = true;
  pose->cam_from_world = options_.smoothed ? chosen->smoothed_cam_from_tag : chosen->cam_from_tag;
  pose->anchors_used = 1;
  pose->rms_reprojection_px = chosen->pose.rms_reprojection_px;
  LayoutTag marker;
  marker.id = chosen->id;
  marker.size = options_.tracker.tag_size;
  pose->markers.push_back(marker);  // at the world origin (identity layout_from_tag)
}

}  // namespace reconar
