#pragma once
// Levenberg-Marquardt on accumulated normal equations, for small problems: the problem sums
// J^T W J (N x N, fixed size) and J^T W r over its residuals itself, so memory is independent of
// the number of residuals and nothing is allocated. The loop is RunLm (lm_loop.h: Marquardt
// damping diag(J^T J) / radius, the gain-ratio trust region of Madsen, Nielsen & Tingleff 2004,
// sec. 3.2); the step is the Cholesky solution of the damped N x N system. The state may live on
// a manifold (the problem supplies x [+] dx, e.g. a rotation update R <- exp(dw) R), and a robust
// loss enters by iteratively reweighted least squares (robust_loss.h).
//
// Users: the absolute pose refinement (core/geometry/pose_refinement.cc; rotation, translation and
// focal, hundreds of robustly weighted reprojection residuals) and the planar tag pose
// (tracker/tag_pose.cc).
//
// The problem type provides
//   using State = ...;                          // copyable, fixed size
//   static constexpr int kDim = N;              // tangent dimension
//   bool Linearize(const State& x, Eigen::Matrix<double, N, N>* jtj, Eigen::Matrix<double, N, 1>* jtr,
//                  double* cost) const;         // cost = 1/2 sum_i rho(|r_i|^2)
//   State Plus(const State& x, const Eigen::Matrix<double, N, 1>& dx) const;
//   double Norm(const State& x) const;          // size of x against which steps are compared
// Linearize returns false when x is outside the domain (such a step is rejected); it is called
// once per trial step.
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "core/math/lm_loop.h"

namespace reconar {

using NormalLmOptions = LmOptions;
using NormalLmSummary = LmSummary;

namespace normal_lm_internal {

// A NormalLmSolve problem as a RunLm problem: the state, its normal equations and those of the
// trial step, all fixed size.
template <typename Problem>
class NormalEquationsProblem {
  static constexpr int N = Problem::kDim;
  using VecN = Eigen::Matrix<double, N, 1>;
  using MatNN = Eigen::Matrix<double, N, N>;
  using State = typename Problem::State;

 public:
  NormalEquationsProblem(const Problem& problem, double min_diagonal, State* x)
      : problem_(problem), min_diagonal_(min_diagonal), x_(x) {}

  bool Linearize() {
    if (!problem_.Linearize(*x_, &jtj_, &g_, &cost_) || !std::isfinite(cost_) || !jtj_.allFinite() || !g_.allFinite()) {
      cost_ = std::numeric_limits<double>::infinity();
      return false;
    }
    return true;
  }
  double Cost() const { return cost_; }
  double MaxGradient() const { return g_.cwiseAbs().maxCoeff(); }

  bool SolveStep(double radius) {
    radius_ = radius;
    diag_ = jtj_.diagonal().cwiseMax(min_diagonal_);
    MatNN a = jtj_;
    a.diagonal() += diag_ / radius;
    llt_.compute(a);
    if (llt_.info() != Eigen::Success) return false;
    dx_ = llt_.solve(-g_);
    return true;
  }
  double StepNorm() const { return dx_.norm(); }
  double StateNorm() const { return problem_.Norm(*x_); }
  // L(0) - L(dx) = 1/2 (dx^T D dx / radius - g^T dx) since (J^T W J + D / radius) dx = -g.
  double PredictedReduction() const { return 0.5 * (dx_.dot(diag_.cwiseProduct(dx_)) / radius_ - g_.dot(dx_)); }

  bool EvaluateStep(double* cost) {
    x_new_ = problem_.Plus(*x_, dx_);
    const bool ok = problem_.Linearize(x_new_, &jtj_new_, &g_new_, &cost_new_);
    *cost = cost_new_;
    return ok && jtj_new_.allFinite() && g_new_.allFinite();
  }
  void AcceptStep() {
    *x_ = x_new_;
    cost_ = cost_new_;
    jtj_ = jtj_new_;
    g_ = g_new_;
  }

 private:
  const Problem& problem_;
  const double min_diagonal_;
  State* x_;
  State x_new_;
  MatNN jtj_, jtj_new_;
  VecN g_, g_new_, diag_, dx_;
  double cost_ = 0.0, cost_new_ = 0.0;
  double radius_ = 1.0;
  Eigen::LLT<MatNN> llt_;
};

}  // namespace normal_lm_internal

template <typename Problem>
NormalLmSummary NormalLmSolve(const Problem& problem, const NormalLmOptions& options, typename Problem::State* x) {
  normal_lm_internal::NormalEquationsProblem<Problem> lm(problem, options.min_diagonal, x);
  return RunLm(lm, options);
}

}  // namespace reconar
