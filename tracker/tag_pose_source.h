#pragma once
// TagPoseSource: the PoseSource of AprilTags. Per frame the TagTracker follows every tag in view;
// the world is then
//  - with a layout (a board, or a project's tags.layout): the layout's frame, posed from all of its
//    tags measured in this frame at once (EstimateBoardPose);
//  - without one: the frame of one tag, `tag_id` when it is measured in this frame, else the lowest
//    id measured in this frame (a tag the tracker still follows but did not find has only a stale
//    pose), at its measured pose or, with `smoothed`, at the tracker's filtered one.
// WorldPose::markers lists the world's tags measured in this frame (a single tag: the chosen one at
// the world origin). Steady-state Track() makes no heap allocation (TagTracker's guarantee; the
// detection list and the markers are sized from max_tags at construction).
#include <memory>

#include "core/base/image.h"
#include "core/base/status.h"
#include "tracker/pose_source.h"
#include "tracker/tag_layout.h"
#include "tracker/tag_tracker.h"

namespace reconar {

struct TagPoseSourceOptions {
  TagTrackerOptions tracker;
  TagLayout layout;  // empty: the world is one tag's frame
  int tag_id = -1;   // without a layout: the tag to follow (-1: the lowest id in view)
  bool smoothed = false;
  BoardPoseOptions board;

  Status Check() const;  // tracker.Check(), tag_id >= -1
};

class TagPoseSource final : public PoseSource {
 public:
  // InvalidArgument for bad options; errors of TagTracker::Create.
  static Result<std::unique_ptr<TagPoseSource>> Create(const TagPoseSourceOptions& options);

  Status Track(ImageView<const uint8_t> gray, WorldPose* pose) override;

  // This frame's tags (valid after Track, until the next).
  const TagTrackerFrameReport& report() const { return report_; }
  // The layout's pose of this frame, when there is a layout and it was found.
  const BoardPose* board() const { return has_board_ ? &board_ : nullptr; }
  const TagPoseSourceOptions& options() const { return options_; }

 private:
  TagPoseSource(const TagPoseSourceOptions& options, std::unique_ptr<TagTracker> tracker);
  void PoseFromLayout(WorldPose* pose);
  void PoseFromOneTag(WorldPose* pose) const;

  TagPoseSourceOptions options_;
  std::unique_ptr<TagTracker> tracker_;
  TagTrackerFrameReport report_;
  TagDetectionList measured_;  // this frame's measured detections, capacity max_tags
  BoardPose board_;
  bool has_board_ = false;
};

}  // namespace reconar
