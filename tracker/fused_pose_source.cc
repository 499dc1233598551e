#include "tracker/fused_pose_source.h"

#include <chrono>
#include <cmath>
#include <string>

#include "tracker/tag_pose.h"

namespace reconar {

const char* PoseSourceKindName(PoseSourceKind kind) {
  switch (kind) {
    case PoseSourceKind::kNone:
      return "none";
    case PoseSourceKind::kTags:
      return "tags";
    case PoseSourceKind::kMap:
      return "map";
    case PoseSourceKind::kTagsAndMap:
      return "tags+map";
    case PoseSourceKind::kCount:
      break;
  }
  return "unknown";
}

Status FusedPoseSourceOptions::Check() const {
  if (track_tags) {
    RECONAR_RETURN_IF_ERROR(tags.Check());
    if (map != nullptr && tags.layout.empty()) {
      return InvalidArgument("fused pose source: a map needs the tags' layout (the map's world frame)");
    }
  } else {
    if (map == nullptr) return InvalidArgument("fused pose source: without tags it needs a map");
    if (!tags.tracker.intrinsics.valid()) return InvalidArgument("fused pose source: the camera's fx and fy must be > 0");
  }
  if (!(fusion_max_error_px > 0.0) || !std::isfinite(fusion_max_error_px)) {
    return InvalidArgument("fused pose source: fusion_max_error_px must be > 0");
  }
  return refinement.Check();
}

FusedPoseSource::FusedPoseSource(const FusedPoseSourceOptions& options) : options_(options) {}

Result<std::unique_ptr<FusedPoseSource>> FusedPoseSource::Create(const FusedPoseSourceOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  std::unique_ptr<FusedPoseSource> source(new FusedPoseSource(options));
  if (options.track_tags) {
    RECONAR_ASSIGN_OR_RETURN(source->tags_, TagPoseSource::Create(options.tags));
  }
  if (options.map != nullptr) {
    MapTrackerOptions map_options = options.map_tracking;
    map_options.intrinsics = options.tags.tracker.intrinsics;
    RECONAR_ASSIGN_OR_RETURN(source->map_, MapTracker::Create(options.map, map_options));
    const size_t capacity = 4 * options.tags.layout.tags().size() + static_cast<size_t>(map_options.max_tracked_points);
    source->pixels_.reserve(capacity);
    source->world_points_.reserve(capacity);
    source->indices_.reserve(capacity);
  }
  return source;
}

Status FusedPoseSource::Track(ImageView<const uint8_t> gray, WorldPose* pose) {
  const auto start = std::chrono::steady_clock::now();
  source_ = PoseSourceKind::kNone;
  fused_map_points_ = 0;
  if (!map_) {
    RECONAR_RETURN_IF_ERROR(tags_->Track(gray, nullptr, pose));
    if (pose->found) source_ = PoseSourceKind::kTags;
    return Status::Ok();
  }
  if (tags_) {
    RECONAR_RETURN_IF_ERROR(tags_->Track(gray, has_previous_ ? &previous_cam_from_world_ : nullptr, &tag_pose_));
  }
  // The tags' pose restarts a map tracker that has lost the map without a relocalisation; a restart
  // that did not take (the next frame has no map pose: photos far apart rather than a video) is
  // followed by a relocalisation.
  const bool restart_failed = map_report_.from_prior && !map_report_.found;
  const Rigid3* map_prior = tag_pose_.found && !restart_failed ? &tag_pose_.cam_from_world : nullptr;
  RECONAR_RETURN_IF_ERROR(map_->Track(gray, map_prior, &map_report_));

  pose->found = false;
  pose->anchors_used = 0;
  pose->rms_reprojection_px = 0.0;
  pose->markers.clear();
  if (pose->markers.capacity() < tag_pose_.markers.capacity()) pose->markers.reserve(tag_pose_.markers.capacity());
  for (const LayoutTag& marker : tag_pose_.markers) pose->markers.push_back(marker);
  if (tag_pose_.found) {
    pose->found = true;
    pose->cam_from_world = tag_pose_.cam_from_world;
    pose->anchors_used = tag_pose_.anchors_used;
    pose->rms_reprojection_px = tag_pose_.rms_reprojection_px;
    source_ = PoseSourceKind::kTags;
    if (map_report_.found && Fuse(pose)) source_ = PoseSourceKind::kTagsAndMap;
  } else if (map_report_.found) {
    pose->found = true;
    pose->cam_from_world = map_report_.cam_from_world;
    pose->anchors_used = map_report_.inliers;
    pose->rms_reprojection_px = map_report_.rms_reprojection_px;
    source_ = PoseSourceKind::kMap;
  }
  has_previous_ = pose->found;
  if (pose->found) previous_cam_from_world_ = pose->cam_from_world;
  pose->track_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

bool FusedPoseSource::Fuse(WorldPose* pose) {
  const RadialCamera camera = options_.tags.tracker.intrinsics.Camera();
  const Eigen::Matrix3d& R = pose->cam_from_world.rotation;
  const Eigen::Vector3d& t = pose->cam_from_world.translation;
  pixels_.clear();
  world_points_.clear();
  for (const TrackedTag& tag : tags_->report().tags) {
    if (!tag.measured) continue;
    const LayoutTag* placed = options_.tags.layout.Find(tag.id);
    if (placed == nullptr) continue;
    const std::array<Eigen::Vector3d, 4> corners = TagCornersInTagFrame(placed->size);
    for (int k = 0; k < 4; ++k) {
      pixels_.push_back(tag.detection.corners[k]);
      world_points_.push_back(placed->layout_from_tag * corners[k]);
    }
  }
  const size_t num_tag_corners = pixels_.size();
  const double max_squared_error = options_.fusion_max_error_px * options_.fusion_max_error_px;
  for (size_t i = 0; i < map_report_.inlier_pixels.size() && pixels_.size() < pixels_.capacity(); ++i) {
    const Eigen::Vector3d& X = map_report_.inlier_world_points[i];
    if (SquaredPixelError(camera, R, t, X, map_report_.inlier_pixels[i]) < max_squared_error) {
      pixels_.push_back(map_report_.inlier_pixels[i]);
      world_points_.push_back(X);
    }
  }
  fused_map_points_ = static_cast<int>(pixels_.size() - num_tag_corners);
  if (fused_map_points_ == 0) return false;
  indices_.clear();
  for (size_t i = 0; i < pixels_.size(); ++i) indices_.push_back(static_cast<int>(i));
  RadialCamera refined_camera = camera;
  Eigen::Matrix3d refined_R = R;
  Eigen::Vector3d refined_t = t;
  const NormalLmSummary summary = RefineAbsolutePoseInPlace(pixels_.data(), world_points_.data(), indices_.data(),
                                                            static_cast<int>(indices_.size()), options_.refinement,
                                                            &refined_camera, &refined_R, &refined_t);
  if (summary.termination == LmTermination::kNumericFailure || !refined_R.allFinite() || !refined_t.allFinite()) {
    fused_map_points_ = 0;
    return false;
  }
  pose->cam_from_world.rotation = refined_R;
  pose->cam_from_world.translation = refined_t;
  pose->anchors_used = tag_pose_.anchors_used + fused_map_points_;
  return true;
}

}  // namespace reconar
