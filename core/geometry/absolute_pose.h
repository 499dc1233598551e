#pragma once
// Absolute pose (camera registration): the pose of a camera from 2D-3D correspondences.
//  - P3PEstimator: Lambda Twist P3P (Persson & Nordberg, "Lambda Twist: An Accurate Fast Robust
//    Perspective Three Point (P3P) Solver", ECCV 2018), up to 4 poses from 3 correspondences.
//  - DltPoseEstimator: the normalised direct linear transform for a 3x4 projection matrix from
//    >= 6 correspondences (Hartley & Zisserman, "Multiple View Geometry", 2nd ed., sec. 7.1 and
//    algorithm 7.1), the unknown-focal solver.
//  - PoseLocalEstimator: the least-squares step of P3P's LO-RANSAC (Chum, Matas & Kittler, DAGM
//    2003): Levenberg-Marquardt on the normalised reprojection error from the current pose.
//  - EstimateAbsolutePose: P3P in LO-RANSAC for a camera of known focal length, then a robust
//    Levenberg-Marquardt refinement of the pose (and optionally the focal) on the pixel
//    reprojection error of the inliers. EstimateAbsolutePoseUnknownFocal: DLT in RANSAC, P
//    decomposed by RQ (H&Z sec. 6.2.4) into focal and pose, then the same refinement.
// Conventions: cam_from_world pose X_cam = R X + t (COLMAP: x right, y down, z forward); the
// camera is RadialCamera (core/math/radial_camera.h): a point in front of it (X_cam.z > 0) maps to
// the pixel diag(f, a f) d(r^2) p + c with p = X_cam.xy / X_cam.z, r^2 = |p|^2 and
// d = 1 + k1 r^2 + k2 r^4. "Normalised" coordinates are p.
#include <array>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/geometry/ransac_options.h"
#include "core/math/normal_lm.h"
#include "core/math/radial_camera.h"
#include "core/math/rigid3.h"
#include "core/math/robust_loss.h"

namespace reconar {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

// One 2D-3D correspondence: the sample of both estimators.
struct PoseCorrespondence {
  Eigen::Vector2d point;  // normalised image point p (undistorted, K^-1 x)
  Eigen::Vector3d world;  // world point X
};

// |hnormalized(P X) - p|^2 for a projection P with the sign making depths positive in front of
// the camera; the largest double when X is not in front of it (depth <= 0) or the error is not finite.
inline double SquaredReprojectionError(const Matrix34d& P, const PoseCorrespondence& c) {
  const Eigen::Vector3d x = P.leftCols<3>() * c.world + P.col(3);
  if (!(x.z() > 0.0)) return std::numeric_limits<double>::max();
  const double inv_z = 1.0 / x.z();
  const double u = x.x() * inv_z - c.point.x();
  const double v = x.y() * inv_z - c.point.y();
  const double squared = u * u + v * v;
  return squared < std::numeric_limits<double>::infinity() ? squared : std::numeric_limits<double>::max();
}

// Lambda Twist P3P. The model is cam_from_world [R | t].
struct P3PEstimator {
  using Sample = PoseCorrespondence;
  using Model = Matrix34d;
  static constexpr int kMinSamples = 3;
  static constexpr int kMaxModels = 4;

  // Uses the first 3 samples. Returns the number of poses (0..4) that put all three points at
  // positive depth; 0 for degenerate samples (collinear or coincident world points).
  static int Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models);

  // SquaredReprojectionError of each sample (normalised units squared).
  static void Residuals(const Sample* samples, int count, const Model& cam_from_world, double* squared_residuals);
};

// Normalised DLT for P (11 degrees of freedom, so it also absorbs an unknown calibration: in
// focal-scaled coordinates it is the unknown-focal solver). P is scaled so that |P(2, 0:3)| = 1
// and det(P(:, 0:3)) > 0, which makes P X's third coordinate the depth. Residuals are those of
// P3PEstimator.
struct DltPoseEstimator {
  using Sample = PoseCorrespondence;
  using Model = Matrix34d;
  static constexpr int kMinSamples = 6;
  static constexpr int kMaxModels = 1;

  // count >= kMinSamples; the right singular vector of the stacked 2 x 12 constraints for the
  // smallest singular value. Returns 0 for degenerate samples: coincident image or world points,
  // coplanar world points (a rank deficiency of at least 2), a non-finite result.
  static int Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models);

  static void Residuals(const Sample* samples, int count, const Model& P, double* squared_residuals);
};

