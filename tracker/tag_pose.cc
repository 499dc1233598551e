#include "tracker/tag_pose.h"

#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "core/geometry/absolute_pose.h"
#include "core/geometry/correspondence.h"
#include "core/geometry/homography_four_point.h"
#include "core/math/rotation.h"

namespace reconar {
namespace {

// Least-squares translation for a known rotation: (R X_i + t) parallel to (q_i, 1), two linear
// equations per point.
bool TranslationForRotation(const Eigen::Matrix3d& R, const Eigen::Vector2d* plane_points,
                            const Eigen::Vector2d* normalized, int count, Eigen::Vector3d* t) {
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d P = R.leftCols<2>() * plane_points[i];
    const Eigen::Vector2d& q = normalized[i];
    Eigen::Matrix<double, 2, 3> a;
    a << 1.0, 0.0, -q.x(), 0.0, 1.0, -q.y();
    const Eigen::Vector2d b(-(P.x() - q.x() * P.z()), -(P.y() - q.y() * P.z()));
    ata += a.transpose() * a;
    atb += a.transpose() * b;
  }
  Eigen::FullPivLU<Eigen::Matrix3d> lu(ata);
  if (!lu.isInvertible()) return false;
  *t = lu.solve(atb);
  return t->allFinite();
}

double RmsNormalized(const Rigid3& cam_from_world, const Eigen::Vector3d* world_points,
                     const Eigen::Vector2d* normalized, int count, double fx, double fy) {
  double sum = 0.0;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d X = cam_from_world * world_points[i];
    if (!(X.z() > 0.0)) return std::numeric_limits<double>::infinity();
    const Eigen::Vector2d d = X.head<2>() / X.z() - normalized[i];
    sum += fx * fx * d.x() * d.x() + fy * fy * d.y() * d.y();
  }
  const double rms = std::sqrt(sum / count);
  return std::isfinite(rms) ? rms : std::numeric_limits<double>::infinity();
}

// LM on normalised points scaled by one focal sqrt(fx fy) (RefineAbsolutePoseInPlace models a single
// focal; the scale only weights x against y by fx / fy ~ 1).
void RefineOnNormalized(const Eigen::Vector3d* world_points, const Eigen::Vector2d* normalized, int count,
                        const CameraIntrinsics& intrinsics, const NormalLmOptions& lm, Rigid3* cam_from_world) {
  const double focal = std::sqrt(intrinsics.fx * intrinsics.fy);
  Eigen::Vector2d scaled[kMaxRefinementPoints];
  int indices[kMaxRefinementPoints];
  for (int i = 0; i < count; ++i) {
    scaled[i] = focal * normalized[i];
    indices[i] = i;
  }
  PoseRefinementOptions options;
  options.loss = LossType::kTrivial;
  options.lm = lm;
  RadialCamera camera;
  camera.focal = focal;
  Eigen::Matrix3d R = cam_from_world->rotation;
  Eigen::Vector3d t = cam_from_world->translation;
  const NormalLmSummary summary =
      RefineAbsolutePoseInPlace(scaled, world_points, indices, count, options, &camera, &R, &t);
  if (summary.termination != NormalLmSummary::Termination::kNumericFailure && R.allFinite() && t.allFinite()) {
    cam_from_world->rotation = NearestRotation(R);
    cam_from_world->translation = t;
  }
}

}  // namespace

std::array<Eigen::Vector3d, 4> TagCornersInTagFrame(double tag_size) {
  const double h = 0.5 * tag_size;
  return {Eigen::Vector3d(-h, -h, 0.0), Eigen::Vector3d(h, -h, 0.0), Eigen::Vector3d(h, h, 0.0),
          Eigen::Vector3d(-h, h, 0.0)};
}

