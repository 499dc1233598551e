#pragma once
// TagLayout: where each tag of a multi-tag target (a board, a room) sits: per id its edge length
// and layout_from_tag (Rigid3). EstimateBoardPose: the pose of the whole layout from the
// detections of any of its tags, using all their corners.
//
// Text format (one tag per line; '#' starts a comment; blank lines ignored; metres and degrees):
//   <id> <size> <x> <y> <z> <qw> <qx> <qy> <qz>   layout_from_tag: translation (x, y, z) and the
//                                                 rotation as a unit quaternion (normalised on read)
//   <id> <size> <cx> <cy> [<angle_deg>]           planar shorthand: tag in the layout's z = 0 plane,
//                                                 centre (cx, cy), rotated by angle_deg about z
// Tag frames follow tag_pose.h (origin at the tag centre, x right, y up, z toward the viewer), so a
// planar layout's z axis also points toward the viewer.
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/rigid3.h"
#include "tracker/tag_detector.h"
#include "tracker/tag_pose.h"

namespace reconar {

struct LayoutTag {
  int id = 0;
  double size = 0.0;  // edge of the black square, metres
  Rigid3 layout_from_tag;
};

class TagLayout {
 public:
  // InvalidArgument for a negative id, a non-positive or non-finite size, a non-finite pose or an
  // id already present.
  Status Add(const LayoutTag& tag);
  // nullptr when the id is not in the layout. No allocation (binary search over ids).
  const LayoutTag* Find(int id) const;
  const std::vector<LayoutTag>& tags() const { return tags_; }  // sorted by id
  bool empty() const { return tags_.empty(); }
  // Every tag lies in the layout's z = 0 plane with its z axis along the layout's (1e-9 tolerance).
  bool IsPlanar() const;

 private:
  std::vector<LayoutTag> tags_;
};

// Parses the text format; errors name `name_for_errors`, the line number and the reason
// (InvalidArgument / CorruptData).
Result<TagLayout> ParseTagLayout(const std::string& text, const std::string& name_for_errors);
// NotFound / IoError for the file, then ParseTagLayout.
Result<TagLayout> ReadTagLayout(const std::string& path);

struct BoardPose {
  Rigid3 cam_from_layout;
  double rms_reprojection_px = 0.0;  // over all corners used
  int tags_used = 0;
  int corners_used = 0;
};

struct BoardPoseOptions {
  PlanarPoseOptions pose;
  // Detections with more corrected bits are ignored.
  int max_hamming = 3;
};

// The layout's pose from the detections of its tags (ids not in the layout are ignored; at most
// kMaxRefinementPoints / 4 tags are used). Planar layouts: IPPE over all corners (EstimatePlanarPose).
// Otherwise each used tag's own IPPE pose gives a candidate cam_from_layout, the one with the lowest
// RMS over all corners is kept. Both then refined by LM over all corners. FailedPrecondition when no
// layout tag is detected or the pose fails; no heap allocation on success.
Result<BoardPose> EstimateBoardPose(const TagLayout& layout, const TagDetectionList& detections,
                                    const CameraIntrinsics& intrinsics, const BoardPoseOptions& options = {});

}  // namespace reconar
