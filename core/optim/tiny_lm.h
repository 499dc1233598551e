#pragma once
// Levenberg-Marquardt for tiny fixed-size problems (a pose, a point, a homography), entirely on
// Eigen fixed-size types: no heap allocation. The solver is NormalLmSolve (core/math/normal_lm.h,
// Cholesky of the damped normal equations, over the one LM loop of core/math/lm_loop.h: Marquardt
// damping diag(J^T J) / radius, gain-ratio trust-region update of Madsen, Nielsen & Tingleff 2004,
// sec. 3.2) on J^T J and J^T r formed from the functor's residuals and Jacobian.
//
// The functor computes residuals and, when `jacobian` is non-null, the Jacobian:
//   bool operator()(const Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, M, 1>* residual,
//                   Eigen::Matrix<double, M, N>* jacobian) const;
// returning false when x is outside its domain (such a step is rejected). Cost = 1/2 |r|^2.
#include <Eigen/Core>

#include "core/math/normal_lm.h"

namespace reconar {

// NormalLmOptions with looser default function and parameter tolerances.
struct TinyLmOptions : NormalLmOptions {
  TinyLmOptions() {
    function_tolerance = 1e-10;   // stop when |cost change| <= tol * cost (accepted step)
    parameter_tolerance = 1e-10;  // stop when |dx| <= tol * (|x| + tol)
  }
};

using TinyLmSummary = NormalLmSummary;

namespace tiny_lm_internal {

// The functor as a NormalLmSolve problem on the vector space R^N.
template <int N, int M, typename Functor>
class FunctorProblem {
 public:
  static_assert(N > 0 && M >= N, "fixed sizes with at least as many residuals as parameters");
  static constexpr int kDim = N;
  using State = Eigen::Matrix<double, N, 1>;

  explicit FunctorProblem(const Functor& functor) : functor_(functor) {}

  bool Linearize(const State& x, Eigen::Matrix<double, N, N>* jtj, State* jtr, double* cost) const {
    Eigen::Matrix<double, M, 1> r;
    Eigen::Matrix<double, M, N> jac;
    if (!functor_(x, &r, &jac) || !r.allFinite() || !jac.allFinite()) return false;
    *jtj = jac.transpose() * jac;
    *jtr = jac.transpose() * r;
    *cost = 0.5 * r.squaredNorm();
    return true;
  }

  State Plus(const State& x, const State& dx) const { return x + dx; }

  double Norm(const State& x) const { return x.norm(); }

 private:
  const Functor& functor_;
};

}  // namespace tiny_lm_internal

template <int N, int M, typename Functor>
TinyLmSummary TinyLmSolve(const Functor& functor, const TinyLmOptions& options,
                          Eigen::Matrix<double, N, 1>* x) {
  const tiny_lm_internal::FunctorProblem<N, M, Functor> problem(functor);
  return NormalLmSolve(problem, options, x);
}

}  // namespace reconar
