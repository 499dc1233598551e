#pragma once
// PoseSource: the camera's pose in the world of an AR scene, once per video frame, from the frame's
// gray image. TagPoseSource (the tags) and FusedPoseSource (the tags and a project's map, the one
// the AR runtime in render/ar uses) implement it; docs/architecture.md says how to add another.
//
// Frames: cam_from_world maps world points (metres) into the camera frame (x right, y down,
// z forward). The world is the source's: a tag layout's frame (tags.layout), the chosen tag's
// frame (tag_pose.h: origin at the tag centre, x right, y up, z toward the viewer), or a map's.
#include <cstdint>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/math/rigid3.h"
#include "core/sfm/tag_layout.h"

namespace reconar {

// One frame's result; plain data, overwritten by every Track() (its storage reused).
struct WorldPose {
  bool found = false;     // cam_from_world holds this frame's pose
  Rigid3 cam_from_world;  // valid when found
  int anchors_used = 0;   // markers (or map points) the pose was estimated from
  double rms_reprojection_px = 0.0;
  double track_ms = 0.0;  // time spent finding the pose (detection included)
  // The world's tags measured in this frame, layout_from_tag being world_from_tag (`reconar view`
  // draws their axes). Empty for a source without markers. Its capacity is reserved once.
  std::vector<LayoutTag> markers;
};

class PoseSource {
 public:
  virtual ~PoseSource() = default;
  // Processes the next frame (8-bit gray, same size as the previous ones). A frame without a pose
  // is not an error (pose->found is false); errors are failures of the source itself. Makes no heap
  // allocation in steady state.
  virtual Status Track(ImageView<const uint8_t> gray, WorldPose* pose) = 0;
};

}  // namespace reconar
