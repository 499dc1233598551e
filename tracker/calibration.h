#pragma once
// Camera intrinsics calibration from AprilTag corners (`reconar calibrate`): Zhang, "A Flexible New
// Technique for Camera Calibration", IEEE TPAMI 22(11), 2000.
//  1. One homography per planar target (a tag instance; HomographyFourPoint on its 4 corners).
//  2. Closed-form fx, fy, cx, cy (skew 0) from the image of the absolute conic B = K^-T K^-1, which
//     every homography constrains twice (h1^T B h2 = 0, h1^T B h1 = h2^T B h2; Zhang sec. 3.1). With
//     fewer than `min_targets_for_free_principal_point` targets, or when the 4-parameter system is
//     degenerate, has no positive-definite solution or puts the principal point outside the image,
//     the closed form fixes the principal point at the image centre (the refinement then frees it
//     unless fix_principal_point). Small tags make this estimate coarse (on the swatbotics photos
//     fx 584 against 765 after refinement); the refinement converges from it.
//  3. Target poses from the homographies (Zhang sec. 3.1, r1 = lambda K^-1 h1, ...; the nearest
//     rotation by SVD). With a layout, each image's board pose is the tag-derived pose that best
//     explains all of the image's board corners.
//  4. Joint Levenberg-Marquardt refinement of (fx, fy, cx, cy, k1, k2) and every target pose on the
//     robustly weighted pixel reprojection error (core/math/robust_loss.h), the poses eliminated
//     by the Schur complement (each pose block 6x6, independent of the others), the LM loop of
//     core/math/lm_loop.h. Parameter standard deviations come from the inverse of the reduced
//     (intrinsics) Gauss-Newton matrix scaled by the residual variance.
//
// Conventions.
//  - Tag frame: origin at the tag centre, x right, y up, z out of the printed tag toward the viewer;
//    libapriltag's corners p[0..3] are (-s/2,-s/2,0), (s/2,-s/2,0), (s/2,s/2,0), (-s/2,s/2,0)
//    (bottom-left, bottom-right, top-right, top-left of the upright tag), s = tag edge (black border).
//  - Camera frame: x right, y down, z forward (COLMAP); poses are cam_from_target.
//  - Pixels: corners and the result are in CameraIntrinsics' convention (core/math/camera_intrinsics.h:
//    the centre of the top-left pixel is (0, 0)), the convention TagDetection corners come in
//    (tracker/tag_detector.h converts libapriltag's (0.5, 0.5) once, at detection).
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/lm_loop.h"
#include "core/math/rigid3.h"
#include "core/math/robust_loss.h"
#include "tracker/tag_detector.h"
#include "tracker/board_pose.h"