// The least-squares step of P3P's LO-RANSAC (ransac.h calls Refine with the model whose inliers
// it fits): up to kMaxIterations Levenberg-Marquardt steps on the squared normalised reprojection
// error of the samples, from the pose `start`. The result is a pose [R | t] like P3P's. A linear
// fit is no substitute: the DLT's 11 degrees of freedom fit the few inliers of a nearly flat patch
// in a narrow cone of view with a 3x4 matrix that no rotation is near (left singular values 1.05,
// 0.23, 0.19 on a handheld video), whose nearest pose then holds none of them. (Other local steps
// measured against this one: docs/capture.md.)
struct PoseLocalEstimator {
  using Sample = PoseCorrespondence;
  using Model = Matrix34d;
  static constexpr int kMinSamples = 4;  // 6 parameters, more equations than unknowns
  static constexpr int kMaxModels = 1;
  static constexpr int kMaxIterations = 10;

  // 1 and the refined pose, or 0 when count < kMinSamples or a sample lies behind `start`. No
  // heap allocation.
  static int Refine(const Sample* samples, int count, const Model& start, std::array<Model, kMaxModels>* models);
};

// The nearest rotation and matching translation to a projection P ~ [R | t] (normalised
// coordinates): P(:, 0:3) = U S V^T, R = U V^T, t = P(:, 3) / mean(S). False when det(P(:, 0:3)) <= 0
// or the result is not finite.
bool NearestPose(const Matrix34d& P, Eigen::Matrix3d* R, Eigen::Vector3d* t);

// RQ decomposition of a finite projection P = K [R | t] (H&Z sec. 6.2.4): K upper triangular with
// positive diagonal and K(2, 2) = 1, R a rotation. False when det(P(:, 0:3)) <= 0 or not finite.
bool DecomposeProjection(const Matrix34d& P, Eigen::Matrix3d* K, Eigen::Matrix3d* R, Eigen::Vector3d* t);

// The camera is RadialCamera (core/math/radial_camera.h). InvalidArgument unless focal and aspect
// are positive and every value is finite.
Status CheckCamera(const RadialCamera& camera);

// InvalidArgument naming `function` when the two vectors differ in length.
Status CheckPoseInputSizes(const std::vector<Eigen::Vector2d>& points_px,
                           const std::vector<Eigen::Vector3d>& world_points, const char* function);

// Squared pixel error of X under the camera and cam_from_world (R, t); the largest double when
// X is not in front of the camera.
double SquaredPixelError(const RadialCamera& camera, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                         const Eigen::Vector3d& world_point, const Eigen::Vector2d& pixel);

