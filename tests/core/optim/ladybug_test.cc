// Ladybug problem-49-7776 (BAL). Reference: Ceres 2.1, SPARSE_SCHUR, one thread, default
// options, reaches cost 13344.32 from 850912.46 in 32 iterations (its count includes iteration
// 0: 31 steps). Ours: 13344.29 in 32 steps (bench/bundle compares them side by side).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "core/optim/bal_problem.h"
#include "core/optim/bundle_adjuster.h"

namespace reconar {
namespace {

constexpr double kReferenceInitialCost = 850912.46;
// Converged optimum: our solver run for 300 iterations with function_tolerance 1e-14 reaches
// 13344.2408 (still creeping down by < 1e-6 per iteration). Ceres' default stop (13344.32) is
// 6e-6 relative above it; we require the default solve to land within 1e-4 relative of it
// (measured: 13344.29, i.e. 4e-6 above).
constexpr double kConvergedOptimum = 13344.2408;
constexpr double kOptimumMargin = 1e-4;

class LadybugTest : public ::testing::TestWithParam<BundleAdjustmentOptions::LinearSolver> {};

TEST_P(LadybugTest, Converges) {
  const std::string path =
      std::string(RECONAR_SHARED_DATA_DIR) + "/bal_ladybug/problem-49-7776-pre.txt";
  Result<BalProblem> problem = ReadBalProblem(path);
  ASSERT_TRUE(problem.ok()) << problem.status().ToString();
  EXPECT_EQ(problem->num_cameras(), 49);
  EXPECT_EQ(problem->num_points(), 7776);
  EXPECT_EQ(problem->observations.size(), 31843u);
  BundleAdjustmentOptions options;
  options.linear_solver = GetParam();
  Result<BundleAdjustmentSummary> r = SolveBundleAdjustment(options, {}, &*problem);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const BundleAdjustmentSummary& s = *r;
  std::printf("ladybug-49: initial %.2f final %.2f iterations %d (accepted %d) %.3f s, %s\n",
              s.initial_cost, s.final_cost, s.iterations, s.accepted_steps, s.seconds,
              TerminationName(s.termination));
  EXPECT_NEAR(s.initial_cost, kReferenceInitialCost, 0.01);
  EXPECT_TRUE(s.converged()) << TerminationName(s.termination);
  EXPECT_LT(s.final_cost, 0.02 * s.initial_cost);
  EXPECT_LT(s.final_cost, kConvergedOptimum * (1.0 + kOptimumMargin));
  EXPECT_GT(s.final_cost, kConvergedOptimum * (1.0 - kOptimumMargin));
}

INSTANTIATE_TEST_SUITE_P(Solvers, LadybugTest,
                         ::testing::Values(BundleAdjustmentOptions::LinearSolver::kDenseCholesky,
                                           BundleAdjustmentOptions::LinearSolver::kSparseCholesky),
                         [](const ::testing::TestParamInfo<LadybugTest::ParamType>& param_info) {
                           return std::string(
                               param_info.param ==
                                       BundleAdjustmentOptions::LinearSolver::kDenseCholesky
                                   ? "Dense"
                                   : "Sparse");
                         });

}  // namespace
}  // namespace reconar
