#pragma once
// The one Levenberg-Marquardt driver: the iteration, the gradient / parameter / function tolerance
// tests, the gain ratio, the trust-region update and the termination reasons, shared by every LM
// solver of the project. Marquardt damping diag / radius (Marquardt 1963), the gain-ratio
// trust-region update of Madsen, Nielsen & Tingleff, "Methods for Non-Linear Least Squares
// Problems" (2004, sec. 3.2; Nocedal & Wright, "Numerical Optimization", 2nd ed., ch. 4 and 10.3).
// The problem owns its state, its linearisation and its damped linear solve (fixed-size Cholesky,
// a Schur complement, CHOLMOD), so the loop knows nothing of the block structure.
//
// Users: NormalLmSolve (normal_lm.h: fixed-size normal equations; the absolute pose refinement,
// the planar tag pose), the bundle adjuster (core/optim/bundle_adjuster.cc: points
// eliminated by the Schur complement) and calibration (tracker/calibration.cc: target poses
// eliminated by the Schur complement).
//
// RunLm(problem, options) calls, on a problem that holds the current state x:
//   bool Linearize();                  // once, at the start: cost, gradient and whatever the solve
//                                      // needs at x; false outside the domain
//   double Cost() const;               // 1/2 sum_i rho(|r_i|^2) at x
//   double MaxGradient() const;        // max_k |g_k|, g = J^T W r over the free parameters
//   bool SolveStep(double radius);     // the step dx of the system damped by diag / radius; false
//                                      // when the solve fails (a failed factorisation, a
//                                      // non-finite step)
//   double StepNorm() const;           // |dx|, and the size of x against which it is compared
//   double StateNorm() const;
//   double PredictedReduction() const; // L(0) - L(dx) of the damped quadratic model
//   bool EvaluateStep(double* cost);   // the cost at x [+] dx; false outside the domain
//   void AcceptStep();                 // x <- x [+] dx, linearised there
// Each problem computes these in its own floating-point order (each keeps the exact arithmetic it
// had before the loops were merged).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/base/status.h"

namespace reconar {

// Why RunLm stopped; the one termination enum of every LM solver.
enum class LmTermination {
  kFunctionTolerance,    // an accepted step changed the cost by <= function_tolerance * cost
  kGradientTolerance,    // max |g| over the free parameters <= gradient_tolerance
  kParameterTolerance,   // |dx| <= parameter_tolerance * (|x| + parameter_tolerance)
  kMaxIterations,        // max_iterations iterations ran without another criterion
  kTrustRegionTooSmall,  // the radius shrank below min_trust_region_radius (no progress)
  kNumericFailure,       // the problem could not be linearised, or gave a non-finite cost, at
                         // the initial state, or max_consecutive_numeric_failures damped solves
                         // failed in a row
};

// "function_tolerance", "gradient_tolerance", ... (the bundle-adjust JSON's words).
inline const char* TerminationName(LmTermination termination) {
  switch (termination) {
    case LmTermination::kFunctionTolerance:
      return "function_tolerance";
    case LmTermination::kGradientTolerance:
      return "gradient_tolerance";
    case LmTermination::kParameterTolerance:
      return "parameter_tolerance";
    case LmTermination::kMaxIterations:
      return "max_iterations";
    case LmTermination::kTrustRegionTooSmall:
      return "trust_region_too_small";
    case LmTermination::kNumericFailure:
      return "numeric_failure";
  }
  return "unknown";
}

// True for the tolerance stops (not max_iterations, a collapsed trust region or a failure).
inline bool LmConverged(LmTermination termination) {
  return termination == LmTermination::kFunctionTolerance || termination == LmTermination::kGradientTolerance ||
         termination == LmTermination::kParameterTolerance;
}

// The settings of the loop. Solvers derive their options from it (BundleAdjustmentOptions) or
// embed it (PoseRefinementOptions::lm, CalibrationOptions::lm) and may change the defaults.
struct LmOptions {
  int max_iterations = 50;             // accepted and rejected steps both count
  double function_tolerance = 1e-12;   // stop when |cost change| <= tol * cost (accepted step)
  double gradient_tolerance = 1e-12;   // stop when max |g| <= tol
  double parameter_tolerance = 1e-12;  // stop when |dx| <= tol * (|x| + tol)
  // Trust region radius Delta; the damping is diag(J^T W J) / Delta (Marquardt 1963).
  double initial_trust_region_radius = 1e4;
  double max_trust_region_radius = 1e16;
  double min_trust_region_radius = 1e-32;
  // Steps with gain ratio rho = actual / predicted reduction at or below this are rejected.
  double min_relative_decrease = 1e-3;
  // diag(J^T W J) is clamped below by min_diagonal before it scales the damping.
  double min_diagonal = 1e-6;
  // Consecutive failed damped solves tolerated (each one a rejected step that shrinks the radius)
  // before giving up with kNumericFailure.
  int max_consecutive_numeric_failures = std::numeric_limits<int>::max();

