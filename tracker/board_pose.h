#pragma once
// EstimateBoardPose: the pose of a multi-tag layout (core/sfm/tag_layout.h: where each tag sits,
// the tags.layout file) from the detections of any of its tags, using all their corners.
#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/rigid3.h"
#include "core/sfm/tag_layout.h"
#include "tracker/tag_detector.h"
#include "tracker/tag_pose.h"

namespace reconar {

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