int IppePoses(const Eigen::Vector2d* plane_points, const Eigen::Vector2d* normalized, int count,
              std::array<Rigid3, 2>* cam_from_plane) {
  if (count < 4 || count > kMaxRefinementPoints) return 0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int i = 0; i < count; ++i) centroid += plane_points[i];
  centroid /= count;
  Correspondence samples[kMaxRefinementPoints];
  Eigen::Vector2d centred[kMaxRefinementPoints];
  for (int i = 0; i < count; ++i) {
    centred[i] = plane_points[i] - centroid;
    samples[i] = Correspondence{centred[i], normalized[i]};
  }
  std::array<Eigen::Matrix3d, 1> models;
  if (HomographyFourPoint::Estimate(samples, count, &models) != 1) return 0;
  Eigen::Matrix3d H = models[0];
  // Collinear plane or image points make the homography singular.
  const double scale = H.norm();
  if (!(std::abs(H.determinant()) > 1e-9 * scale * scale * scale)) return 0;
  if (!(std::abs(H(2, 2)) > 1e-12)) return 0;
  H /= H(2, 2);
  // Image of the centroid v and the Jacobian J of plane -> normalised image at the centroid.
  const Eigen::Vector2d v(H(0, 2), H(1, 2));
  const Eigen::Matrix2d J = H.topLeftCorner<2, 2>() - v * H.block<1, 2>(2, 0);
  // Rv turns the optical axis onto the ray through v; then J = B R~(0:2, 0:2) / depth.
  const Eigen::Matrix3d Rv =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), Eigen::Vector3d(v.x(), v.y(), 1.0))
          .toRotationMatrix();
  Eigen::Matrix<double, 2, 3> projector;
  projector << 1.0, 0.0, -v.x(), 0.0, 1.0, -v.y();
  const Eigen::Matrix2d B = projector * Rv.leftCols<2>();
  if (!(std::abs(B.determinant()) > 1e-12)) return 0;
  const Eigen::Matrix2d A = B.inverse() * J;
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(A);
  const double gamma = svd.singularValues()(0);
  if (!(gamma > 0.0) || !std::isfinite(gamma)) return 0;
  const Eigen::Matrix2d R22 = A / gamma;
  const double b0 = std::sqrt(std::max(0.0, 1.0 - R22.col(0).squaredNorm()));
  double b1 = std::sqrt(std::max(0.0, 1.0 - R22.col(1).squaredNorm()));
  if (R22.col(0).dot(R22.col(1)) > 0.0) b1 = -b1;  // makes the first two columns orthogonal
  for (int k = 0; k < 2; ++k) {
    const double sign = k == 0 ? 1.0 : -1.0;
    const Eigen::Vector3d c0(R22(0, 0), R22(1, 0), sign * b0);
    const Eigen::Vector3d c1(R22(0, 1), R22(1, 1), sign * b1);
    Eigen::Matrix3d R_tilde;
    R_tilde.col(0) = c0;
    R_tilde.col(1) = c1;
    R_tilde.col(2) = c0.cross(c1);
    const Eigen::Matrix3d R = NearestRotation(Rv * R_tilde);
    Eigen::Vector3d t;
    if (!R.allFinite() || !TranslationForRotation(R, centred, normalized, count, &t)) return 0;
    (*cam_from_plane)[k].rotation = R;
    // X_cam = R (x - centroid) + t.
    (*cam_from_plane)[k].translation = t - R.leftCols<2>() * centroid;
  }
  return 2;
}

double RmsReprojectionErrorPx(const Rigid3& cam_from_world, const Eigen::Vector3d* world_points,
                              const Eigen::Vector2d* normalized, int count, const CameraIntrinsics& intrinsics) {
  return RmsNormalized(cam_from_world, world_points, normalized, count, intrinsics.fx, intrinsics.fy);
}

Status PlanarPoseOptions::Check() const { return lm.Check().WithContext("PlanarPoseOptions.lm"); }

