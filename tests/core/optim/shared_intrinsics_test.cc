// Shared intrinsics (BundleAdjustmentConstancy::intrinsics_group) in both linear solvers: one LM
// step against the damped normal equations of the whole Jacobian in the shared parametrisation,
// built here column by column; and the dense and sparse solvers against each other over whole
// solves with groups, constant cameras, constant camera parameters and constant points.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <ostream>
#include <string>
#include <vector>

#include "core/optim/bundle_adjuster.h"
#include "core/optim/radial_camera_model.h"
#include "tests/core/optim/synthetic_bal.h"

namespace reconar {
namespace {

using LinearSolver = BundleAdjustmentOptions::LinearSolver;

struct Case {
  std::string name;
  std::vector<int> groups;            // per camera
  std::vector<char> constant_cameras;  // per camera
  std::vector<int> constant_parameters;
  bool some_constant_points = false;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

// Every fourth point is constant when some are (and left at the truth).
RadialProblem MakeProblem(const Case& setup) {
  const RadialProblem truth = testing::MakeSyntheticRadial(setup.groups, 60, 0.5, 7);
  RadialProblem problem = truth;
  testing::PerturbRadial(&problem, setup.groups, 8, setup.constant_cameras);
  for (int j = 0; setup.some_constant_points && j < problem.num_points(); j += 4) {
    for (int d = 0; d < 3; ++d) problem.point(j)[d] = truth.point(j)[d];
  }
  return problem;
}

BundleAdjustmentConstancy ConstancyOf(const Case& setup, const RadialProblem& problem) {
  BundleAdjustmentConstancy c;
  c.constant_cameras = setup.constant_cameras;
  c.constant_camera_parameters = setup.constant_parameters;
  c.intrinsics_group = setup.groups;
  if (setup.some_constant_points) {
    c.constant_points.assign(static_cast<size_t>(problem.num_points()), 0);
    for (int j = 0; j < problem.num_points(); j += 4) c.constant_points[static_cast<size_t>(j)] = 1;
  }
  return c;
}

// The step of (J^T J + lambda D) dx = -J^T r over the free parameters, a shared intrinsic one
// column for its whole group; D is diag(J^T J) clamped per camera and per point block, summed
// over a group's cameras (the solver's Marquardt scaling). Returns the parameters after it.
RadialProblem ReferenceStep(const RadialProblem& problem, const BundleAdjustmentConstancy& c, double lambda,
                            const BundleAdjustmentOptions& options) {
  const int nc = problem.num_cameras(), np = problem.num_points();
  std::vector<char> constant_parameter(12, 0);
  for (int m : c.constant_camera_parameters) constant_parameter[static_cast<size_t>(m)] = 1;
  // Column of camera parameter (i, k) or -1; shared ones by (group, k).
  std::vector<int> camera_column(static_cast<size_t>(nc) * 12, -1);
  std::vector<int> group_first(16 * 12, -1);  // column of shared parameter (group, k)
  int n = 0;
  for (int i = 0; i < nc; ++i) {
    if (c.constant_cameras[static_cast<size_t>(i)]) continue;
    const int g = c.intrinsics_group[static_cast<size_t>(i)];
    for (int k = 0; k < 12; ++k) {
      if (constant_parameter[static_cast<size_t>(k)]) continue;
      int& column = camera_column[static_cast<size_t>(i) * 12 + static_cast<size_t>(k)];
      if (k < 6 || g < 0) {
        column = n++;
        continue;
      }
      int& first = group_first.at(static_cast<size_t>(g) * 12 + static_cast<size_t>(k));
      if (first < 0) first = n++;
      column = first;
    }
  }
  std::vector<int> point_column(static_cast<size_t>(np), -1);
  for (int j = 0; j < np; ++j) {
    if (c.constant_points.empty() || !c.constant_points[static_cast<size_t>(j)]) {
      point_column[static_cast<size_t>(j)] = n;
      n += 3;
    }
  }
  const auto rows = static_cast<Eigen::Index>(2 * problem.observations.size());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows, n);
  Eigen::VectorXd r(rows);
  // Per camera and point block, diag(J^T J) before the sharing (the Marquardt scaling).
  Eigen::MatrixXd camera_diag = Eigen::MatrixXd::Zero(12, nc);
  Eigen::MatrixXd point_diag = Eigen::MatrixXd::Zero(3, np);
  for (size_t q = 0; q < problem.observations.size(); ++q) {
    const BalObservation& o = problem.observations[q];
    double uv[2], jc[24], jp[6];
    EXPECT_TRUE(ProjectRadial(problem.camera(o.camera), problem.point(o.point), uv, jc, jp));
    const auto row = static_cast<Eigen::Index>(2 * q);
    r[row] = uv[0] - o.x;
    r[row + 1] = uv[1] - o.y;
    for (int k = 0; k < 12; ++k) {
      const int column = camera_column[static_cast<size_t>(o.camera) * 12 + static_cast<size_t>(k)];
      if (column < 0) continue;
      J(row, column) += jc[k];
      J(row + 1, column) += jc[12 + k];
      camera_diag(k, o.camera) += jc[k] * jc[k] + jc[12 + k] * jc[12 + k];
    }
    const int pc = point_column[static_cast<size_t>(o.point)];
    if (pc < 0) continue;
    for (int d = 0; d < 3; ++d) {
      J(row, pc + d) = jp[d];
      J(row + 1, pc + d) = jp[3 + d];
      point_diag(d, o.point) += jp[d] * jp[d] + jp[3 + d] * jp[3 + d];
    }
  }
  Eigen::VectorXd damping = Eigen::VectorXd::Zero(n);
  const auto clamp = [&options](double x) { return std::min(std::max(x, options.min_diagonal), options.max_diagonal); };
  for (int i = 0; i < nc; ++i) {
    for (int k = 0; k < 12; ++k) {
      const int column = camera_column[static_cast<size_t>(i) * 12 + static_cast<size_t>(k)];
      if (column >= 0) damping[column] += clamp(camera_diag(k, i));
    }
  }
  for (int j = 0; j < np; ++j) {
    const int pc = point_column[static_cast<size_t>(j)];
    for (int d = 0; pc >= 0 && d < 3; ++d) damping[pc + d] = clamp(point_diag(d, j));
  }
  Eigen::MatrixXd A = J.transpose() * J;
  A.diagonal() += lambda * damping;
  const Eigen::VectorXd dx = A.llt().solve(-J.transpose() * r);
  RadialProblem stepped = problem;
  for (int i = 0; i < nc; ++i) {
    for (int k = 0; k < 12; ++k) {
      const int column = camera_column[static_cast<size_t>(i) * 12 + static_cast<size_t>(k)];
      if (column >= 0) stepped.camera(i)[k] += dx[column];
    }
  }
  for (int j = 0; j < np; ++j) {
    const int pc = point_column[static_cast<size_t>(j)];
    for (int d = 0; pc >= 0 && d < 3; ++d) stepped.point(j)[d] += dx[pc + d];
  }
  return stepped;
}

// Largest |a - b| over the camera parameters, relative to max(1, |b|), and over the points.
double CameraDifference(const RadialProblem& a, const RadialProblem& b) {
  double m = 0.0;
  for (size_t k = 0; k < a.cameras.size(); ++k) {
    m = std::max(m, std::abs(a.cameras[k] - b.cameras[k]) / std::max(1.0, std::abs(b.cameras[k])));
  }
  return m;
}
double PointDifference(const RadialProblem& a, const RadialProblem& b) {
  double m = 0.0;
  for (size_t k = 0; k < a.points.size(); ++k) m = std::max(m, std::abs(a.points[k] - b.points[k]));
  return m;
}

std::vector<Case> Cases() {
  // Nine cameras; groups named by arbitrary ids (camera ids in the mapper). Two constant cameras
  // fix the gauge.
  const std::vector<char> first_two = {1, 1, 0, 0, 0, 0, 0, 0, 0};
  return {
      {"NoGroup", {-1, -1, -1, -1, -1, -1, -1, -1, -1}, first_two, {11}, false},
      {"OneGroup", {0, 0, 0, 0, 0, 0, 0, 0, 0}, first_two, {11}, false},
      {"TwoGroupsAndOwnIntrinsics", {4, 4, 4, 1, 4, 1, 1, -1, 1}, first_two, {11}, false},
      {"ConstantCamerasInsideTheGraph", {3, 3, 3, 3, 3, 3, 3, 3, 3}, {1, 0, 0, 0, 1, 0, 0, 1, 0}, {11}, false},
      {"ConstantPrincipalPointAndDistortion", {0, 0, 0, 0, 0, 0, 0, 0, 0}, first_two, {7, 8, 9, 10, 11}, false},
      {"ConstantPoints", {2, 2, 5, 5, 2, 5, 2, 5, 2}, first_two, {9, 10, 11}, true},
  };
}

class SharedIntrinsicsTest : public ::testing::TestWithParam<Case> {};

TEST_P(SharedIntrinsicsTest, OneStepSolvesTheDampedNormalEquations) {
  const Case& setup = GetParam();
  const RadialProblem start = MakeProblem(setup);
  const BundleAdjustmentConstancy constancy = ConstancyOf(setup, start);
  BundleAdjustmentOptions options;
  options.max_iterations = 1;
  const RadialProblem expected = ReferenceStep(start, constancy, 1.0 / options.initial_trust_region_radius, options);
  for (LinearSolver solver : {LinearSolver::kDenseCholesky, LinearSolver::kSparseCholesky}) {
    SCOPED_TRACE(solver == LinearSolver::kDenseCholesky ? "dense" : "sparse");
    options.linear_solver = solver;
    RadialProblem problem = start;
    Result<BundleAdjustmentSummary> r = SolveBundleAdjustment(options, constancy, &problem);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_EQ(r->accepted_steps, 1);
    EXPECT_LT(CameraDifference(problem, expected), 1e-9);
    EXPECT_LT(PointDifference(problem, expected), 1e-9);
    // The step moved the shared intrinsics, by the same amount in every camera of a group.
    for (int i = 0; i < problem.num_cameras(); ++i) {
      if (constancy.constant_cameras[static_cast<size_t>(i)]) {
        for (int k = 0; k < 12; ++k) EXPECT_EQ(problem.camera(i)[k], start.camera(i)[k]);
        continue;
      }
      EXPECT_NE(problem.camera(i)[6], start.camera(i)[6]);
      for (int m : setup.constant_parameters) EXPECT_EQ(problem.camera(i)[m], start.camera(i)[m]);
    }
  }
}

TEST_P(SharedIntrinsicsTest, SparseSolverMatchesDense) {
  const Case& setup = GetParam();
  RadialProblem dense = MakeProblem(setup);
  RadialProblem sparse = dense;
  const RadialProblem start = dense;
  const BundleAdjustmentConstancy constancy = ConstancyOf(setup, dense);
  BundleAdjustmentOptions options;
  options.max_iterations = 30;
  options.function_tolerance = 1e-10;
  Result<BundleAdjustmentSummary> rd = SolveBundleAdjustment(options, constancy, &dense);
  options.linear_solver = LinearSolver::kSparseCholesky;
  options.num_threads = 2;
  Result<BundleAdjustmentSummary> rs = SolveBundleAdjustment(options, constancy, &sparse);
  ASSERT_TRUE(rd.ok() && rs.ok());
  EXPECT_TRUE(rd->converged()) << TerminationName(rd->termination);
  // Below the cost of the observations' noise at the truth (0.5 px: 1/2 E|r|^2 = 1/4 each).
  EXPECT_LT(rd->final_cost, 0.25 * static_cast<double>(dense.observations.size()));
  EXPECT_EQ(rd->iterations, rs->iterations);
  EXPECT_NEAR(rd->final_cost, rs->final_cost, 1e-10 * rd->initial_cost);
  EXPECT_LT(CameraDifference(dense, sparse), 1e-8);
  EXPECT_LT(PointDifference(dense, sparse), 1e-8);
  // Shared intrinsics stay equal within a group; constant blocks and parameters stay put.
  for (int i = 0; i < dense.num_cameras(); ++i) {
    // A constant camera keeps intrinsics of its own.
    const int g = constancy.constant_cameras[static_cast<size_t>(i)] ? -1 : constancy.intrinsics_group[static_cast<size_t>(i)];
    for (int i2 = 0; i2 < i && g >= 0; ++i2) {
      if (constancy.constant_cameras[static_cast<size_t>(i2)] || constancy.intrinsics_group[static_cast<size_t>(i2)] != g) {
        continue;
      }
      for (int k = 6; k < 12; ++k) EXPECT_EQ(sparse.camera(i)[k], sparse.camera(i2)[k]);
    }
    for (int k = 0; k < 12; ++k) {
      const bool held = constancy.constant_cameras[static_cast<size_t>(i)] ||
                        std::count(setup.constant_parameters.begin(), setup.constant_parameters.end(), k) > 0;
      if (held) EXPECT_EQ(sparse.camera(i)[k], start.camera(i)[k]);
    }
  }
  for (int j = 0; j < sparse.num_points(); ++j) {
    if (constancy.constant_points.empty() || !constancy.constant_points[static_cast<size_t>(j)]) continue;
    for (int d = 0; d < 3; ++d) EXPECT_EQ(sparse.point(j)[d], start.point(j)[d]);
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, SharedIntrinsicsTest, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace
}  // namespace reconar
