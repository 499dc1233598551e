#pragma once
// Null spaces of the homogeneous DLT systems A m = 0 (m a 3x3 model stacked row-major into a
// 9-vector), in fixed-size Eigen types so the minimal solvers never touch the heap.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

namespace reconar {

// Minimal case: A has kRows < 9 rows of full rank. With A^T = Q R (Householder QR), the first
// kRows columns of Q span the row space of A, so the remaining 9 - kRows columns are an
// orthonormal basis of its null space. Exact to working precision, unlike forming A^T A.
template <int kRows>
Eigen::Matrix<double, 9, 9 - kRows> NullSpaceOfWideMatrix(const Eigen::Matrix<double, kRows, 9>& A) {
  static_assert(kRows > 0 && kRows < 9, "A must be wide");
  const Eigen::HouseholderQR<Eigen::Matrix<double, 9, kRows>> qr(A.transpose());
  const Eigen::Matrix<double, 9, 9> Q = qr.householderQ();
  return Q.template rightCols<9 - kRows>();
}

// Least-squares case: the kDim right singular vectors of A with the smallest singular values,
// computed as eigenvectors of the 9x9 normal matrix A^T A (accumulated by the caller, which keeps
// memory constant in the number of rows). Callers normalise the data first (Hartley), which keeps
// the squared condition number harmless.
template <int kDim>
Eigen::Matrix<double, 9, kDim> SmallestEigenvectors(const Eigen::Matrix<double, 9, 9>& AtA) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> solver(AtA);
  return solver.eigenvectors().template leftCols<kDim>();  // eigenvalues are sorted increasingly
}

// Row-major 9-vector -> 3x3 matrix.
inline Eigen::Matrix3d Matrix3FromVector(const Eigen::Matrix<double, 9, 1>& v) {
  Eigen::Matrix3d M;
  M << v(0), v(1), v(2), v(3), v(4), v(5), v(6), v(7), v(8);
  return M;
}

// The epipolar constraint x2^T M x1 = 0 as a row acting on row-major vec(M).
inline Eigen::Matrix<double, 1, 9> EpipolarRow(const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) {
  Eigen::Matrix<double, 1, 9> row;
  row << x2.x() * x1.x(), x2.x() * x1.y(), x2.x(), x2.y() * x1.x(), x2.y() * x1.y(), x2.y(), x1.x(),
      x1.y(), 1.0;
  return row;
}

}  // namespace reconar