Result<TagPose> EstimatePlanarPose(const Eigen::Vector2d* plane_points, const Eigen::Vector2d* pixels, int count,
                                   const CameraIntrinsics& intrinsics, const PlanarPoseOptions& options) {
  if (!intrinsics.valid()) return InvalidArgument("EstimatePlanarPose: intrinsics need fx > 0 and fy > 0");
  if (count < 4 || count > kMaxRefinementPoints) {
    return InvalidArgument("EstimatePlanarPose: needs 4.." + std::to_string(kMaxRefinementPoints) + " points, got " +
                           std::to_string(count));
  }
  RECONAR_RETURN_IF_ERROR(options.Check());
  Eigen::Vector2d normalized[kMaxRefinementPoints];
  Eigen::Vector3d world[kMaxRefinementPoints];
  for (int i = 0; i < count; ++i) {
    normalized[i] = intrinsics.Unproject(pixels[i]);
    world[i] = Eigen::Vector3d(plane_points[i].x(), plane_points[i].y(), 0.0);
    if (!normalized[i].allFinite() || !world[i].allFinite()) {
      return InvalidArgument("EstimatePlanarPose: point " + std::to_string(i) + " is not finite");
    }
  }
  std::array<Rigid3, 2> candidates;
  if (IppePoses(plane_points, normalized, count, &candidates) != 2) {
    return FailedPrecondition("EstimatePlanarPose: degenerate points (collinear or coincident)");
  }
  double rms[2];
  for (int k = 0; k < 2; ++k) {
    if (options.refine) RefineOnNormalized(world, normalized, count, intrinsics, options.lm, &candidates[k]);
    rms[k] = RmsNormalized(candidates[k], world, normalized, count, intrinsics.fx, intrinsics.fy);
  }
  const int best = rms[1] < rms[0] ? 1 : 0;
  if (!std::isfinite(rms[best])) {
    return FailedPrecondition("EstimatePlanarPose: no pose puts the points in front of the camera");
  }
  TagPose pose;
  pose.cam_from_tag = candidates[best];
  pose.rms_reprojection_px = rms[best];
  pose.alternative_cam_from_tag = candidates[1 - best];
  pose.alternative_rms_reprojection_px = rms[1 - best];
  pose.ambiguity_ratio = std::isfinite(rms[1 - best]) && rms[1 - best] > 0.0 ? rms[best] / rms[1 - best]
                         : rms[1 - best] > 0.0                               ? 0.0
                                                                             : 1.0;
  return pose;
}

Result<TagPose> EstimateTagPose(const Eigen::Vector2d (&corners_px)[4], double tag_size,
                                const CameraIntrinsics& intrinsics, const PlanarPoseOptions& options) {
  if (!(tag_size > 0.0) || !std::isfinite(tag_size)) {
    return InvalidArgument("EstimateTagPose: tag size must be > 0, got " + std::to_string(tag_size));
  }
  const std::array<Eigen::Vector3d, 4> corners = TagCornersInTagFrame(tag_size);
  const Eigen::Vector2d plane[4] = {corners[0].head<2>(), corners[1].head<2>(), corners[2].head<2>(),
                                    corners[3].head<2>()};
  return EstimatePlanarPose(plane, corners_px, 4, intrinsics, options);
}

double RefinePoseOnPoints(const Eigen::Vector3d* world_points, const Eigen::Vector2d* pixels, int count,
                          const CameraIntrinsics& intrinsics, const NormalLmOptions& lm, Rigid3* cam_from_world) {
  if (count < 1 || count > kMaxRefinementPoints || !intrinsics.valid()) {
    return std::numeric_limits<double>::infinity();
  }
  Eigen::Vector2d normalized[kMaxRefinementPoints];
  for (int i = 0; i < count; ++i) normalized[i] = intrinsics.Unproject(pixels[i]);
  if (count >= 4) RefineOnNormalized(world_points, normalized, count, intrinsics, lm, cam_from_world);
  return RmsNormalized(*cam_from_world, world_points, normalized, count, intrinsics.fx, intrinsics.fy);
}

}  // namespace reconar
