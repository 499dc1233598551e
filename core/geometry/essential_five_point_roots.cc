#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>

#include "core/geometry/essential_five_point_internal.h"
#include "core/geometry/null_space.h"

namespace reconar::five_point_internal {

int SolutionsFromActionMatrix(const Eigen::Matrix<double, 10, 10>& action,
                              const Eigen::Matrix<double, 9, 4>& null_space, std::array<Eigen::Matrix3d, 10>* models) {
  const Eigen::EigenSolver<Eigen::Matrix<double, 10, 10>> eigen(action, /*computeEigenvectors=*/true);
  if (eigen.info() != Eigen::Success) return 0;

  const Eigen::Matrix<std::complex<double>, 10, 10> eigenvectors = eigen.eigenvectors();
  int num_models = 0;
  for (int k = 0; k < 10; ++k) {
    const std::complex<double> lambda = eigen.eigenvalues()(k);
    if (std::abs(lambda.imag()) > 1e-8 * (1.0 + std::abs(lambda.real()))) continue;  // complex root
    const Eigen::Matrix<std::complex<double>, 10, 1> v = eigenvectors.col(k);
    if (std::abs(v(kBasisOne)) < 1e-12 * v.norm()) continue;  // solution at infinity
    const double x = lambda.real();
    const double y = (v(kBasisY) / v(kBasisOne)).real();
    const double z = (v(kBasisZ) / v(kBasisOne)).real();
    const Eigen::Matrix<double, 9, 1> e =
        x * null_space.col(0) + y * null_space.col(1) + z * null_space.col(2) + null_space.col(3);
    const double norm = e.norm();
    if (!(norm > 0.0) || !e.allFinite()) continue;
    (*models)[num_models++] = Matrix3FromVector(e / norm);
  }
  return num_models;
}

}  // namespace reconar::five_point_internal
