// Robust Levenberg-Marquardt refinement of an absolute pose (and focal) on the pixel reprojection
// error (RefineAbsolutePose in absolute_pose.h), and the camera checks it shares with the
// estimators.
#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <string>

#include "core/geometry/absolute_pose.h"
#include "core/math/rotation.h"

namespace reconar {
namespace {

// Correspondences picked by index from parallel arrays (RefineAbsolutePoseInPlace): pixels,
// projected through the camera.
struct IndexedCorrespondences {
  static constexpr bool kNormalised = false;
  const Eigen::Vector2d* points;
  const Eigen::Vector3d* world_points;
  const int* indices;
  int count;
  const Eigen::Vector2d& Point(int k) const { return points[indices[k]]; }
  const Eigen::Vector3d& World(int k) const { return world_points[indices[k]]; }
};

// The samples of the RANSAC loop (PoseLocalEstimator): normalised points, no camera.
struct SampleCorrespondences {
  static constexpr bool kNormalised = true;
  const PoseCorrespondence* samples;
  int count;
  const Eigen::Vector2d& Point(int k) const { return samples[k].point; }
  const Eigen::Vector3d& World(int k) const { return samples[k].world; }
};

// The NormalLmSolve problem: pose (dw, dt) and, when kRefineFocal, log focal, over the
// reprojection errors camera(R X + t) - x of `Correspondences`.
template <bool kRefineFocal, typename Correspondences>
class PoseRefinementProblem {
 public:
  static constexpr int kDim = kRefineFocal ? 7 : 6;
  struct State {
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    double focal;
  };
  using Tangent = Eigen::Matrix<double, kDim, 1>;

  PoseRefinementProblem(const Correspondences& correspondences, const RadialCamera& camera, LossType loss,
                        double loss_scale)
      : correspondences_(correspondences), camera_(camera), loss_{loss, loss_scale} {}

  bool Linearize(const State& x, Eigen::Matrix<double, kDim, kDim>* jtj, Tangent* jtr, double* cost) const {
    jtj->setZero();
    jtr->setZero();
    *cost = 0.0;
    for (int k = 0; k < correspondences_.count; ++k) {
      const Eigen::Vector3d rotated = x.R * correspondences_.World(k);
      const Eigen::Vector3d X = rotated + x.t;
      if (!(X.z() > 0.0)) return false;
      const double inv_z = 1.0 / X.z();
      const Eigen::Vector2d p(X.x() * inv_z, X.y() * inv_z);
      Eigen::Matrix<double, 2, 3> dp_dX;
      dp_dX << inv_z, 0.0, -p.x() * inv_z, 0.0, inv_z, -p.y() * inv_z;
      Eigen::Vector2d e;
      Eigen::Matrix<double, 2, 3> de_dX;
      RadialCamera camera = camera_;
      if constexpr (Correspondences::kNormalised) {
        e = p - correspondences_.Point(k);
        de_dX = dp_dX;
      } else {
        camera.focal = x.focal;
        e = camera.PixelFromNormalised(p) - correspondences_.Point(k);
        de_dX = camera.PixelFromNormalisedJacobian(p) * dp_dX;
      }
      Eigen::Matrix<double, 2, kDim> J;
      J.template leftCols<3>() = -de_dX * Skew(rotated);  // d(exp(dw) R X) / d dw = -[R X]x
      J.template middleCols<3>(3) = de_dX;
      if constexpr (kRefineFocal) {  // f = f0 exp(df)
        static_assert(!Correspondences::kNormalised, "normalised points have no focal");
        const double d = camera.Distortion(p.squaredNorm());
        J.col(6) = Eigen::Vector2d(x.focal * d * p.x(), camera.aspect * x.focal * d * p.y());
      }

      double rho = 0.0, weight = 0.0;
      loss_.Evaluate(e.squaredNorm(), &rho, &weight);
      jtj->noalias() += weight * J.transpose() * J;
      jtr->noalias() += weight * J.transpose() * e;
      *cost += 0.5 * rho;
    }
    return true;
  }

  State Plus(const State& x, const Tangent& dx) const {
    State next;
    next.R = RotationFromAngleAxis(dx.template head<3>()) * x.R;
    next.t = x.t + dx.template segment<3>(3);
    next.focal = x.focal;
    if constexpr (kRefineFocal) next.focal = x.focal * std::exp(dx(6));
    return next;
  }

  double Norm(const State& x) const { return 1.0 + x.t.norm(); }

