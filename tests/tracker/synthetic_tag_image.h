#pragma once
// Synthetic camera frames of AprilTags for the tracker tests: the real tag bitmap (RenderTagBitmap,
// i.e. libapriltag's apriltag_to_image) seen by a pinhole camera (no distortion) at a known pose,
// rendered with area coverage (supersampling) and an optional Gaussian blur. The corners returned
// here are in the program's pixel convention (CameraIntrinsics, TagDetection: pixel (i, j) covers
// [i - 0.5, i + 0.5] x [j - 0.5, j + 0.5]); the renderer samples in pixel-edge coordinates (+0.5).
#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "core/base/image.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/rigid3.h"
#include "tracker/tag_detector.h"

namespace reconar {
namespace testing {

struct SyntheticTag {
  TagFamily family = TagFamily::kTag36h11;
  int id = 0;
  double size = 0.1;  // black-square edge, metres
  Rigid3 cam_from_tag;
};

struct SyntheticRenderOptions {
  uint8_t background = 170;
  int supersampling = 8;     // samples per pixel side
  double blur_sigma = 0.0;   // pixels; 0 = none
};

// Draws the tag over `image` (a gray image the caller filled, e.g. with the background).
// Returns false when the family cannot be rendered or the tag is not in front of the camera.
bool DrawTag(const SyntheticTag& tag, const CameraIntrinsics& camera, int supersampling, Image<uint8_t>* image);

// A 0.1 m tag facing the camera (tag z toward the viewer), rotated by angle_deg about a fixed
// oblique axis, its centre at `translation` in the camera frame.
SyntheticTag TiltedTag(int id, const Eigen::Vector3d& translation, double angle_deg);

// The tests' camera: 640x480, f = 600 px, principal point (320, 240), no distortion.
CameraIntrinsics TestCamera();
// A camera.width x camera.height frame of the background with the tags drawn, then blurred.
Image<uint8_t> RenderTags(const SyntheticTag* tags, int count, const CameraIntrinsics& camera,
                          const SyntheticRenderOptions& options);

// The tag's corners in libapriltag's order, in the program's pixel convention (as TagDetection).
std::array<Eigen::Vector2d, 4> ProjectedCorners(const SyntheticTag& tag, const CameraIntrinsics& camera);

}  // namespace testing
}  // namespace reconar