  // InvalidArgument naming the first offending field.
  Status Check() const {
    auto fail = [](const std::string& what) { return InvalidArgument("LmOptions." + what); };
    if (max_iterations < 0) return fail("max_iterations must be >= 0, got " + std::to_string(max_iterations));
    if (!(function_tolerance >= 0.0)) return fail("function_tolerance must be >= 0");
    if (!(gradient_tolerance >= 0.0)) return fail("gradient_tolerance must be >= 0");
    if (!(parameter_tolerance >= 0.0)) return fail("parameter_tolerance must be >= 0");
    if (!(initial_trust_region_radius > 0.0)) return fail("initial_trust_region_radius must be > 0");
    if (!(max_trust_region_radius >= initial_trust_region_radius)) {
      return fail("max_trust_region_radius must be >= initial_trust_region_radius");
    }
    if (!(min_trust_region_radius > 0.0)) return fail("min_trust_region_radius must be > 0");
    if (!(min_relative_decrease >= 0.0 && min_relative_decrease < 1.0)) {
      return fail("min_relative_decrease must be in [0, 1)");
    }
    if (!(min_diagonal > 0.0)) return fail("min_diagonal must be > 0");
    if (max_consecutive_numeric_failures < 1) return fail("max_consecutive_numeric_failures must be >= 1");
    return Status::Ok();
  }
};

struct LmSummary {
  using Termination = LmTermination;
  Termination termination = Termination::kMaxIterations;
  double initial_cost = 0.0;  // 1/2 sum rho(|r|^2) at the start (as the problem gave it)
  double final_cost = 0.0;    // same at the returned state
  int iterations = 0;         // accepted + rejected
  int accepted_steps = 0;

  bool converged() const { return LmConverged(termination); }
};

// The Levenberg-Marquardt trust region: the damping is diag / radius; an accepted step with gain
// ratio `gain` (actual over predicted cost reduction) scales the radius by Nielsen's rule
// (Madsen, Nielsen & Tingleff 2004, eq. 3.16 for mu = 1 / radius), a rejected one divides it by
// nu, which doubles on every consecutive rejection.
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

// Runs LM on `problem` (the interface in the header comment) from its current state; the problem
// holds the last accepted state on return. Allocates nothing itself.
template <typename Problem>
LmSummary RunLm(Problem& problem, const LmOptions& options) {
  using Termination = LmTermination;
  LmSummary summary;
  const bool linearised = problem.Linearize();
  double cost = problem.Cost();
  summary.initial_cost = summary.final_cost = cost;
  if (!linearised || !std::isfinite(cost)) {
    summary.termination = Termination::kNumericFailure;
    return summary;
  }
  LmTrustRegion region(options.initial_trust_region_radius);
  int numeric_failures = 0;
  while (true) {
    if (problem.MaxGradient() <= options.gradient_tolerance) {
      summary.termination = Termination::kGradientTolerance;
      break;
    }
    if (summary.iterations >= options.max_iterations) {
      summary.termination = Termination::kMaxIterations;
      break;
    }
    ++summary.iterations;
    bool accepted = false;
    if (!problem.SolveStep(region.radius())) {
      if (++numeric_failures >= options.max_consecutive_numeric_failures) {
        summary.termination = Termination::kNumericFailure;
        break;
      }
    } else {
      numeric_failures = 0;
      if (problem.StepNorm() <= options.parameter_tolerance * (problem.StateNorm() + options.parameter_tolerance)) {
        summary.termination = Termination::kParameterTolerance;
        break;
      }
      const double predicted = problem.PredictedReduction();
      double new_cost = 0.0;
      if (predicted > 0.0 && problem.EvaluateStep(&new_cost) && std::isfinite(new_cost)) {
        const double gain = (cost - new_cost) / predicted;
        if (gain > options.min_relative_decrease) {
          accepted = true;
          const double change = cost - new_cost;
          const double old_cost = cost;
          problem.AcceptStep();
          cost = problem.Cost();
          ++summary.accepted_steps;
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
