#include "tracker/board_pose.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

namespace reconar {

Result<BoardPose> EstimateBoardPose(const TagLayout& layout, const TagDetectionList& detections,
                                    const CameraIntrinsics& intrinsics, const BoardPoseOptions& options) {
  if (!intrinsics.valid()) return InvalidArgument("EstimateBoardPose: intrinsics need fx > 0 and fy > 0");
  constexpr int kMaxTags = kMaxRefinementPoints / 4;
  Eigen::Vector3d world[kMaxRefinementPoints];
  Eigen::Vector2d pixels[kMaxRefinementPoints];
  const LayoutTag* used_tags[kMaxTags];
  const TagDetection* used_detections[kMaxTags];
  int tags = 0;
  for (const TagDetection& detection : detections) {
    if (tags >= kMaxTags) break;
    if (detection.hamming > options.max_hamming) continue;
    const LayoutTag* tag = layout.Find(detection.id);
    if (tag == nullptr) continue;
    bool duplicate = false;
    for (int i = 0; i < tags; ++i) duplicate |= used_tags[i]->id == detection.id;
    if (duplicate) continue;
    const std::array<Eigen::Vector3d, 4> corners = TagCornersInTagFrame(tag->size);
    for (int k = 0; k < 4; ++k) {
      world[4 * tags + k] = tag->layout_from_tag * corners[k];
      pixels[4 * tags + k] = detection.corners[k];
    }
    used_tags[tags] = tag;
    used_detections[tags] = &detection;
    ++tags;
  }
  if (tags == 0) return FailedPrecondition("EstimateBoardPose: no tag of the layout was detected");
  const int count = 4 * tags;
  BoardPose board;
  board.tags_used = tags;
  board.corners_used = count;
  if (layout.IsPlanar()) {
    Eigen::Vector2d plane[kMaxRefinementPoints];
    for (int i = 0; i < count; ++i) plane[i] = world[i].head<2>();
    Result<TagPose> pose = EstimatePlanarPose(plane, pixels, count, intrinsics, options.pose);
    if (!pose.ok()) return pose.status();
    board.cam_from_layout = pose->cam_from_tag;
    board.rms_reprojection_px = pose->rms_reprojection_px;
    return board;
  }
  Eigen::Vector2d normalized[kMaxRefinementPoints];
  for (int i = 0; i < count; ++i) normalized[i] = intrinsics.Unproject(pixels[i]);
  double best_rms = std::numeric_limits<double>::infinity();
  for (int i = 0; i < tags; ++i) {
    Result<TagPose> pose = EstimateTagPose(used_detections[i]->corners, used_tags[i]->size, intrinsics, options.pose);
    if (!pose.ok()) continue;
    for (const Rigid3& cam_from_tag : {pose->cam_from_tag, pose->alternative_cam_from_tag}) {
      const Rigid3 candidate = cam_from_tag * used_tags[i]->layout_from_tag.Inverse();
      const double rms = RmsReprojectionErrorPx(candidate, world, normalized, count, intrinsics);
      if (rms < best_rms) {
        best_rms = rms;
        board.cam_from_layout = candidate;
      }
    }
  }
  if (!std::isfinite(best_rms)) return FailedPrecondition("EstimateBoardPose: no tag gave a pose in front of the camera");
  board.rms_reprojection_px =
      options.pose.refine
          ? RefinePoseOnPoints(world, pixels, count, intrinsics, options.pose.lm, &board.cam_from_layout)
          : best_rms;
  return board;
}

}  // namespace reconar
