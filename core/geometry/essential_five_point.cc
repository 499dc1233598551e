#include "core/geometry/essential_five_point.h"

#include <Eigen/LU>

#include "core/geometry/essential_five_point_internal.h"
#include "core/geometry/null_space.h"
#include "core/geometry/residuals.h"

namespace reconar {
namespace {

// Polynomials of degree <= 3 in (x, y, z) as 20 coefficients. The 10 cubic monomials come first
// (they are eliminated), then the quotient-ring basis in the order used by the action matrix.
constexpr int kNumMonomials = 20;
constexpr int kExponents[kNumMonomials][3] = {
    {3, 0, 0}, {2, 1, 0}, {2, 0, 1}, {1, 2, 0}, {1, 1, 1},  // x^3 x^2y x^2z xy^2 xyz
    {1, 0, 2}, {0, 3, 0}, {0, 2, 1}, {0, 1, 2}, {0, 0, 3},  // xz^2 y^3 y^2z yz^2 z^3
    {2, 0, 0}, {1, 1, 0}, {1, 0, 1}, {0, 2, 0}, {0, 1, 1},  // x^2 xy xz y^2 yz
    {0, 0, 2}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 0},  // z^2 x y z 1
};
constexpr int kFirstQuadratic = 10;  // monomials [10, 20) have degree <= 2
constexpr int kFirstLinear = 16;     // monomials [16, 20) have degree <= 1

constexpr int MonomialIndex(int a, int b, int c) {
  for (int i = 0; i < kNumMonomials; ++i) {
    if (kExponents[i][0] == a && kExponents[i][1] == b && kExponents[i][2] == c) return i;
  }
  return -1;
}

struct ProductTable {
  int index[kNumMonomials][kNumMonomials];
};

// index[i][j] = monomial of m_i * m_j, or -1 when its degree exceeds 3.
constexpr ProductTable MakeProductTable() {
  ProductTable table{};
  for (int i = 0; i < kNumMonomials; ++i) {
    for (int j = 0; j < kNumMonomials; ++j) {
      table.index[i][j] = MonomialIndex(kExponents[i][0] + kExponents[j][0], kExponents[i][1] + kExponents[j][1],
                                        kExponents[i][2] + kExponents[j][2]);
    }
  }
  return table;
}
constexpr ProductTable kProducts = MakeProductTable();

using Poly = Eigen::Matrix<double, kNumMonomials, 1>;

// a * b where a has support in [a_first, 20) and b in [b_first, 20) and the product has degree <= 3.
Poly Multiply(const Poly& a, int a_first, const Poly& b, int b_first) {
  Poly product = Poly::Zero();
  for (int i = a_first; i < kNumMonomials; ++i) {
    for (int j = b_first; j < kNumMonomials; ++j) product(kProducts.index[i][j]) += a(i) * b(j);
  }
  return product;
}

// The 10x20 coefficient matrix of the cubic constraints for E = x X + y Y + z Z + W.
Eigen::Matrix<double, 10, kNumMonomials> ConstraintMatrix(const Eigen::Matrix<double, 9, 4>& null_space) {
  Poly E[3][3];  // each entry is linear in (x, y, z)
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      E[r][c] = Poly::Zero();
      E[r][c](MonomialIndex(1, 0, 0)) = null_space(3 * r + c, 0);
      E[r][c](MonomialIndex(0, 1, 0)) = null_space(3 * r + c, 1);
      E[r][c](MonomialIndex(0, 0, 1)) = null_space(3 * r + c, 2);
      E[r][c](MonomialIndex(0, 0, 0)) = null_space(3 * r + c, 3);
    }
  }

  Poly EEt[3][3];  // E E^T, quadratic
  for (int r = 0; r < 3; ++r) {
    for (int c = r; c < 3; ++c) {
      EEt[r][c] = Poly::Zero();
      for (int k = 0; k < 3; ++k) EEt[r][c] += Multiply(E[r][k], kFirstLinear, E[c][k], kFirstLinear);
      EEt[c][r] = EEt[r][c];
    }
  }
  const Poly trace = EEt[0][0] + EEt[1][1] + EEt[2][2];

  Eigen::Matrix<double, 10, kNumMonomials> M;
  // Rows 0..8: 2 E E^T E - tr(E E^T) E = 0 (the essential-matrix trace constraint).
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      Poly entry = -Multiply(trace, kFirstQuadratic, E[r][c], kFirstLinear);
      for (int k = 0; k < 3; ++k) entry += 2.0 * Multiply(EEt[r][k], kFirstQuadratic, E[k][c], kFirstLinear);
      M.row(3 * r + c) = entry.transpose();
    }
  }
  // Row 9: det(E) = 0, by cofactor expansion along the first row.
  const Poly minor0 = Multiply(E[1][1], kFirstLinear, E[2][2], kFirstLinear) -
                      Multiply(E[1][2], kFirstLinear, E[2][1], kFirstLinear);
  const Poly minor1 = Multiply(E[1][0], kFirstLinear, E[2][2], kFirstLinear) -
                      Multiply(E[1][2], kFirstLinear, E[2][0], kFirstLinear);
  const Poly minor2 = Multiply(E[1][0], kFirstLinear, E[2][1], kFirstLinear) -
                      Multiply(E[1][1], kFirstLinear, E[2][0], kFirstLinear);
  const Poly det = Multiply(minor0, kFirstQuadratic, E[0][0], kFirstLinear) -
                   Multiply(minor1, kFirstQuadratic, E[0][1], kFirstLinear) +
                   Multiply(minor2, kFirstQuadratic, E[0][2], kFirstLinear);
  M.row(9) = det.transpose();
  return M;
}

}  // namespace

