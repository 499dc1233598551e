#include "core/optim/adjustment_covariance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "core/optim/radial_camera_model.h"

namespace reconar {
namespace {

constexpr int kCameraSize = RadialProblem::kCameraSize;

// The unknown of each parameter of each camera block (-1: held constant).
struct CameraUnknowns {
  std::vector<std::array<int, kCameraSize>> of_camera;
  int count = 0;
};

Result<CameraUnknowns> NumberCameraUnknowns(const RadialProblem& problem, const BundleAdjustmentConstancy& constancy) {
  const int cameras = problem.num_cameras();
  if ((!constancy.constant_cameras.empty() && static_cast<int>(constancy.constant_cameras.size()) != cameras) ||
      (!constancy.intrinsics_group.empty() && static_cast<int>(constancy.intrinsics_group.size()) != cameras) ||
      (!constancy.constant_points.empty() &&
       static_cast<int>(constancy.constant_points.size()) != problem.num_points())) {
    return InvalidArgument("adjustment covariance: the constancy vectors do not match the problem");
  }
  std::array<bool, kCameraSize> constant_parameter{};
  for (int index : constancy.constant_camera_parameters) {
    if (index < 0 || index >= kCameraSize) return InvalidArgument("adjustment covariance: no camera parameter " + std::to_string(index));
    constant_parameter[static_cast<size_t>(index)] = true;
  }
  CameraUnknowns unknowns;
  unknowns.of_camera.assign(static_cast<size_t>(cameras), {});
  std::vector<std::array<int, kCameraSize>> of_group;
  for (int i = 0; i < cameras; ++i) {
    std::array<int, kCameraSize>& mine = unknowns.of_camera[static_cast<size_t>(i)];
    mine.fill(-1);
    if (!constancy.constant_cameras.empty() && constancy.constant_cameras[static_cast<size_t>(i)]) continue;
    const int group = constancy.intrinsics_group.empty() ? -1 : constancy.intrinsics_group[static_cast<size_t>(i)];
    if (group >= 0 && static_cast<size_t>(group) >= of_group.size()) {
      std::array<int, kCameraSize> none;
      none.fill(-2);  // not numbered yet
      of_group.resize(static_cast<size_t>(group) + 1, none);
    }
    for (int d = 0; d < kCameraSize; ++d) {
      if (constant_parameter[static_cast<size_t>(d)]) continue;
      if (d < 6 || group < 0) {
        mine[static_cast<size_t>(d)] = unknowns.count++;
        continue;
      }
      int& shared = of_group[static_cast<size_t>(group)][static_cast<size_t>(d)];
      if (shared == -2) shared = unknowns.count++;
      mine[static_cast<size_t>(d)] = shared;
    }
  }
  return unknowns;
}

}  // namespace

Result<AdjustmentCovariance> AdjustmentCovariance::Compute(const RadialProblem& problem,
                                                           const BundleAdjustmentConstancy& constancy,
                                                           const AdjustmentCovarianceOptions& options) {
  RECONAR_RETURN_IF_ERROR(problem.Check());
  RECONAR_ASSIGN_OR_RETURN(const CameraUnknowns unknowns, NumberCameraUnknowns(problem, constancy));
  AdjustmentCovariance covariance;
  covariance.s_size_ = static_cast<size_t>(unknowns.count);
  covariance.row_of_.assign(covariance.s_size_, -1);
  const auto n = static_cast<Eigen::Index>(unknowns.count);
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(n, n);

  std::vector<std::vector<int>> observations_of(static_cast<size_t>(problem.num_points()));
  for (size_t k = 0; k < problem.observations.size(); ++k) {
    observations_of[static_cast<size_t>(problem.observations[k].point)].push_back(static_cast<int>(k));
  }
  covariance.points_.resize(observations_of.size());
  covariance.adjusted_points_ = observations_of.size();
  covariance.cameras_ = problem.cameras;
  covariance.camera_unknowns_ = unknowns.of_camera;
  double weighted_squares = 0.0;
  int free_points = 0;
  bool any_constant_camera = false;
  for (char c : constancy.constant_cameras) any_constant_camera = any_constant_camera || c != 0;
  for (size_t j = 0; j < observations_of.size(); ++j) {
    PointBlock& block = covariance.points_[j];
    block.constant = !constancy.constant_points.empty() && constancy.constant_points[j];
    std::vector<BalObservation> observations;
    observations.reserve(observations_of[j].size());
    for (int k : observations_of[j]) observations.push_back(problem.observations[static_cast<size_t>(k)]);
    weighted_squares += covariance.FillPointBlock(problem.point(static_cast<int>(j)), observations, nullptr, &s, &block);
    if (block.constant) continue;
    ++free_points;
    if (!block.determined) continue;
    const Eigen::MatrixXd wv = block.w * block.v_inverse;
    const Eigen::MatrixXd update = wv * block.w.transpose();
    for (size_t a = 0; a < block.unknowns.size(); ++a) {
      for (size_t b = 0; b < block.unknowns.size(); ++b) {
        s(block.unknowns[a], block.unknowns[b]) -= update(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
      }
    }
  }
  covariance.redundancy_ = 2 * static_cast<int>(problem.observations.size()) - unknowns.count - 3 * free_points +
                           (any_constant_camera ? 0 : 7);
  if (covariance.redundancy_ <= 0) {
    return FailedPrecondition("adjustment covariance: the observations leave no redundancy (" +
                              std::to_string(covariance.redundancy_) + ")");
  }
  covariance.variance_factor_ = weighted_squares / covariance.redundancy_;
  if (n > 0) {
    const double damping = options.gauge_damping * s.diagonal().maxCoeff();
    s.diagonal().array() += damping;
    covariance.s_factor_.compute(s);
    if (covariance.s_factor_.info() != Eigen::Success) {
      return FailedPrecondition("adjustment covariance: the reduced camera system is not positive definite");
    }
  }
  return covariance;
}

double AdjustmentCovariance::FillPointBlock(const double* point, const std::vector<BalObservation>& observations,
                                            const std::vector<Eigen::Matrix2d>* residual_projections, Eigen::MatrixXd* s,
                                            PointBlock* block) {
  double weighted_squares = 0.0;
  Eigen::Matrix3d v = Eigen::Matrix3d::Zero();
  std::vector<Eigen::RowVector3d> w_rows;
  for (size_t k = 0; k < observations.size(); ++k) {
    const BalObservation& o = observations[k];
    Eigen::Matrix<double, 2, kCameraSize, Eigen::RowMajor> jc;
    Eigen::Matrix<double, 2, 3, Eigen::RowMajor> jp;
    double predicted[2];
    const double* camera_block = cameras_.data() + static_cast<size_t>(o.camera) * kCameraSize;
    if (!ProjectRadial(camera_block, point, predicted, jc.data(), jp.data())) continue;
    Eigen::Vector2d r = o.weight * Eigen::Vector2d(predicted[0] - o.x, predicted[1] - o.y);
    jc *= o.weight;
    jp *= o.weight;
    if (residual_projections != nullptr) {
      const Eigen::Matrix2d& projection = (*residual_projections)[k];
      r = projection * r;
      jc = projection * jc;
      jp = projection * jp;
    }
    weighted_squares += r.squaredNorm();
    const std::array<int, kCameraSize>& camera = camera_unknowns_[static_cast<size_t>(o.camera)];
    for (int a = 0; a < kCameraSize; ++a) {
      const int ua = camera[static_cast<size_t>(a)];
      if (ua < 0) continue;
      if (s != nullptr) {
        for (int b = 0; b < kCameraSize; ++b) {
          const int ub = camera[static_cast<size_t>(b)];
          if (ub >= 0) (*s)(ua, ub) += jc.col(a).dot(jc.col(b));
        }
      }
      if (block->constant) continue;
      if (row_of_[static_cast<size_t>(ua)] < 0) {
        row_of_[static_cast<size_t>(ua)] = static_cast<int>(block->unknowns.size());
        block->unknowns.push_back(ua);
        w_rows.push_back(Eigen::RowVector3d::Zero());
      }
      w_rows[static_cast<size_t>(row_of_[static_cast<size_t>(ua)])] += jc.col(a).transpose() * jp;
    }
    if (!block->constant) v += jp.transpose() * jp;
  }
  for (int u : block->unknowns) row_of_[static_cast<size_t>(u)] = -1;
  if (block->constant) return weighted_squares;
  block->w.resize(static_cast<Eigen::Index>(block->unknowns.size()), 3);
  for (size_t r = 0; r < w_rows.size(); ++r) block->w.row(static_cast<Eigen::Index>(r)) = w_rows[r];
  // A point fixed along one ray only (or seen once) has a V without a well-conditioned inverse.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(v);
  const Eigen::Vector3d values = eigen.eigenvalues();  // increasing
  block->determined = eigen.info() == Eigen::Success && values(0) > 1e-12 * values(2) && values(0) > 0.0;
  if (block->determined) {
    block->v_inverse = eigen.eigenvectors() * values.cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose();
  }
  return weighted_squares;
}

Result<int> AdjustmentCovariance::AddPoint(const Eigen::Vector3d& position, const std::vector<BalObservation>& observations,
                                           const std::vector<Eigen::Matrix2d>& residual_projections) {
  if (!residual_projections.empty() && residual_projections.size() != observations.size()) {
    return InvalidArgument("adjustment covariance: an added point's residual projections do not match its observations");
  }
  const int cameras = static_cast<int>(camera_unknowns_.size());
  for (const BalObservation& o : observations) {
    if (o.camera < 0 || o.camera >= cameras) {
      return InvalidArgument("adjustment covariance: an added point's observation names camera " +
                             std::to_string(o.camera) + " of " + std::to_string(cameras));
    }
  }
  PointBlock block;
  FillPointBlock(position.data(), observations, residual_projections.empty() ? nullptr : &residual_projections, nullptr,
                 &block);
  points_.push_back(std::move(block));
  return static_cast<int>(points_.size()) - 1;
}

void AdjustmentCovariance::RemoveAddedPoints(int count) {
  const size_t keep = std::max(adjusted_points_, static_cast<size_t>(std::max(count, 0)));
  if (keep < points_.size()) points_.resize(keep);
}

double AdjustmentCovariance::Variance(const std::vector<PointGradient>& gradients) const {
  double variance = 0.0;
  Eigen::VectorXd y = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(s_size_));
  for (const PointGradient& g : gradients) {
    if (g.point < 0 || static_cast<size_t>(g.point) >= points_.size()) return std::numeric_limits<double>::quiet_NaN();
    const PointBlock& block = points_[static_cast<size_t>(g.point)];
    if (block.constant) continue;
    if (!block.determined) return std::numeric_limits<double>::infinity();
    const Eigen::Vector3d a = block.v_inverse * g.gradient;
    variance += g.gradient.dot(a);
    const Eigen::VectorXd wa = block.w * a;
    for (size_t r = 0; r < block.unknowns.size(); ++r) y(block.unknowns[r]) += wa(static_cast<Eigen::Index>(r));
  }
  if (s_size_ > 0) variance += y.dot(s_factor_.solve(y));
  return variance_factor_ * variance;
}

}  // namespace reconar
