// RunLm (core/math/lm_loop.h) on scripted one-parameter problems: each termination reason comes
// from the condition its comment names, and LmOptions::Check rejects bad settings.
#include "core/math/lm_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace reconar {
namespace {

// f(x) = 1/2 (x - target)^2 with a Gauss-Newton model (J = 1), whose damped solve can be made to
// fail: the smallest RunLm problem.
class Parabola {
 public:
  explicit Parabola(double x, double target = 3.0) : x_(x), target_(target) {}

  bool Linearize() { return std::isfinite(Cost()); }
  double Cost() const { return 0.5 * (x_ - target_) * (x_ - target_); }
  double MaxGradient() const { return std::abs(x_ - target_); }
  bool SolveStep(double radius) {
    if (fail_solves_) return false;
    radius_ = radius;
    dx_ = -(x_ - target_) / (1.0 + 1.0 / radius);  // (J^T J + D / radius) dx = -g, D = 1
    return true;
  }
  double StepNorm() const { return std::abs(dx_); }
  double StateNorm() const { return std::abs(x_); }
  double PredictedReduction() const { return 0.5 * (dx_ * dx_ / radius_ - (x_ - target_) * dx_); }
  bool EvaluateStep(double* cost) {
    const double next = x_ + dx_;
    *cost = 0.5 * (next - target_) * (next - target_);
    return true;
  }
  void AcceptStep() { x_ += dx_; }

  double x() const { return x_; }
  bool fail_solves_ = false;

 private:
  double x_, target_;
  double radius_ = 1.0, dx_ = 0.0;
};

TEST(LmLoop, ConvergesOnAParabola) {
  Parabola p(-5.0);
  const LmSummary s = RunLm(p, LmOptions());
  EXPECT_TRUE(s.converged()) << TerminationName(s.termination);
  EXPECT_NEAR(p.x(), 3.0, 1e-9);
  EXPECT_EQ(s.initial_cost, 32.0);
  EXPECT_LT(s.final_cost, 1e-18);
  EXPECT_GE(s.accepted_steps, 1);
  EXPECT_LE(s.accepted_steps, s.iterations);
}

TEST(LmLoop, GradientToleranceAtTheStartRunsNoIteration) {
  Parabola p(3.0);
  const LmSummary s = RunLm(p, LmOptions());
  EXPECT_EQ(s.termination, LmTermination::kGradientTolerance);
  EXPECT_EQ(s.iterations, 0);
}

TEST(LmLoop, MaxIterations) {
  Parabola p(-5.0);
  LmOptions options;
  options.max_iterations = 1;
  options.initial_trust_region_radius = 1e-3;  // a short first step
  const LmSummary s = RunLm(p, options);
  EXPECT_EQ(s.termination, LmTermination::kMaxIterations);
  EXPECT_EQ(s.iterations, 1);
  EXPECT_FALSE(s.converged());
}

TEST(LmLoop, NonFiniteStartIsNumericFailure) {
  Parabola p(std::numeric_limits<double>::quiet_NaN());
  const LmSummary s = RunLm(p, LmOptions());
  EXPECT_EQ(s.termination, LmTermination::kNumericFailure);
  EXPECT_EQ(s.iterations, 0);
}

TEST(LmLoop, FailedSolvesShrinkTheRegionOrGiveUp) {
  // Unlimited failures (the default): every failure is a rejected step until the radius collapses.
  Parabola p(-5.0);
  p.fail_solves_ = true;
  const LmSummary collapsed = RunLm(p, LmOptions());
  EXPECT_EQ(collapsed.termination, LmTermination::kTrustRegionTooSmall);
  EXPECT_EQ(collapsed.accepted_steps, 0);
  // A bound on consecutive failures stops first.
  LmOptions options;
  options.max_consecutive_numeric_failures = 3;
  const LmSummary failed = RunLm(p, options);
  EXPECT_EQ(failed.termination, LmTermination::kNumericFailure);
  EXPECT_EQ(failed.iterations, 3);
  EXPECT_EQ(p.x(), -5.0);
}

TEST(LmLoop, TrustRegionUpdate) {
  LmTrustRegion region(100.0);
  region.Reject();
  EXPECT_EQ(region.radius(), 50.0);
  region.Reject();
  EXPECT_EQ(region.radius(), 12.5);  // nu doubled
  region.Accept(1.0, 1e16);          // gain 1: radius * 3, nu reset
  EXPECT_EQ(region.radius(), 37.5);
  region.Reject();
  EXPECT_EQ(region.radius(), 18.75);
  region.Accept(1.0, 20.0);
  EXPECT_EQ(region.radius(), 20.0);  // capped
}

TEST(LmLoop, OptionsCheck) {
  EXPECT_TRUE(LmOptions().Check().ok());
  LmOptions bad;
  bad.max_iterations = -1;
  EXPECT_FALSE(bad.Check().ok());
  bad = LmOptions();
  bad.min_relative_decrease = 1.0;
  EXPECT_FALSE(bad.Check().ok());
  bad = LmOptions();
  bad.max_trust_region_radius = 1.0;  // below the initial radius
  EXPECT_FALSE(bad.Check().ok());
  bad = LmOptions();
  bad.min_diagonal = 0.0;
  EXPECT_FALSE(bad.Check().ok());
  bad = LmOptions();
  bad.max_consecutive_numeric_failures = 0;
  const Status status = bad.Check();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("max_consecutive_numeric_failures"), std::string::npos) << status.message();
}

TEST(LmLoop, TerminationNames) {
  EXPECT_STREQ(TerminationName(LmTermination::kFunctionTolerance), "function_tolerance");
  EXPECT_STREQ(TerminationName(LmTermination::kTrustRegionTooSmall), "trust_region_too_small");
  EXPECT_STREQ(TerminationName(LmTermination::kNumericFailure), "numeric_failure");
}

}  // namespace
}  // namespace reconar
