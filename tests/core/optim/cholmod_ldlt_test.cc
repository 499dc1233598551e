// SparseCholesky (CHOLMOD) against Eigen's dense LLT on random sparse SPD matrices: solutions,
// non-SPD detection and refactorisation of the same pattern with new values.
#include "core/optim/cholmod_ldlt.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace reconar {
namespace {

// Upper triangle (diagonal included) of a symmetric matrix in compressed sparse columns.
struct UpperCsc {
  int n = 0;
  std::vector<int> col_ptr, row_idx;
  std::vector<double> values;
};

UpperCsc ToUpperCsc(const Eigen::MatrixXd& a) {
  UpperCsc m;
  m.n = static_cast<int>(a.rows());
  m.col_ptr.push_back(0);
  for (int j = 0; j < m.n; ++j) {
    for (int i = 0; i <= j; ++i) {
      if (a(i, j) != 0.0 || i == j) {
        m.row_idx.push_back(i);
        m.values.push_back(a(i, j));
      }
    }
    m.col_ptr.push_back(static_cast<int>(m.row_idx.size()));
  }
  return m;
}

// Symmetric, about `density` of the off-diagonal entries non-zero (values in [-1, 1]), and
// strictly diagonally dominant with a positive diagonal, hence SPD and well conditioned.
Eigen::MatrixXd RandomSparseSpd(int n, double density, std::mt19937* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), value(-1.0, 1.0);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < j; ++i) {
      if (unit(*rng) < density) a(i, j) = a(j, i) = value(*rng);
    }
  }
  for (int i = 0; i < n; ++i) a(i, i) = a.row(i).cwiseAbs().sum() + 0.5 + unit(*rng);
  return a;
}

// Like a reduced camera system: dense b x b blocks on the diagonal and between random pairs of
// block columns (cameras sharing points); supernodes form on this structure.
Eigen::MatrixXd RandomBlockSpd(int blocks, int b, double pair_probability, std::mt19937* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), value(-1.0, 1.0);
  const int n = blocks * b;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int bj = 0; bj < blocks; ++bj) {
    for (int bi = 0; bi <= bj; ++bi) {
      if (bi != bj && unit(*rng) >= pair_probability) continue;
      for (int j = 0; j < b; ++j) {
        for (int i = 0; i < b; ++i) {
          const int r = bi * b + i, c = bj * b + j;
          if (r < c) a(r, c) = a(c, r) = value(*rng);
        }
      }
    }
  }
  for (int i = 0; i < n; ++i) a(i, i) = a.row(i).cwiseAbs().sum() + 0.5 + unit(*rng);
  return a;
}

double RelativeError(const Eigen::VectorXd& x, const Eigen::VectorXd& reference) {
  return (x - reference).norm() / reference.norm();
}

class SparseCholeskyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!SparseCholesky::IsAvailable()) GTEST_SKIP() << "built without CHOLMOD";
  }
};

TEST_F(SparseCholeskyTest, MatchesDenseLltOnRandomSpdMatrices) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  struct Case {
    int n;
    double density;
  };
  for (const Case c : {Case{1, 0.0}, Case{5, 0.5}, Case{40, 0.1}, Case{200, 0.02}, Case{300, 0.3}}) {
    SCOPED_TRACE(testing::Message() << "n = " << c.n << ", density " << c.density);
    const Eigen::MatrixXd a = RandomSparseSpd(c.n, c.density, &rng);
    const UpperCsc m = ToUpperCsc(a);
    SparseCholesky cholesky;
    ASSERT_TRUE(cholesky.Analyze(m.n, m.col_ptr.data(), m.row_idx.data()).ok());
    EXPECT_EQ(cholesky.size(), c.n);
    ASSERT_TRUE(cholesky.Factorize(m.values.data()));
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd rhs(c.n);
      for (int i = 0; i < c.n; ++i) rhs[i] = normal(rng);
      const Eigen::VectorXd reference = a.llt().solve(rhs);
      Eigen::VectorXd x(c.n);
      cholesky.Solve(rhs.data(), x.data());
      EXPECT_LT(RelativeError(x, reference), 1e-10);
      EXPECT_LT((a * x - rhs).norm() / rhs.norm(), 1e-10);
    }
  }
}

TEST_F(SparseCholeskyTest, MatchesDenseLltOnBlockStructuredSystem) {
  std::mt19937 rng(11);
  const Eigen::MatrixXd a = RandomBlockSpd(/*blocks=*/60, /*b=*/9, /*pair_probability=*/0.08, &rng);
  const UpperCsc m = ToUpperCsc(a);
  SparseCholesky cholesky;
  ASSERT_TRUE(cholesky.Analyze(m.n, m.col_ptr.data(), m.row_idx.data()).ok());
  ASSERT_TRUE(cholesky.Factorize(m.values.data()));
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(m.n, -1.0, 2.0);
  Eigen::VectorXd x(m.n);
  cholesky.Solve(rhs.data(), x.data());
  EXPECT_LT(RelativeError(x, a.llt().solve(rhs)), 1e-10);
  // rhs and x may be the same array.
  Eigen::VectorXd in_place = rhs;
  cholesky.Solve(in_place.data(), in_place.data());
  EXPECT_EQ(in_place, x);
}

