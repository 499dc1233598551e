#pragma once
// TagPoseSource: the PoseSource of AprilTags. Per frame the TagTracker follows every tag in view;
// the world is then
//  - with a layout (a board, or a project's tags.layout): the layout's frame, posed from all of its
//    tags measured in this frame at once (EstimateBoardPose);
//  - without one: the frame of one tag, `tag_id` when it is measured in this frame, else the lowest
//    id measured in this frame (a tag the tracker still follows but did not find has only a stale
//    pose), at its measured pose or, with `smoothed`, at the tracker's filtered one.
// With a layout, the layout's tags not measured yet are then predicted (predict_layout_tags): the
// frame's board pose, or without one the caller's prior cam_from_world, places each of them in the
// frame, and TagTracker::SearchPredicted searches each one whose square should be in view where it
// should appear; when any is found the board pose is estimated again from all the frame's tags. A
// tag entering the view is so found in the frame it appears, not at the next full-frame search.
// WorldPose::markers lists the world's tags measured in this frame (a single tag: the chosen one at
// the world origin). Steady-state Track() makes no heap allocation (TagTracker's guarantee; the
// detection list and the markers are sized from max_tags at construction).
#include <memory>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "tracker/pose_source.h"
#include "tracker/board_pose.h"
#include "tracker/tag_tracker.h"

namespace reconar {

struct TagPoseSourceOptions {
  TagTrackerOptions tracker;
  TagLayout layout;  // empty: the world is one tag's frame
  int tag_id = -1;   // without a layout: the tag to follow (-1: the lowest id in view)
  bool smoothed = false;
  // With a layout: search the layout's tags where the frame's pose predicts them (see above).
  bool predict_layout_tags = true;
  BoardPoseOptions board;

  Status Check() const;  // tracker.Check(), tag_id >= -1
};

class TagPoseSource final : public PoseSource {
 public:
  // InvalidArgument for bad options; errors of TagTracker::Create. With a layout, tracker.max_tags
  // is raised to the layout's tag count when lower (options() shows the value used).
  static Result<std::unique_ptr<TagPoseSource>> Create(const TagPoseSourceOptions& requested);

  Status Track(ImageView<const uint8_t> gray, WorldPose* pose) override;
  // Track with a prior pose of this frame (world = the layout's frame; nullptr: none), e.g. from
  // another pose source: with a layout, it places the layout's tags when no tag found by the
  // tracker gives a board pose. It is only a prediction: the pose comes from the tags found.
  Status Track(ImageView<const uint8_t> gray, const Rigid3* prior_cam_from_world, WorldPose* pose);

  // This frame's tags (valid after Track, until the next).
  const TagTrackerFrameReport& report() const { return report_; }
  // The layout's pose of this frame, when there is a layout and it was found.
  const BoardPose* board() const { return has_board_ ? &board_ : nullptr; }
  const TagPoseSourceOptions& options() const { return options_; }

 private:
  TagPoseSource(const TagPoseSourceOptions& options, std::unique_ptr<TagTracker> tracker);
  void ResetPose(WorldPose* pose) const;
  void PoseFromLayout(WorldPose* pose);
  // Searches the layout's tags not measured in this frame where cam_from_world puts them.
  Status SearchLayoutTags(ImageView<const uint8_t> gray, const Rigid3& cam_from_world);
  void PoseFromOneTag(WorldPose* pose) const;

  TagPoseSourceOptions options_;
  std::unique_ptr<TagTracker> tracker_;
  TagTrackerFrameReport report_;
  TagDetectionList measured_;  // this frame's measured detections, capacity max_tags
  std::vector<PredictedTag> predicted_;  // capacity: the layout's tags
  BoardPose board_;
  bool has_board_ = false;
};

}  // namespace reconar
