#pragma once
// The adjugate (transposed cofactor matrix) of a 3x3 matrix: adj(A) A = A adj(A) = det(A) I. The
// cubic det(A + g B) = det A + g tr(adj(A) B) + g^2 tr(A adj(B)) + g^3 det B of the 7-point F
// and the P3P solvers is built from it.
#include <Eigen/Core>

namespace reconar {

inline Eigen::Matrix3d Adjugate(const Eigen::Matrix3d& A) {
  Eigen::Matrix3d adj;
  adj(0, 0) = A(1, 1) * A(2, 2) - A(1, 2) * A(2, 1);
  adj(0, 1) = A(0, 2) * A(2, 1) - A(0, 1) * A(2, 2);
  adj(0, 2) = A(0, 1) * A(1, 2) - A(0, 2) * A(1, 1);
  adj(1, 0) = A(1, 2) * A(2, 0) - A(1, 0) * A(2, 2);
  adj(1, 1) = A(0, 0) * A(2, 2) - A(0, 2) * A(2, 0);
  adj(1, 2) = A(0, 2) * A(1, 0) - A(0, 0) * A(1, 2);
  adj(2, 0) = A(1, 0) * A(2, 1) - A(1, 1) * A(2, 0);
  adj(2, 1) = A(0, 1) * A(2, 0) - A(0, 0) * A(2, 1);
  adj(2, 2) = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  return adj;
}

}  // namespace reconar
