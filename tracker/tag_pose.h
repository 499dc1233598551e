#pragma once
// Pose of a planar target (one AprilTag, or any set of coplanar points) from its image points.
//  - IppePoses: Infinitesimal Plane-based Pose Estimation (Collins & Bartoli, "Infinitesimal
//    Plane-Based Pose Estimation", IJCV 2014): the homography from the plane to normalised image
//    coordinates, its Jacobian at the centroid of the plane points, and the two rotations that
//    explain that Jacobian (the two-fold planar ambiguity); translation by linear least squares.
//  - EstimatePlanarPose / EstimateTagPose: both IPPE solutions refined by Levenberg-Marquardt on
//    the reprojection error (RefineAbsolutePoseInPlace, core/geometry/absolute_pose.h, which runs
//    the fixed-size NormalLmSolve: no heap), the one with the lower error kept.
//
// Frames: cam_from_tag maps tag-frame points into the camera frame (x right, y down, z forward).
// Tag frame: origin at the tag centre, x right, y up, z out of the printed tag toward the viewer;
// libapriltag's corners p[0..3] are (-s/2,-s/2,0), (s/2,-s/2,0), (s/2,s/2,0), (-s/2,s/2,0). This is
// libapriltag's estimate_tag_pose frame (x right, y down, z into the tag) rotated 180 deg about x.
//
// Pixels: in the program's one convention (CameraIntrinsics: centre of the top-left pixel at
// (0, 0)), the convention TagDetection corners already come in (tag_detector.h converts once).
// Reprojection errors are in pixels, measured after undistortion (|fx, fy scaled normalised error|).
#include <array>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/normal_lm.h"
#include "core/math/rigid3.h"

namespace reconar {

// The 4 corners of a tag of edge `tag_size` (edge of the black square) in the tag frame, in
// libapriltag's corner order.
std::array<Eigen::Vector3d, 4> TagCornersInTagFrame(double tag_size);

// IPPE on `count` >= 4 points: plane_points[i] = (x, y) on the plane z = 0 of the plane frame,
// normalized[i] = their undistorted normalised image coordinates (K^-1 x). Writes the two
// cam_from_plane candidates (both with the plane in front of the camera) and returns 2, or 0 when
// the points are degenerate (fewer than 4, collinear, or a non-finite homography). The candidates
// are not sorted. No heap allocation.
int IppePoses(const Eigen::Vector2d* plane_points, const Eigen::Vector2d* normalized, int count,
              std::array<Rigid3, 2>* cam_from_plane);

// Root-mean-square pixel reprojection error of world points under cam_from_world (undistorted
// pixels: |(fx, fy) * (projection - normalized)|); infinity when a point is not in front.
double RmsReprojectionErrorPx(const Rigid3& cam_from_world, const Eigen::Vector3d* world_points,
                              const Eigen::Vector2d* normalized, int count, const CameraIntrinsics& intrinsics);

struct PlanarPoseOptions {
  bool refine = true;  // LM refinement of both IPPE candidates (off: IPPE only)
  NormalLmOptions lm;

  Status Check() const;
};

struct TagPose {
  Rigid3 cam_from_tag;
  double rms_reprojection_px = 0.0;
  // The other IPPE solution after the same refinement, and the ratio of the chosen solution's
  // RMS error to the other's, in [0, 1]: near 1 the two are equally good (pose ambiguous, e.g. a
  // small or fronto-parallel tag), near 0 the choice is clear.
  Rigid3 alternative_cam_from_tag;
  double alternative_rms_reprojection_px = 0.0;
  double ambiguity_ratio = 1.0;
};

// Pose of a plane from count >= 4 points: plane_points (x, y, 0) in the plane frame and their
// pixels (TagDetection corners). InvalidArgument for bad intrinsics/options or count < 4;
// FailedPrecondition when the points are degenerate or neither candidate puts them in front of
// the camera. No heap allocation on success.
Result<TagPose> EstimatePlanarPose(const Eigen::Vector2d* plane_points, const Eigen::Vector2d* pixels, int count,
                                   const CameraIntrinsics& intrinsics,
                                   const PlanarPoseOptions& options = PlanarPoseOptions());

// EstimatePlanarPose on the 4 corners of one tag of edge tag_size (metres, > 0).
Result<TagPose> EstimateTagPose(const Eigen::Vector2d (&corners_px)[4], double tag_size,
                                const CameraIntrinsics& intrinsics,
                                const PlanarPoseOptions& options = PlanarPoseOptions());

// Refines cam_from_world on the pixel reprojection error of count points (world_points and their
// pixels) with LM (trivial loss); returns the RMS error in pixels afterwards.
// count <= kMaxRefinementPoints; no heap allocation.
inline constexpr int kMaxRefinementPoints = 512;
double RefinePoseOnPoints(const Eigen::Vector3d* world_points, const Eigen::Vector2d* pixels, int count,
                          const CameraIntrinsics& intrinsics, const NormalLmOptions& lm, Rigid3* cam_from_world);

}  // namespace reconar