int EssentialFivePoint::Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  Eigen::Matrix<double, 9, 4> null_space;
  if (count == kMinSamples) {
    Eigen::Matrix<double, kMinSamples, 9> A;
    for (int i = 0; i < kMinSamples; ++i) A.row(i) = EpipolarRow(samples[i].x1, samples[i].x2);
    null_space = NullSpaceOfWideMatrix<kMinSamples>(A);
  } else {
    Eigen::Matrix<double, 9, 9> AtA = Eigen::Matrix<double, 9, 9>::Zero();
    for (int i = 0; i < count; ++i) {
      const Eigen::Matrix<double, 1, 9> row = EpipolarRow(samples[i].x1, samples[i].x2);
      AtA.selfadjointView<Eigen::Lower>().rankUpdate(row.transpose());
    }
    AtA.triangularView<Eigen::StrictlyUpper>() = AtA.transpose();
    // The best-fitting vector (smallest eigenvalue) becomes W, the constant term: the solution
    // then lies near x = y = z = 0 instead of at infinity in the parameterisation.
    const Eigen::Matrix<double, 9, 4> smallest = SmallestEigenvectors<4>(AtA);
    null_space << smallest.col(1), smallest.col(2), smallest.col(3), smallest.col(0);
  }
  if (!null_space.allFinite()) return 0;

  // Gauss-Jordan elimination of the cubic monomials: [C | B] -> [I | C^-1 B].
  const Eigen::Matrix<double, 10, kNumMonomials> M = ConstraintMatrix(null_space);
  const Eigen::FullPivLU<Eigen::Matrix<double, 10, 10>> lu(M.leftCols<10>());
  if (!lu.isInvertible()) return 0;
  const Eigen::Matrix<double, 10, 10> G = lu.solve(M.rightCols<10>());
  if (!G.allFinite()) return 0;

  // Action matrix of multiplication by x on the basis b = {x^2, xy, xz, y^2, yz, z^2, x, y, z, 1}:
  // x b = A b. Basis elements of degree 2 map to cubic monomials, which the reduced equations
  // give as m_cubic = -G.row(m_cubic) b; the others map to basis elements.
  Eigen::Matrix<double, 10, 10> action = Eigen::Matrix<double, 10, 10>::Zero();
  for (int i = 0; i < 6; ++i) {
    const int basis = kFirstQuadratic + i;
    const int cubic = kProducts.index[MonomialIndex(1, 0, 0)][basis];
    action.row(i) = -G.row(cubic);
  }
  action(6, MonomialIndex(2, 0, 0) - kFirstQuadratic) = 1.0;  // x * x = x^2
  action(7, MonomialIndex(1, 1, 0) - kFirstQuadratic) = 1.0;  // x * y = xy
  action(8, MonomialIndex(1, 0, 1) - kFirstQuadratic) = 1.0;  // x * z = xz
  action(9, MonomialIndex(1, 0, 0) - kFirstQuadratic) = 1.0;  // x * 1 = x

  // The eigen decomposition and the solutions it gives (essential_five_point_roots.cc).
  static_assert(MonomialIndex(0, 1, 0) - kFirstQuadratic == five_point_internal::kBasisY, "basis order");
  static_assert(MonomialIndex(0, 0, 1) - kFirstQuadratic == five_point_internal::kBasisZ, "basis order");
  static_assert(MonomialIndex(0, 0, 0) - kFirstQuadratic == five_point_internal::kBasisOne, "basis order");
  return five_point_internal::SolutionsFromActionMatrix(action, null_space, models);
}

void EssentialFivePoint::Residuals(const Sample* samples, int count, const Model& E, double* squared_residuals) {
  for (int i = 0; i < count; ++i) squared_residuals[i] = SquaredSampsonError(E, samples[i].x1, samples[i].x2);
}

}  // namespace reconar
