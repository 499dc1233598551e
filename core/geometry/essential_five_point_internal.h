#pragma once
// The last step of EssentialFivePoint::Estimate (essential_five_point.h), in its own translation
// unit (essential_five_point_roots.cc) so that the 10x10 eigen decomposition it instantiates
// compiles in parallel with the null-space and elimination steps; not a public API.
#include <Eigen/Core>
#include <array>

namespace reconar::five_point_internal {

// Positions of the monomials y, z and 1 in the action matrix's quotient-ring basis
// {x^2, xy, xz, y^2, yz, z^2, x, y, z, 1}.
constexpr int kBasisY = 7;
constexpr int kBasisZ = 8;
constexpr int kBasisOne = 9;

// The real solutions from the action matrix of multiplication by x: each eigenvector with a real
// eigenvalue x and a non-zero 1-component gives (y, z) = (v_y, v_z) / v_1 and
// E = x X + y Y + z Z + W (the columns of null_space), scaled to unit Frobenius norm.
// Returns how many were written to *models (0..10); 0 when the eigen decomposition fails.
int SolutionsFromActionMatrix(const Eigen::Matrix<double, 10, 10>& action,
                              const Eigen::Matrix<double, 9, 4>& null_space, std::array<Eigen::Matrix3d, 10>* models);

}  // namespace reconar::five_point_internal
