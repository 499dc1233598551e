#pragma once
// Levenberg-Marquardt for tiny fixed-size problems (a pose, a point, a homography), entirely on
// Eigen fixed-size types: no heap allocation. Same method as the bundle adjuster
// (bundle_adjuster.h): Marquardt damping diag(J^T J) / radius, gain-ratio trust-region update of
// Madsen, Nielsen & Tingleff (2004, sec. 3.2), Cholesky of the damped normal equations.
//
// The functor computes residuals and, when `jacobian` is non-null, the Jacobian:
//   bool operator()(const Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, M, 1>* residual,
//                   Eigen::Matrix<double, M, N>* jacobian) const;
// returning false when x is outside its domain (such a step is rejected). Cost = 1/2 |r|^2.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace reconar {

struct TinyLmOptions {
  int max_iterations = 50;             // accepted and rejected steps both count
  double function_tolerance = 1e-10;   // stop when |cost change| <= tol * cost (accepted step)
  double gradient_tolerance = 1e-12;   // stop when max |J^T r| <= tol
  double parameter_tolerance = 1e-10;  // stop when |dx| <= tol * (|x| + tol)
  double initial_trust_region_radius = 1e4;
  double max_trust_region_radius = 1e16;
  double min_trust_region_radius = 1e-32;
  double min_relative_decrease = 1e-3;
  double min_diagonal = 1e-6;
};

struct TinyLmSummary {
  enum class Termination {
    kFunctionTolerance,    // an accepted step changed the cost by <= function_tolerance * cost
    kGradientTolerance,    // max |J^T r| <= gradient_tolerance
    kParameterTolerance,   // |dx| <= parameter_tolerance * (|x| + parameter_tolerance)
    kMaxIterations,        // max_iterations iterations ran without another criterion
    kTrustRegionTooSmall,  // the radius shrank below min_trust_region_radius
    kNumericFailure,       // the functor failed or gave a non-finite cost at the start
  };
  Termination termination = Termination::kMaxIterations;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;

  bool converged() const {
    return termination == Termination::kFunctionTolerance ||
           termination == Termination::kGradientTolerance ||
           termination == Termination::kParameterTolerance;
  }
};

template <int N, int M, typename Functor>
TinyLmSummary TinyLmSolve(const Functor& functor, const TinyLmOptions& options,
                          Eigen::Matrix<double, N, 1>* x) {
  static_assert(N > 0 && M >= N, "fixed sizes with at least as many residuals as parameters");
  using VecN = Eigen::Matrix<double, N, 1>;
  using VecM = Eigen::Matrix<double, M, 1>;
  using MatMN = Eigen::Matrix<double, M, N>;
  using MatNN = Eigen::Matrix<double, N, N>;
  using Termination = TinyLmSummary::Termination;

  TinyLmSummary summary;
  VecM r, r_new;
  MatMN jac;
  if (!functor(*x, &r, &jac) || !r.allFinite() || !jac.allFinite()) {
    summary.termination = Termination::kNumericFailure;
    return summary;
  }
  double cost = 0.5 * r.squaredNorm();
  summary.initial_cost = summary.final_cost = cost;
  MatNN jtj = jac.transpose() * jac;
  VecN g = jac.transpose() * r;
  double radius = options.initial_trust_region_radius;
  double nu = 2.0;
  Eigen::LLT<MatNN> llt;
  while (true) {
    if (g.cwiseAbs().maxCoeff() <= options.gradient_tolerance) {
      summary.termination = Termination::kGradientTolerance;
      break;
    }
    if (summary.iterations >= options.max_iterations) {
      summary.termination = Termination::kMaxIterations;
      break;
    }
    ++summary.iterations;
    const VecN diag = jtj.diagonal().cwiseMax(options.min_diagonal);
    MatNN a = jtj;
    a.diagonal() += diag / radius;
    llt.compute(a);
    bool accepted = false;
    if (llt.info() == Eigen::Success) {
      const VecN dx = llt.solve(-g);
      if (dx.norm() <= options.parameter_tolerance * (x->norm() + options.parameter_tolerance)) {
        summary.termination = Termination::kParameterTolerance;
        break;
      }
      // L(0) - L(dx) = 1/2 (dx^T D dx / radius - g^T dx) since (J^T J + D / radius) dx = -g.
      const double predicted = 0.5 * (dx.dot(diag.cwiseProduct(dx)) / radius - g.dot(dx));
      const VecN x_new = *x + dx;
      if (functor(x_new, &r_new, static_cast<MatMN*>(nullptr))) {
        const double new_cost = 0.5 * r_new.squaredNorm();
        const double gain = (cost - new_cost) / predicted;
        if (std::isfinite(new_cost) && predicted > 0.0 && gain > options.min_relative_decrease &&
            functor(x_new, &r_new, &jac) && jac.allFinite()) {
          accepted = true;
          const double change = cost - new_cost;
          const double old_cost = cost;
          *x = x_new;
          r = r_new;
          cost = new_cost;
          jtj = jac.transpose() * jac;
          g = jac.transpose() * r;
          const double t = 2.0 * gain - 1.0;
          radius = std::min(options.max_trust_region_radius,
                            radius / std::max(1.0 / 3.0, 1.0 - t * t * t));
          nu = 2.0;
          if (std::abs(change) <= options.function_tolerance * old_cost) {
            summary.termination = Termination::kFunctionTolerance;
            break;
          }
        }
      }
    }
    if (!accepted) {
      radius /= nu;
      nu *= 2.0;
      if (radius < options.min_trust_region_radius) {
        summary.termination = Termination::kTrustRegionTooSmall;
        break;
      }
    }
  }
  summary.final_cost = cost;
  return summary;
}

}  // namespace reconar
