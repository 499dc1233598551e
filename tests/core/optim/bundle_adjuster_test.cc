#include "core/optim/bundle_adjuster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "tests/core/optim/synthetic_bal.h"

namespace reconar {
namespace {

using Termination = BundleAdjustmentSummary::Termination;

// Two cameras held constant fix the 7-dof similarity gauge, so the optimum is the truth.
BundleAdjustmentConstancy FirstTwoCamerasConstant(const BalProblem& p) {
  BundleAdjustmentConstancy c;
  c.constant_cameras.assign(static_cast<size_t>(p.num_cameras()), 0);
  c.constant_cameras[0] = c.constant_cameras[1] = 1;
  return c;
}

double MaxAbsDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0.0;
  for (size_t k = 0; k < a.size(); ++k) m = std::max(m, std::abs(a[k] - b[k]));
  return m;
}

using LinearSolver = BundleAdjustmentOptions::LinearSolver;

// (threads, linear solver)
class SyntheticBundleTest : public ::testing::TestWithParam<std::tuple<int, LinearSolver>> {};

TEST_P(SyntheticBundleTest, ConvergesToZeroCostAndRecoversParameters) {
  const BalProblem truth = testing::MakeSyntheticBal(8, 150, 42);
  BalProblem problem = truth;
  testing::PerturbBal(&problem, 43, 2);
  BundleAdjustmentOptions options;
  options.num_threads = std::get<0>(GetParam());
  options.linear_solver = std::get<1>(GetParam());
  options.function_tolerance = 1e-12;
  Result<BundleAdjustmentSummary> r =
      SolveBundleAdjustment(options, FirstTwoCamerasConstant(problem), &problem);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const BundleAdjustmentSummary& s = *r;
  EXPECT_TRUE(s.converged()) << TerminationName(s.termination);
  EXPECT_GT(s.initial_cost, 1e3);
  EXPECT_LT(s.final_cost, 1e-12);
  EXPECT_NEAR(s.final_cost, BundleAdjustmentCost(problem, RobustLoss()), 1e-12);
  EXPECT_LT(s.iterations, 50);
  EXPECT_LT(MaxAbsDiff(problem.points, truth.points), 1e-6);
  EXPECT_LT(MaxAbsDiff(problem.cameras, truth.cameras), 1e-5);
  // The constant cameras did not move at all.
  for (int k = 0; k < 18; ++k)
    EXPECT_EQ(problem.cameras[static_cast<size_t>(k)], truth.cameras[static_cast<size_t>(k)]);
}

INSTANTIATE_TEST_SUITE_P(
    ThreadsAndSolvers, SyntheticBundleTest,
    ::testing::Combine(::testing::Values(1, 2), ::testing::Values(LinearSolver::kDenseCholesky,
                                                                  LinearSolver::kSparseCholesky)),
    [](const ::testing::TestParamInfo<SyntheticBundleTest::ParamType>& param_info) {
      return std::to_string(std::get<0>(param_info.param)) + "Threads" +
             (std::get<1>(param_info.param) == LinearSolver::kDenseCholesky ? "Dense" : "Sparse");
    });

// A sparse camera graph: cameras in a row, each point seen by 3 consecutive cameras.
BalProblem MakeChain(int num_cameras) {
  BalProblem truth;
  const BalProblem ring = testing::MakeSyntheticBal(num_cameras, 1, 21);
  truth.cameras = ring.cameras;
  for (int j = 0; j < 40 * num_cameras; ++j) {
    const int first = j % (num_cameras - 2);
    const double x[3] = {-1.0 + 0.002 * j, std::sin(0.1 * j), std::cos(0.37 * j)};
    truth.points.insert(truth.points.end(), x, x + 3);
    for (int i = first; i < first + 3; ++i) {
      double uv[2] = {0.0, 0.0};
      ProjectBal(truth.camera(i), x, uv, nullptr, nullptr);
      truth.observations.push_back({i, j, uv[0], uv[1]});
    }
  }
  return truth;
}

TEST(BundleAdjusterTest, SparseAndDenseSolversAgree) {
  const BalProblem truth = MakeChain(30);
  BalProblem dense = truth;
  testing::PerturbBal(&dense, 22, 2);
  BalProblem sparse = dense;
  BundleAdjustmentOptions options;
  options.max_iterations = 8;
  Result<BundleAdjustmentSummary> rd =
      SolveBundleAdjustment(options, FirstTwoCamerasConstant(dense), &dense);
  options.linear_solver = LinearSolver::kSparseCholesky;
  Result<BundleAdjustmentSummary> rs =
      SolveBundleAdjustment(options, FirstTwoCamerasConstant(sparse), &sparse);
  ASSERT_TRUE(rd.ok() && rs.ok());
  EXPECT_EQ(rd->iterations, rs->iterations);
  EXPECT_NEAR(rd->final_cost, rs->final_cost, 1e-9 * rd->initial_cost);
  EXPECT_LT(MaxAbsDiff(dense.cameras, sparse.cameras), 1e-6);
  EXPECT_LT(MaxAbsDiff(dense.points, sparse.points), 1e-6);
}

// kAuto: sparse from kMinSparseUnknowns unknowns when the coupled blocks fill at most
// kMaxSparseFill of the reduced system, dense otherwise.
TEST(BundleAdjusterTest, AutoSolverFollowsSizeAndFill) {
  using Options = BundleAdjustmentOptions;
  BundleAdjustmentOptions options;
  options.max_iterations = 1;
  ASSERT_EQ(options.linear_solver, LinearSolver::kAuto);
  // 58 free cameras of 9 parameters in a chain: 522 unknowns, 3 blocks of 58 in a row coupled.
  BalProblem chain = MakeChain(60);
  BundleAdjustmentConstancy constancy = FirstTwoCamerasConstant(chain);
  Result<BundleAdjustmentSummary> r = SolveBundleAdjustment(options, constancy, &chain);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->reduced_unknowns, 58 * 9);
  static_assert(58 * 9 >= Options::kMinSparseUnknowns);
  EXPECT_EQ(r->linear_solver, LinearSolver::kSparseCholesky);
  // Sharing the intrinsics leaves 58 poses and one f, k1, k2: too small for the sparse solver.
  constancy.intrinsics_group.assign(60, 0);
  r = SolveBundleAdjustment(options, constancy, &chain);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->reduced_unknowns, 58 * 6 + 3);
  EXPECT_EQ(r->linear_solver, LinearSolver::kDenseCholesky);
  // Every camera pair shares points: dense at any size.
  BalProblem all_pairs = testing::MakeSyntheticBal(60, 100, 3);
  r = SolveBundleAdjustment(options, FirstTwoCamerasConstant(all_pairs), &all_pairs);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->reduced_unknowns, 58 * 9);
  EXPECT_EQ(r->linear_solver, LinearSolver::kDenseCholesky);
}

