#pragma once
// FusedPoseSource: the PoseSource of a project (`reconar track --project`, `reconar view
// --project`): its tags (tags.layout) and its localisation map (map/map.rmap, through the
// MapTracker) together, both in the project's world frame. Per frame:
//  1. the tags are tracked; the layout's tags not followed are searched where this frame's board
//     pose, else the previous frame's pose, predicts them (TagPoseSource's prior);
//  2. the map tracker tracks the camera against the map with the tags' pose of this frame as its
//     prior when there is one (its prediction, and a restart without relocalisation when it had
//     lost the map, unless such a restart failed on the previous frame), else by itself,
//     relocalising when it has lost the map;
//  3. the pose: with tags and map, one robust refinement (Huber, core/geometry/absolute_pose.h)
//     from the tags' board pose over the tag corners and the map inliers that agree with that pose
//     within fusion_max_error_px. The tags keep the metric anchor (a map that disagrees with them
//     is left out, and the frame is posed by the tags alone); the map keeps the model in place when
//     no tag is in view. Either alone poses the frame by itself.
// Without a map it is the TagPoseSource; without tags (track_tags false: a project reconstructed
// without tags) it is the map tracker alone, in the map's own frame and units. Steady-state Track() makes no heap allocation of its own
// (every buffer is sized at construction; the tag and map trackers give the same guarantee for
// their tracked frames; a relocalisation allocates).
#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/geometry/absolute_pose.h"
#include "core/sfm/localization_map.h"
#include "tracker/map_tracker.h"
#include "tracker/pose_source.h"
#include "tracker/tag_pose_source.h"

namespace reconar {

struct FusedPoseSourceOptions {
  TagPoseSourceOptions tags;             // needs a layout when there is a map (the map's world frame)
  const LocalizationMap* map = nullptr;  // borrowed; nullptr: tags only
  // false: no tag is searched and the map alone poses the frames, in its own world frame (a project
  // without tags); of `tags` only tracker.intrinsics is used. Needs a map.
  bool track_tags = true;
  // Its intrinsics are replaced by tags.tracker.intrinsics (one camera for both).
  MapTrackerOptions map_tracking;
  // A map inlier joins the fused refinement when its error under the tags' pose is below this: the
  // localizer's inlier threshold (AbsolutePoseOptions::max_error_px) by default.
  double fusion_max_error_px = AbsolutePoseOptions().max_error_px;
  PoseRefinementOptions refinement;

  Status Check() const;
};

// Which sources posed a frame; reports list them in this order. kCount is no kind: their number.
enum class PoseSourceKind { kNone, kTagsAndMap, kTags, kMap, kCount };
const char* PoseSourceKindName(PoseSourceKind kind);  // "none", "tags+map", "tags", "map"
// Frame counts indexed by PoseSourceKind.
using PoseSourceCounts = std::array<long, static_cast<size_t>(PoseSourceKind::kCount)>;

class FusedPoseSource final : public PoseSource {
 public:
  // InvalidArgument for bad options (a map without a layout, no tags and no map); errors of the tag
  // and map trackers.
  static Result<std::unique_ptr<FusedPoseSource>> Create(const FusedPoseSourceOptions& options);

  Status Track(ImageView<const uint8_t> gray, WorldPose* pose) override;

  // This frame's (valid after Track, until the next).
  PoseSourceKind source() const { return source_; }
  // nullptr when tags are not tracked (track_tags false).
  const TagPoseSource* tags() const { return tags_.get(); }
  const WorldPose& tag_pose() const { return tag_pose_; }
  // nullptr without a map.
  const MapTrackerFrameReport* map_report() const { return map_ ? &map_report_ : nullptr; }
  // Map inliers that agreed with the tags and joined the fused refinement (kTagsAndMap frames).
  int fused_map_points() const { return fused_map_points_; }
  const FusedPoseSourceOptions& options() const { return options_; }

 private:
  explicit FusedPoseSource(const FusedPoseSourceOptions& options);
  // Refines pose->cam_from_world (the tags' pose) over the tag corners and the agreeing map
  // inliers; false when the refinement fails (the tags' pose is kept).
  bool Fuse(WorldPose* pose);

  FusedPoseSourceOptions options_;
  std::unique_ptr<TagPoseSource> tags_;
  std::unique_ptr<MapTracker> map_;
  WorldPose tag_pose_;
  MapTrackerFrameReport map_report_;
  PoseSourceKind source_ = PoseSourceKind::kNone;
  int fused_map_points_ = 0;
  bool has_previous_ = false;
  Rigid3 previous_cam_from_world_;
  // The fused refinement's correspondences, capacity reserved at construction.
  std::vector<Eigen::Vector2d> pixels_;
  std::vector<Eigen::Vector3d> world_points_;
  std::vector<int> indices_;
};

}  // namespace reconar