struct PoseRefinementOptions {
  using Loss = LossType;       // kTrivial, kHuber or kCauchy (core/math/robust_loss.h)
  Loss loss = Loss::kHuber;
  double loss_scale_px = 1.0;  // c
  bool refine_focal = false;   // also refine camera.focal (as log f); k1, k2 stay fixed
  NormalLmOptions lm;

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

// Minimises 1/2 sum_i rho(|camera(R X_i + t) - x_i|^2) over the correspondences `indices` (pixel
// x_i = points_px[indices[i]], X_i = world_points[indices[i]], i < count) with respect to the pose
// (rotation updated as R <- exp(dw) R, translation t <- t + dt) and, with refine_focal, the
// focal. *R, *t and camera->focal are updated when the summary's termination is not
// kNumericFailure. Steps that put a point behind the camera are rejected. No heap allocation;
// the caller validates the input (see RefineAbsolutePose below).
NormalLmSummary RefineAbsolutePoseInPlace(const Eigen::Vector2d* points_px, const Eigen::Vector3d* world_points,
                                          const int* indices, int count, const PoseRefinementOptions& options,
                                          RadialCamera* camera, Eigen::Matrix3d* R, Eigen::Vector3d* t);

// RefineAbsolutePoseInPlace on validated input. InvalidArgument when the vectors differ in
// length, an index is out of range, fewer than 4 indices are given (7 parameters need more than
// 3 points), the options or camera fail Check(), or a point lies behind the initial camera;
// NumericFailure when the initial cost or system is not finite.
Result<NormalLmSummary> RefineAbsolutePose(const std::vector<Eigen::Vector2d>& points_px,
                                           const std::vector<Eigen::Vector3d>& world_points,
                                           const std::vector<int>& indices, const PoseRefinementOptions& options,
                                           RadialCamera* camera, Eigen::Matrix3d* R, Eigen::Vector3d* t);

struct AbsolutePoseOptions {
  // Inlier threshold on the pixel reprojection error; RANSAC uses max_error_px / focal in
  // normalised units (ransac.max_residual is replaced by it).
  double max_error_px = 4.0;
  RansacOptions ransac;
  // Inliers (after refinement, at max_error_px) the pose needs; also the least number of
  // correspondences accepted. >= 4.
  int min_inliers = 12;
  // Robust refinement of the RANSAC pose on its inliers (the loss and LM settings come from
  // `refinement`; its refine_focal is replaced by refine_focal below).
  bool refine = true;
  bool refine_focal = false;  // EstimateAbsolutePose only; the unknown-focal path always refines the focal
  PoseRefinementOptions refinement;
  // RANSAC keeps the pose of least truncated cost. Where the points lie near one plane, another
  // pose (the planar flip) can fit nearly as many of them. With this on, RANSAC runs again on the
  // first pose's outliers; the pose it finds, refined like the first, is taken when it has more
  // inliers over all the correspondences, and otherwise returned as AbsolutePoseResult::alternative
  // for the caller to weigh (EstimateAbsolutePose only).
  bool second_pose_from_outliers = false;

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

// A second pose that also explains many of the correspondences (second_pose_from_outliers).
struct AlternativePose {
  Rigid3 cam_from_world;
  std::vector<int> inliers;  // indices into the input, ascending
};

struct AbsolutePoseResult {
  enum class Outcome {
    kSuccess,                // a pose with >= min_inliers inliers
    kTooFewCorrespondences,  // fewer than max(min_inliers, kMinSamples + 1) usable correspondences
                             // (finite, and undistortable pixels)
    kNoModel,                // RANSAC found no pose with enough inliers to fit: every minimal sample was
                             // degenerate (collinear or coplanar-for-DLT world points) or no pose put
                             // the points in front of the camera
    kTooFewInliers,          // the best pose has fewer than min_inliers inliers
  };
  Outcome outcome = Outcome::kNoModel;
  std::string reason;  // why it failed (empty on success)
  Rigid3 cam_from_world;
  double focal = 0.0;                // the camera's focal, or the estimate (unknown-focal path, refine_focal)
  std::vector<int> inliers;          // indices into the input with pixel error < max_error_px, ascending
  int num_inliers = 0;
  double mean_inlier_error_px = 0.0;  // mean pixel reprojection error of the inliers
  int ransac_iterations = 0;
  std::vector<AlternativePose> alternatives;  // at most one (second_pose_from_outliers)
  bool refined = false;              // the refinement ran and its result was kept
  NormalLmSummary refinement;        // valid when `refined`

  bool success() const { return outcome == Outcome::kSuccess; }
};

const char* AbsolutePoseOutcomeName(AbsolutePoseResult::Outcome outcome);

// The pose of a camera of known intrinsics from points_px[i] <-> world_points[i]. InvalidArgument
// when the vectors differ in length or the camera or options fail Check(); every other outcome is
// an AbsolutePoseResult whose `outcome` and `reason` say what happened. Non-finite or
// non-undistortable correspondences are never inliers.
Result<AbsolutePoseResult> EstimateAbsolutePose(const std::vector<Eigen::Vector2d>& points_px,
                                                const std::vector<Eigen::Vector3d>& world_points,
                                                const RadialCamera& camera,
                                                const AbsolutePoseOptions& options);

// The same for an unknown focal length: camera.focal is only a prior that scales the coordinates
// (and the pixel threshold) for the DLT; the principal point is taken as known. Distortion is
// ignored by the DLT and modelled (with k1, k2 fixed) by the refinement. Needs non-coplanar
// world points. result.focal is the mean of K(0, 0) and K(1, 1) of the RQ decomposition, refined
// with the pose when options.refine.
Result<AbsolutePoseResult> EstimateAbsolutePoseUnknownFocal(const std::vector<Eigen::Vector2d>& points_px,
                                                            const std::vector<Eigen::Vector3d>& world_points,
                                                            const RadialCamera& camera,
                                                            const AbsolutePoseOptions& options);

}  // namespace reconar