namespace reconar {

struct TagCorners {
  int tag_id = 0;
  std::array<Eigen::Vector2d, 4> corners;  // libapriltag order p[0..3], pixels (our convention)
};

struct CalibrationImage {
  std::string name;  // for messages and the report (e.g. the file name)
  int width = 0;     // pixels; every image must have the same size (one camera)
  int height = 0;
  std::vector<TagCorners> tags;
};

// The detections of one image as calibration input.
CalibrationImage MakeCalibrationImage(std::string name, int width, int height, const TagDetectionList& detections);

struct CalibrationObservations {
  std::vector<CalibrationImage> images;
  double tag_size = 0.0;  // s, metres, of tags not in the layout (scales the reported poses only)
  // Optional rigid layout (tracker/tag_layout.h; tags may lie on several planes and have their own
  // sizes). When non-empty, the layout tags seen in an image share one board pose (target frame =
  // the layout frame); tags not in it are planar targets of their own (size tag_size). When empty,
  // every tag instance is its own planar target.
  TagLayout layout;
};

struct CalibrationOptions {
  bool fix_principal_point = false;  // keep cx, cy at the image centre ((width-1)/2, (height-1)/2)
  bool fix_aspect_ratio = false;     // keep fy = aspect_ratio * fx
  double aspect_ratio = 1.0;         // used with fix_aspect_ratio
  bool estimate_k1 = true;           // otherwise k1 = 0
  bool estimate_k2 = true;           // otherwise k2 = 0; needs estimate_k1
  // The refinement's LM settings (core/math/lm_loop.h): at most 200 iterations, and a stop when an
  // accepted step changes the cost by <= 1e-9 * cost.
  LmOptions lm = [] {
    LmOptions defaults;
    defaults.max_iterations = 200;
    defaults.function_tolerance = 1e-9;
    return defaults;
  }();
  RobustLoss loss{LossType::kHuber, 1.0};  // on the pixel reprojection error of each corner
  // Least number of targets (tag instances or board views) and of distinct images.
  int min_targets = 3;
  int min_images = 1;
  // The closed form estimates the principal point only from at least this many targets.
  int min_targets_for_free_principal_point = 4;
  // Degeneracy (FailedPrecondition), checked three ways:
  //  - Zhang's constraint matrix has a second-smallest singular value below this fraction of its
  //    largest (exactly fronto-parallel or too few targets; corner noise alone lifts the ratio to
  //    ~ noise / tag size * distance / tag edge, e.g. 0.016 for 0.2 px on 100 px tags at 8 edges);
  //  - its null vector is no positive-definite image of the absolute conic;
  //  - after refinement, the focal standard deviation exceeds max_relative_focal_stddev * focal
  //    (nearly fronto-parallel views that noise made look solvable).
  double min_constraint_ratio = 1e-3;
  double max_relative_focal_stddev = 0.05;

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

// One refined planar target or board view.
struct CalibrationTargetPose {
  int image = 0;    // index into CalibrationObservations::images
  int tag_id = -1;  // the tag of a single-tag target; -1 for a board (layout) view
  Rigid3 cam_from_target;
  int num_corners = 0;
  double rms_px = 0.0;
};

struct CalibrationReport {
  CameraIntrinsics intrinsics;
  // Standard deviations of fx, fy, cx, cy, k1, k2 (0 for fixed ones; fy's is aspect_ratio times
  // fx's when the aspect ratio is fixed), assuming independent, identically distributed corner
  // noise (real detectors' corner errors are correlated within a tag, so take them as a lower
  // bound), sigma^2 = 2 * final robust cost / (2 * corners - parameters).
  std::array<double, 6> stddev{};
  // Root mean square of the corners' 2D pixel error |projected - detected| (with N corners and p
  // parameters it estimates sigma * sqrt(2 (2N - p) / 2N) for per-coordinate noise sigma).
  double rms_px = 0.0;            // over all corners used, after refinement
  double initial_rms_px = 0.0;    // with the closed-form intrinsics and poses
  std::vector<double> image_rms_px;  // per input image; 0 for images without targets
  std::vector<CalibrationTargetPose> targets;
  int num_images_used = 0;
  int num_targets = 0;
  int num_corners = 0;
  int iterations = 0;
  // Why the LM stopped (core/math/lm_loop.h); never kNumericFailure in a returned report.
  LmTermination termination = LmTermination::kMaxIterations;
  bool converged = false;  // LmConverged(termination): stopped on a tolerance, for the JSON report
  bool principal_point_from_closed_form = false;  // false: the closed form fixed it at the centre
  double constraint_ratio = 0.0;  // of the closed form that was used (see min_constraint_ratio)
  CameraIntrinsics closed_form;  // the initial estimate (k1 = k2 = 0)
};

// Calibrates from tag corners. InvalidArgument for bad options or observations (sizes differ,
// non-finite corners, tag_size <= 0 while a tag outside the layout is seen); FailedPrecondition
// when there are fewer than min_targets targets or min_images images with tags, or when the views
// are degenerate (see the three checks at min_constraint_ratio; the message says "degenerate");
// NumericFailure when the refinement meets a non-finite cost.
Result<CalibrationReport> CalibrateIntrinsics(const CalibrationObservations& observations,
                                              const CalibrationOptions& options);

}  // namespace reconar
