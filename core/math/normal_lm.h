#pragma once
// Levenberg-Marquardt on accumulated normal equations, for small problems: the problem sums
// J^T W J (N x N, fixed size) and J^T W r over its residuals itself, so memory is independent of
// the number of residuals and nothing is allocated. Marquardt damping diag(J^T J) / radius, the
// gain-ratio trust-region update of Madsen, Nielsen & Tingleff (2004, sec. 3.2), Cholesky of the
// damped system (the method of the bundle adjuster, core/optim/bundle_adjuster.h). The state may
// live on a manifold (the problem supplies x [+] dx, e.g. a rotation update R <- exp(dw) R), and a
// robust loss enters by iteratively reweighted least squares (robust_loss.h).
//
// Users: TinyLmSolve (core/optim/tiny_lm.h; vector state, the normal equations formed from a
// fixed-size residual functor) and the absolute pose refinement (core/geometry/absolute_pose.cc;
// rotation, translation and focal, hundreds of robustly weighted reprojection residuals).
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
#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace reconar {

struct NormalLmOptions {
  int max_iterations = 50;             // accepted and rejected steps both count
  double function_tolerance = 1e-12;   // stop when |cost change| <= tol * cost (accepted step)
  double gradient_tolerance = 1e-12;   // stop when max |J^T W r| <= tol
  double parameter_tolerance = 1e-12;  // stop when |dx| <= tol * (Norm(x) + tol)
  double initial_trust_region_radius = 1e4;
  double max_trust_region_radius = 1e16;
  double min_trust_region_radius = 1e-32;
  double min_relative_decrease = 1e-3;
  double min_diagonal = 1e-6;
};

struct NormalLmSummary {
  enum class Termination {
    kFunctionTolerance,    // an accepted step changed the cost by <= function_tolerance * cost
    kGradientTolerance,    // max |J^T W r| <= gradient_tolerance
    kParameterTolerance,   // |dx| <= parameter_tolerance * (Norm(x) + parameter_tolerance)
    kMaxIterations,        // max_iterations iterations ran without another criterion
    kTrustRegionTooSmall,  // the radius shrank below min_trust_region_radius
    kNumericFailure,       // the problem could not be linearised, or gave a non-finite cost or
                           // system, at the initial state
  };
  Termination termination = Termination::kMaxIterations;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;

  bool converged() const {
    return termination == Termination::kFunctionTolerance || termination == Termination::kGradientTolerance ||
           termination == Termination::kParameterTolerance;
  }
};

// The Levenberg-Marquardt trust region, shared with the bundle adjuster: the damping is
// diag / radius; an accepted step with gain ratio `gain` (actual over predicted cost reduction)
// scales the radius by Nielsen's rule (Madsen, Nielsen & Tingleff 2004, eq. 3.16 for
// mu = 1 / radius), a rejected one divides it by nu, which doubles on every consecutive rejection.
class LmTrustRegion {
 public:
  explicit LmTrustRegion(double initial_radius) : radius_(initial_radius) {}

  double radius() const { return radius_; }

  void Accept(double gain, double max_radius) {
    const double t = 2.0 * gain - 1.0;
    radius_ = std::min(max_radius, radius_ / std::max(1.0 / 3.0, 1.0 - t * t * t));
    nu_ = 2.0;
  }

  void Reject() {
    radius_ /= nu_;
    nu_ *= 2.0;
  }

 private:
  double radius_;
  double nu_ = 2.0;
};

inline const char* NormalLmTerminationName(NormalLmSummary::Termination termination) {
  using Termination = NormalLmSummary::Termination;
  switch (termination) {
    case Termination::kFunctionTolerance: return "function tolerance";
    case Termination::kGradientTolerance: return "gradient tolerance";
    case Termination::kParameterTolerance: return "parameter tolerance";
    case Termination::kMaxIterations: return "max iterations";
    case Termination::kTrustRegionTooSmall: return "trust region too small";
    case Termination::kNumericFailure: return "numeric failure";
  }
  return "unknown";
}

template <typename Problem>
NormalLmSummary NormalLmSolve(const Problem& problem, const NormalLmOptions& options, typename Problem::State* x) {
  constexpr int N = Problem::kDim;
  using VecN = Eigen::Matrix<double, N, 1>;
  using MatNN = Eigen::Matrix<double, N, N>;
  using State = typename Problem::State;
  using Termination = NormalLmSummary::Termination;

  NormalLmSummary summary;
  MatNN jtj;
  VecN g;
  double cost = 0.0;
  if (!problem.Linearize(*x, &jtj, &g, &cost) || !std::isfinite(cost) || !jtj.allFinite() || !g.allFinite()) {
    summary.termination = Termination::kNumericFailure;
    return summary;
  }
  summary.initial_cost = summary.final_cost = cost;
  LmTrustRegion region(options.initial_trust_region_radius);
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
    const double radius = region.radius();
    a.diagonal() += diag / radius;
    llt.compute(a);
    bool accepted = false;
    if (llt.info() == Eigen::Success) {
      const VecN dx = llt.solve(-g);
      if (dx.norm() <= options.parameter_tolerance * (problem.Norm(*x) + options.parameter_tolerance)) {
        summary.termination = Termination::kParameterTolerance;
        break;
      }
      // L(0) - L(dx) = 1/2 (dx^T D dx / radius - g^T dx) since (J^T W J + D / radius) dx = -g.
      const double predicted = 0.5 * (dx.dot(diag.cwiseProduct(dx)) / radius - g.dot(dx));
      const State x_new = problem.Plus(*x, dx);
      MatNN jtj_new;
      VecN g_new;
      double new_cost = 0.0;
      if (problem.Linearize(x_new, &jtj_new, &g_new, &new_cost) && std::isfinite(new_cost) && predicted > 0.0 &&
          jtj_new.allFinite() && g_new.allFinite()) {
        const double gain = (cost - new_cost) / predicted;
        if (gain > options.min_relative_decrease) {
          accepted = true;
          const double change = cost - new_cost;
          const double old_cost = cost;
          *x = x_new;
          cost = new_cost;
          jtj = jtj_new;
          g = g_new;
          region.Accept(gain, options.max_trust_region_radius);
          if (std::abs(change) <= options.function_tolerance * old_cost) {
            summary.termination = Termination::kFunctionTolerance;
            break;
          }
        }
      }
    }
    if (!accepted) {
      region.Reject();
      if (region.radius() < options.min_trust_region_radius) {
        summary.termination = Termination::kTrustRegionTooSmall;
        break;
      }
    }
  }
  summary.final_cost = cost;
  return summary;
}

}  // namespace reconar
