#pragma once
// How well a bundle adjustment determined its points, for measurements in the model
// (`reconar measure`). At the adjusted parameters the Gauss-Newton normal matrix J^T J (the
// weighted residuals' Jacobian: every free camera parameter, shared intrinsics as one block per
// group, and every point) is the inverse covariance of the parameters up to the variance factor
// sigma0^2, estimated from the residuals a posteriori (their weighted sum of squares over the
// redundancy: observations x 2 - unknowns + 7). The points are eliminated as in the adjustment
// (Schur complement, Triggs et al. 2000, sec. 6.1): with U, W, V the camera, camera-point and
// point blocks and S = U - W V^-1 W^T the reduced camera system, the covariance of points i, j is
//   sigma0^2 (delta_ij V_i^-1 + V_i^-1 W_i^T S^-1 W_j V_j^-1),
// so the variance of a function f of points, with gradient g_j at point j, is
//   sigma0^2 (sum_j g_j^T V_j^-1 g_j + y^T S^-1 y),  y = sum_j W_j V_j^-1 g_j:
// one solve with the factored S per function. The model's similarity (7 degrees of freedom) is
// not fixed by the observations, so S is singular; it is factored with a damping of
// gauge_damping x its largest diagonal entry on the camera unknowns, which leaves the variance of
// every function the similarity does not change (ratios of distances, angles) as it is. A
// distance in metres is such a function once divided by the scale's own measure (the mean edge
// of the scale tags in the model): the caller forms it so.
#include <array>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "core/base/status.h"
#include "core/optim/bal_problem.h"
#include "core/optim/bundle_adjuster.h"

namespace reconar {

struct PointGradient {
  int point = -1;  // index into the problem's points
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
};

struct AdjustmentCovarianceOptions {
  double gauge_damping = 1e-10;
};

class AdjustmentCovariance {
 public:
  // `problem` at its adjusted parameters, `constancy` as the adjustment had it (the constant cameras
  // and points, constant camera parameters, intrinsics groups). InvalidArgument for a malformed
  // problem or constancy, FailedPrecondition when the observations leave no redundancy or a point
  // the reduced camera system cannot be factored.
  static Result<AdjustmentCovariance> Compute(const RadialProblem& problem, const BundleAdjustmentConstancy& constancy,
                                              const AdjustmentCovarianceOptions& options = {});

  double variance_factor() const { return variance_factor_; }  // sigma0^2, squared weighted pixels
  int redundancy() const { return redundancy_; }
  int camera_unknowns() const { return static_cast<int>(s_size_); }
  // Whether the point's observations fix it (a free point seen from two directions).
  bool determined(int point) const {
    return point >= 0 && static_cast<size_t>(point) < points_.size() && !points_[static_cast<size_t>(point)].constant &&
           points_[static_cast<size_t>(point)].determined;
  }

  // A point the adjustment did not have (a pick in the photos), at `position`, seen by these
  // observations (their `point` is ignored) of the problem's cameras: its block as if it had been
  // adjusted with the others, without what its observations would have told about the cameras
  // (negligible beside the model's, and if anything it makes the point's variance larger).
  // `residual_projections`, when given (one per observation), multiply each weighted residual:
  // e.g. e e^T with a unit e keeps only its component along e (an observation that fixes the point
  // along one image direction only). Returns its index for PointGradient; it is undetermined
  // (infinite variance) when its observations do not fix it. InvalidArgument for an observation
  // of a missing camera or projections that do not match the observations.
  Result<int> AddPoint(const Eigen::Vector3d& position, const std::vector<BalObservation>& observations,
                       const std::vector<Eigen::Matrix2d>& residual_projections = {});

  // Drops the points added after the first `count` (AddPoint's), so that a caller adding points
  // for one question at a time does not grow it. The adjusted points stay whatever `count` says.
  void RemoveAddedPoints(int count);

  // The variance of a function of the points with these gradients (one entry per point it depends
  // on), including sigma0^2. A constant point contributes nothing; a point its observations do not
  // fix (fewer than two views, or all along one ray) makes it infinite.
  double Variance(const std::vector<PointGradient>& gradients) const;

 private:
  struct PointBlock {
    Eigen::Matrix3d v_inverse = Eigen::Matrix3d::Zero();
    std::vector<int> unknowns;  // camera unknowns its observations touch
    Eigen::MatrixXd w;          // unknowns.size() x 3: W_j restricted to them
    bool constant = false;
    bool determined = true;
  };
  // The point's V^-1, W and unknowns from its observations (their residuals projected when
  // `residual_projections` is not null); adds the cameras' J^T J to *s unless null. Returns the
  // observations' weighted squared residuals.
  double FillPointBlock(const double* point, const std::vector<BalObservation>& observations,
                        const std::vector<Eigen::Matrix2d>* residual_projections, Eigen::MatrixXd* s, PointBlock* block);

  std::vector<PointBlock> points_;
  size_t adjusted_points_ = 0;  // the problem's; AddPoint's follow
  std::vector<double> cameras_;                                          // the problem's camera blocks
  std::vector<std::array<int, RadialProblem::kCameraSize>> camera_unknowns_;  // per camera parameter, -1: constant
  std::vector<int> row_of_;                                              // scratch: unknown -> row of a point's W
  Eigen::LLT<Eigen::MatrixXd> s_factor_;  // of the damped S
  size_t s_size_ = 0;
  double variance_factor_ = 0.0;
  int redundancy_ = 0;
};

}  // namespace reconar
