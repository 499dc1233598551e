#pragma once
// A real-looking video with exact ground truth for the map tracker's tests and bench: a camera
// rotating about its centre sees every view as a homography of one photo, so warping one real
// photo through small rotations gives frames whose cam_from_world is known exactly, for any scene.
// The map is made the same way: keyframes rendered at a few rotations, their SIFT keypoints given
// random depths along their rays (pure rotation cannot tell depths apart, so any depths agree with
// every frame), and a LocalizationMap built from that model with the project's own builder.
// Test support only.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/rigid3.h"
#include "core/sfm/localization_map.h"

namespace reconar::testing {

struct RotationScene {
  Image<uint8_t> photo;           // grey
  CameraIntrinsics photo_camera;  // pinhole; the photo's pixels are rays of the world
  CameraIntrinsics frame_camera;  // pinhole, the video's frames
  Rigid3 photo_cam_from_world;    // the rotating camera's frame at rotation identity
};

// The photo at `path` read upright, grey, box-filtered by `downscale` (an integer); a pinhole
// camera of focal `focal_factor` times the photo's larger side for it, and for frames of
// width x height with the same focal (so a frame shows a crop of the photo at rotation identity).
// photo_cam_from_world is a fixed rotation and translation (the world is not the camera's frame).
Result<RotationScene> MakeRotationScene(const std::string& path, int downscale, int width, int height,
                                        double focal_factor = 0.9);

// The frame seen by the camera at cam_from_photo_cam = R (rotation only): frame pixel x shows the
// photo's pixel of the ray R^T K_frame^-1 x (K_photo times it for a pinhole photo), bilinear;
// outside the photo a mid grey. A distorted photo thus gives undistorted frames.
Image<uint8_t> RenderRotatedView(const RotationScene& scene, const Eigen::Matrix3d& rotation);

// cam_from_world of that view: R * photo_cam_from_world.
Rigid3 RotatedViewPose(const RotationScene& scene, const Eigen::Matrix3d& rotation);

// A rotation by yaw (about y), pitch (about x) and roll (about z), in degrees.
Eigen::Matrix3d YawPitchRoll(double yaw_deg, double pitch_deg, double roll_deg);

// A localisation map of keyframes rendered at `keyframe_rotations`: SIFT (default options) on each,
// every keypoint a map point at a depth uniform in [min_depth, max_depth] (seeded), one keyframe
// observation per point. Vocabulary of branching 8, depth 3.
Result<LocalizationMap> BuildRotationSceneMap(const RotationScene& scene,
                                              const std::vector<Eigen::Matrix3d>& keyframe_rotations,
                                              double min_depth = 2.0, double max_depth = 4.0);

}  // namespace reconar::testing
