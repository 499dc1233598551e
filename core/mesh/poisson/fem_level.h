#pragma once
// One level of the cascadic finite-element solve of the screened Poisson equation
// (Kazhdan & Hoppe 2013, "Screened Poisson Surface Reconstruction", ACM ToG 32(3)).
//
// Discretisation, by `degree`:
//  1: trilinear (first-order B-spline) hat functions phi_i on the nodes of the level's regular
//     grid over the unit cube (spacing h = 2^-depth), natural (Neumann) boundary conditions, i.e.
//     hats truncated at the cube. Unknown i is node i (2^depth + 1 per axis).
//  2: quadratic (second-order) B-splines centred on the cells (support 3 cells per axis, as in
//     PoissonRecon's --degree 2); unknown i is cell i (2^depth per axis, stored in the BlockGrid
//     slot of the cell's lower corner node; the last node slot per axis is unused). Neumann
//     boundary by reflection: the B-splines centred just outside the cube (cells -1 and 2^depth)
//     are folded onto their mirror images (cells 0 and 2^depth - 1), so constants stay
//     representable up to the boundary. Stencils are 5x5x5; refinement is the two-scale relation
//     B(x) = (B(2x+1.5) + 3 B(2x+0.5) + 3 B(2x-0.5) + B(2x-1.5)) / 4, i.e. prolongation weights
//     [1, 3, 3, 1] / 4 from a coarse cell to its 4 nearest fine cells per axis.
// The energy
//   E(chi) = integral |grad chi - V|^2  +  lambda * sum_s area_s * chi(p_s)^2
// gives the system (K + lambda * S) x = b with K_ij = integral grad phi_i . grad phi_j,
// S_ij = sum_s area_s phi_i(p_s) phi_j(p_s) and b_i = integral V . grad phi_i. V is the field of
// area-weighted sample normals splatted at the finest level, so chi grows outwards: negative
// inside, positive outside, and the iso-value sits near 0 (the screening pulls chi(p_s) to 0).
//
// Cascade: a level's unknowns are the nodes of its band ("active" nodes); every other stored node
// keeps the value prolonged from the coarser level and acts as a Dirichlet value. This is the
// Galerkin system for the correction on the band, solved by Jacobi-preconditioned CG.
#include <cstdint>
#include <vector>

#include "core/base/thread_pool.h"
#include "core/mesh/poisson/block_grid.h"

namespace reconar::poisson {

constexpr int kMaxSupport = 27;  // basis functions that are non-zero at a point (degree 2: 3^3)

// Basis functions non-zero at a point: 8 (degree 1) or 27 (degree 2).
inline int SupportSize(int degree) { return degree == 1 ? 8 : 27; }
// Unknowns per axis of a level: nodes (degree 1) or cells (degree 2).
inline int UnknownsPerAxis(const BlockGrid& grid, int degree) {
  return degree == 1 ? grid.nodes_per_axis() : grid.cells_per_axis();
}
inline bool IsUnknown(const BlockGrid& grid, int degree, const Eigen::Vector3i& index) {
  return (index.array() >= 0).all() && (index.array() < UnknownsPerAxis(grid, degree)).all();
}

// Degree 2 prolongation along one axis: fine cell `fine` is 3/4 of its parent coarse cell plus
// 1/4 of the parent's neighbour on the fine cell's side (folded at the boundary). Writes the two
// coarse cells; their weights are kQuadraticChildWeights.
constexpr float kQuadraticChildWeights[2] = {0.75f, 0.25f};
inline void QuadraticParents(int fine, int coarse_cells, int parents[2]) {
  parents[0] = fine >> 1;
  const int side = parents[0] + ((fine & 1) ? 1 : -1);
  parents[1] = side < 0 ? 0 : (side >= coarse_cells ? coarse_cells - 1 : side);
}

// Weights of the basis functions non-zero at `p` (unit-cube coordinates) on a level of `depth`:
// their grid indices (with the boundary reflection folded in) and values. Returns the count,
// SupportSize(degree). `derivative_axis` >= 0 differentiates along that axis instead (per unit
// of the level's spacing h).
int BasisAt(int degree, int depth, const Eigen::Vector3f& p, Eigen::Vector3i indices[kMaxSupport],
            float weights[kMaxSupport], int derivative_axis = -1);

// A screening sample at one level: the samples of one cell merged into their area-weighted
// centroid (as PoissonRecon does), with the unknowns whose basis functions are non-zero there.
struct ScreeningPoint {
  int32_t nodes[kMaxSupport];
  float weights[kMaxSupport];
  float area;        // total surface area represented, unit-cube units
};

struct FemLevel {
  FemLevel(int depth, int basis_degree) : grid(depth), degree(basis_degree), support(SupportSize(basis_degree)) {}

  BlockGrid grid;
  int degree;
  int support;                        // SupportSize(degree)
  std::vector<uint8_t> active;        // per node slot: 1 = unknown of this level's solve
  std::vector<int32_t> active_blocks; // blocks holding at least one active node
  std::vector<float> solution;        // per node slot: chi at the node
  std::vector<float> rhs;             // per node slot: b_i (zero away from the samples)
  std::vector<ScreeningPoint> points;
  // The screening points' active unknowns grouped by active block (IndexScreeningPoints): the
  // entries of active_blocks[b] are screening_entries[screening_offsets[b] ..
  // screening_offsets[b + 1]), in point order, so every block can be updated by one thread.
  std::vector<uint32_t> screening_offsets;
  std::vector<uint32_t> screening_entries;
};

struct CgReport {
  int iterations = 0;
  double initial_residual = 0.0;
  double final_residual = 0.0;
};

// Fills level->screening_offsets/entries; call after active_blocks, active and points are set.
void IndexScreeningPoints(FemLevel* level);

// out = A * in on the active nodes (other slots of `out` are left untouched; `in` must be zero
// or meaningful on all stored nodes). lambda: screening weight. Blocks and points are split
// among the pool's threads (nullptr: the calling thread); every node's sum is formed in the same
// order whatever the thread count, so the result does not depend on it. point_values: scratch.
void ApplyScreenedPoisson(const FemLevel& level, double lambda, const float* in, float* out, ThreadPool* pool,
                          std::vector<float>* point_values);

// Diagonal of A at every active node (zero elsewhere).
std::vector<float> ScreenedPoissonDiagonal(const FemLevel& level, double lambda);

// b_i = integral V . grad phi_i at every unknown of `grid`, where V = sum_j area_normal[j] / h^3 phi_j
// is given by its (area-weighted normal) coefficients on the same grid and basis.
void ComputeDivergenceRhs(int degree, const BlockGrid& grid, const std::vector<float>& area_normal_x,
                          const std::vector<float>& area_normal_y, const std::vector<float>& area_normal_z,
                          std::vector<float>* rhs);

// coarse += P^T fine (P: the prolongation of the basis of `degree` from coarse to fine). Fine
// unknowns whose coarse parents are absent are dropped.
void RestrictAdd(int degree, const BlockGrid& fine_grid, const std::vector<float>& fine, const BlockGrid& coarse_grid,
                 std::vector<float>* coarse);

// Runs Jacobi-preconditioned CG on the active nodes of `level` starting from level->solution,
// stopping after max_iterations or when |r| <= relative_tolerance * |r0|. Products and vector
// updates run on `pool` (nullptr: the calling thread); dot products are summed per fixed chunk
// of blocks, then in chunk order, so the iterates are identical for any thread count.
CgReport SolveLevel(FemLevel* level, double lambda, int max_iterations, double relative_tolerance, ThreadPool* pool);

}  // namespace reconar::poisson