TEST_F(SparseCholeskyTest, NotPositiveDefiniteReportsFalse) {
  std::mt19937 rng(3);
  Eigen::MatrixXd a = RandomSparseSpd(50, 0.1, &rng);
  a(17, 17) = -1.0;  // e_17^T A e_17 < 0
  const UpperCsc m = ToUpperCsc(a);
  SparseCholesky cholesky;
  ASSERT_TRUE(cholesky.Analyze(m.n, m.col_ptr.data(), m.row_idx.data()).ok());
  EXPECT_FALSE(cholesky.Factorize(m.values.data()));

  // Singular (positive semi-definite): a zero row and column.
  Eigen::MatrixXd singular = RandomSparseSpd(20, 0.2, &rng);
  singular.row(4).setZero();
  singular.col(4).setZero();
  const UpperCsc s = ToUpperCsc(singular);
  ASSERT_TRUE(cholesky.Analyze(s.n, s.col_ptr.data(), s.row_idx.data()).ok());
  EXPECT_FALSE(cholesky.Factorize(s.values.data()));

  std::vector<double> not_finite = s.values;
  not_finite[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(cholesky.Factorize(not_finite.data()));
}

TEST_F(SparseCholeskyTest, RefactorizesWithNewValuesAfterSuccessAndFailure) {
  std::mt19937 rng(5);
  const Eigen::MatrixXd a = RandomSparseSpd(120, 0.05, &rng);
  const UpperCsc m = ToUpperCsc(a);
  SparseCholesky cholesky;
  ASSERT_TRUE(cholesky.Analyze(m.n, m.col_ptr.data(), m.row_idx.data()).ok());
  const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(m.n);
  Eigen::VectorXd x(m.n);

  // Same pattern, new values: a Levenberg-Marquardt style damping of the diagonal.
  for (const double damping : {0.0, 10.0, 1e-3}) {
    SCOPED_TRACE(testing::Message() << "damping " << damping);
    Eigen::MatrixXd damped = a;
    damped.diagonal().array() += damping;
    const UpperCsc d = ToUpperCsc(damped);
    ASSERT_EQ(d.row_idx, m.row_idx);
    ASSERT_TRUE(cholesky.Factorize(d.values.data()));
    cholesky.Solve(rhs.data(), x.data());
    EXPECT_LT(RelativeError(x, damped.llt().solve(rhs)), 1e-10);
  }

  // A failed factorisation does not spoil the next one.
  Eigen::MatrixXd indefinite = a;
  indefinite(60, 60) = -5.0;
  const UpperCsc bad = ToUpperCsc(indefinite);
  ASSERT_EQ(bad.row_idx, m.row_idx);
  EXPECT_FALSE(cholesky.Factorize(bad.values.data()));
  ASSERT_TRUE(cholesky.Factorize(m.values.data()));
  cholesky.Solve(rhs.data(), x.data());
  EXPECT_LT(RelativeError(x, a.llt().solve(rhs)), 1e-10);

  // Moving keeps the factorisation.
  SparseCholesky moved = std::move(cholesky);
  Eigen::VectorXd y(m.n);
  moved.Solve(rhs.data(), y.data());
  EXPECT_EQ(x, y);
}

TEST_F(SparseCholeskyTest, RejectsMalformedPatterns) {
  SparseCholesky cholesky;
  const std::vector<int> col_ptr = {0, 1, 3};
  EXPECT_EQ(cholesky.Analyze(0, col_ptr.data(), nullptr).code(), StatusCode::kInvalidArgument);
  const std::vector<int> lower = {0, 1, 1};  // row 1 in column 0
  EXPECT_EQ(cholesky.Analyze(2, col_ptr.data(), lower.data()).code(), StatusCode::kInvalidArgument);
  const std::vector<int> unsorted = {0, 1, 0};
  EXPECT_EQ(cholesky.Analyze(2, col_ptr.data(), unsorted.data()).code(), StatusCode::kInvalidArgument);
  const std::vector<int> decreasing = {0, 1, 0};
  const std::vector<int> rows = {0};
  EXPECT_EQ(cholesky.Analyze(2, decreasing.data(), rows.data()).code(), StatusCode::kInvalidArgument);
  const std::vector<int> good = {0, 0, 1};
  EXPECT_TRUE(cholesky.Analyze(2, col_ptr.data(), good.data()).ok());
  EXPECT_EQ(cholesky.size(), 2);
}

}  // namespace
}  // namespace reconar