TEST(BundleAdjusterTest, ThreadCountDoesNotChangeResult) {
  BalProblem a = testing::MakeSyntheticBal(6, 80, 5);
  testing::PerturbBal(&a, 6, 2);
  BalProblem b = a;
  BundleAdjustmentOptions options;
  options.max_iterations = 10;
  Result<BundleAdjustmentSummary> ra =
      SolveBundleAdjustment(options, FirstTwoCamerasConstant(a), &a);
  options.num_threads = 2;
  Result<BundleAdjustmentSummary> rb =
      SolveBundleAdjustment(options, FirstTwoCamerasConstant(b), &b);
  ASSERT_TRUE(ra.ok() && rb.ok());
  EXPECT_EQ(ra->final_cost, rb->final_cost);
  EXPECT_EQ(a.cameras, b.cameras);
  EXPECT_EQ(a.points, b.points);
}

TEST(BundleAdjusterTest, ConstantPointsStayPut) {
  const BalProblem truth = testing::MakeSyntheticBal(5, 60, 9);
  BalProblem problem = truth;
  testing::PerturbBal(&problem, 10, 0);
  // Points are the truth and constant: cameras alone recover exactly, no gauge freedom.
  problem.points = truth.points;
  BundleAdjustmentConstancy c;
  c.constant_points.assign(static_cast<size_t>(problem.num_points()), 1);
  Result<BundleAdjustmentSummary> r = SolveBundleAdjustment(BundleAdjustmentOptions(), c, &problem);
  ASSERT_TRUE(r.ok());
  EXPECT_LT(r->final_cost, 1e-10);
  EXPECT_EQ(problem.points, truth.points);
  EXPECT_LT(MaxAbsDiff(problem.cameras, truth.cameras), 1e-5);
}

TEST(BundleAdjusterTest, RobustLossesResistOutliers) {
  const BalProblem truth = testing::MakeSyntheticBal(8, 150, 11);
  // Point error after solving with `type`, every 25th observation a gross outlier (+40 px).
  auto solve = [&truth](LossType type) {
    BalProblem problem = truth;
    for (size_t k = 0; k < problem.observations.size(); k += 25) problem.observations[k].x += 40.0;
    testing::PerturbBal(&problem, 12, 2);
    BundleAdjustmentOptions options;
    options.loss.type = type;
    options.loss.scale = 2.0;
    Result<BundleAdjustmentSummary> r =
        SolveBundleAdjustment(options, FirstTwoCamerasConstant(problem), &problem);
    EXPECT_TRUE(r.ok());
    EXPECT_TRUE(r->converged()) << TerminationName(r->termination);
    return MaxAbsDiff(problem.points, truth.points);
  };
  const double trivial = solve(LossType::kTrivial);
  const double huber = solve(LossType::kHuber);
  const double cauchy = solve(LossType::kCauchy);
  // Huber bounds the influence of an outlier (c per residual), Cauchy makes it redescend.
  EXPECT_LT(huber, 0.5 * trivial);
  EXPECT_LT(cauchy, 0.02);
  EXPECT_LT(cauchy, 0.1 * trivial);
}

TEST(BundleAdjusterTest, RejectsBadInput) {
  BalProblem problem = testing::MakeSyntheticBal(3, 10, 1);
  BundleAdjustmentOptions options;
  options.initial_trust_region_radius = -1.0;
  EXPECT_EQ(SolveBundleAdjustment(options, {}, &problem).status().code(),
            StatusCode::kInvalidArgument);
  BundleAdjustmentConstancy c;
  c.constant_cameras.assign(2, 0);
  EXPECT_EQ(SolveBundleAdjustment(BundleAdjustmentOptions(), c, &problem).status().code(),
            StatusCode::kInvalidArgument);
  problem.observations[0].point = 99;
  EXPECT_EQ(SolveBundleAdjustment(BundleAdjustmentOptions(), {}, &problem).status().code(),
            StatusCode::kInvalidArgument);
}

TEST(BundleAdjusterTest, NonFiniteStartIsNumericFailure) {
  BalProblem problem = testing::MakeSyntheticBal(3, 10, 1);
  problem.points[0] = std::nan("");
  Result<BundleAdjustmentSummary> r =
      SolveBundleAdjustment(BundleAdjustmentOptions(), {}, &problem);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->termination, Termination::kNumericFailure);
  EXPECT_EQ(r->iterations, 0);
}

}  // namespace
}  // namespace reconar