 private:
  Correspondences correspondences_;
  RadialCamera camera_;
  RobustLoss loss_;
};

template <bool kRefineFocal>
NormalLmSummary SolvePoseRefinement(const Eigen::Vector2d* points_px, const Eigen::Vector3d* world_points,
                                    const int* indices, int count, const PoseRefinementOptions& options,
                                    RadialCamera* camera, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  using Problem = PoseRefinementProblem<kRefineFocal, IndexedCorrespondences>;
  const Problem problem(IndexedCorrespondences{points_px, world_points, indices, count}, *camera, options.loss,
                        options.loss_scale_px);
  typename Problem::State state{*R, *t, camera->focal};
  const NormalLmSummary summary = NormalLmSolve(problem, options.lm, &state);
  if (summary.termination != NormalLmSummary::Termination::kNumericFailure) {
    *R = state.R;
    *t = state.t;
    camera->focal = state.focal;
  }
  return summary;
}

}  // namespace

int PoseLocalEstimator::Refine(const Sample* samples, int count, const Model& start,
                               std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  using Problem = PoseRefinementProblem<false, SampleCorrespondences>;
  const Problem problem(SampleCorrespondences{samples, count}, RadialCamera{}, LossType::kTrivial, 1.0);
  Problem::State state{start.leftCols<3>(), start.col(3), 1.0};
  // The start is a P3P pose or an earlier step's; its rotation is orthonormal to rounding.
  LmOptions lm;
  lm.max_iterations = kMaxIterations;
  const NormalLmSummary summary = NormalLmSolve(problem, lm, &state);
  if (summary.termination == NormalLmSummary::Termination::kNumericFailure) return 0;
  Model& pose = (*models)[0];
  pose.leftCols<3>() = state.R;
  pose.col(3) = state.t;
  return pose.allFinite() ? 1 : 0;
}

Status CheckCamera(const RadialCamera& camera) {
  if (!(camera.focal > 0.0) || !std::isfinite(camera.focal)) {
    return InvalidArgument("camera focal must be positive and finite, got " + std::to_string(camera.focal));
  }
  if (!(camera.aspect > 0.0) || !std::isfinite(camera.aspect)) {
    return InvalidArgument("camera aspect must be positive and finite, got " + std::to_string(camera.aspect));
  }
  if (!camera.IsValid()) return InvalidArgument("camera: cx, cy, k1 and k2 must be finite");
  return Status::Ok();
}

Status CheckPoseInputSizes(const std::vector<Eigen::Vector2d>& points_px,
                           const std::vector<Eigen::Vector3d>& world_points, const char* function) {
  if (points_px.size() != world_points.size()) {
    return InvalidArgument(std::string(function) + ": " + std::to_string(points_px.size()) + " image points but " +
                           std::to_string(world_points.size()) + " world points");
  }
  return Status::Ok();
}

double SquaredPixelError(const RadialCamera& camera, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                         const Eigen::Vector3d& world_point, const Eigen::Vector2d& pixel) {
  const Eigen::Vector3d X = R * world_point + t;
  if (!(X.z() > 0.0)) return std::numeric_limits<double>::max();
  const double squared = (camera.Project(X) - pixel).squaredNorm();
  return squared < std::numeric_limits<double>::infinity() ? squared : std::numeric_limits<double>::max();
}

Status PoseRefinementOptions::Check() const {
  if (!(loss_scale_px > 0.0) || !std::isfinite(loss_scale_px)) {
    return InvalidArgument("PoseRefinementOptions.loss_scale_px must be positive and finite, got " +
                           std::to_string(loss_scale_px));
  }
  return lm.Check().WithContext("PoseRefinementOptions.lm");
}

NormalLmSummary RefineAbsolutePoseInPlace(const Eigen::Vector2d* points_px, const Eigen::Vector3d* world_points,
                                          const int* indices, int count, const PoseRefinementOptions& options,
                                          RadialCamera* camera, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  if (options.refine_focal) {
    return SolvePoseRefinement<true>(points_px, world_points, indices, count, options, camera, R, t);
  }
  return SolvePoseRefinement<false>(points_px, world_points, indices, count, options, camera, R, t);
}

Result<NormalLmSummary> RefineAbsolutePose(const std::vector<Eigen::Vector2d>& points_px,
                                           const std::vector<Eigen::Vector3d>& world_points,
                                           const std::vector<int>& indices, const PoseRefinementOptions& options,
                                           RadialCamera* camera, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(CheckCamera(*camera));
  RECONAR_RETURN_IF_ERROR(CheckPoseInputSizes(points_px, world_points, "RefineAbsolutePose"));
  if (indices.size() < 4) {
    return InvalidArgument("RefineAbsolutePose: " + std::to_string(indices.size()) +
                           " correspondences, need at least 4");
  }
  if (!R->allFinite() || !t->allFinite()) return InvalidArgument("RefineAbsolutePose: the initial pose is not finite");
  for (int i : indices) {
    if (i < 0 || static_cast<size_t>(i) >= points_px.size()) {
      return InvalidArgument("RefineAbsolutePose: index " + std::to_string(i) + " out of range [0, " +
                             std::to_string(points_px.size()) + ")");
    }
    if (!points_px[i].allFinite() || !world_points[i].allFinite()) {
      return InvalidArgument("RefineAbsolutePose: correspondence " + std::to_string(i) + " is not finite");
    }
    if (!((*R * world_points[i] + *t).z() > 0.0)) {
      return InvalidArgument("RefineAbsolutePose: world point " + std::to_string(i) +
                             " lies behind the initial camera");
    }
  }
  const NormalLmSummary summary = RefineAbsolutePoseInPlace(points_px.data(), world_points.data(), indices.data(),
                                                            static_cast<int>(indices.size()), options, camera, R, t);
  if (summary.termination == NormalLmSummary::Termination::kNumericFailure) {
    return NumericFailure("RefineAbsolutePose: the initial cost or normal equations are not finite");
  }
  return summary;
}

}  // namespace reconar
