#pragma once
// Bundle adjustment of BAL problems: Levenberg-Marquardt with a trust-region radius update
// (the one LM loop, core/math/lm_loop.h: Nocedal & Wright, "Numerical Optimization", 2nd ed.,
// ch. 4 and 10.3; Madsen, Nielsen & Tingleff, "Methods for Non-Linear Least Squares Problems",
// 2004, sec. 3.2), Marquardt scaling of the damping by diag(J^T J), analytic Jacobians
// (bal_camera_model.h, radial_camera_model.h), and the Schur
// complement that eliminates the points (Triggs et al., "Bundle Adjustment - A Modern
// Synthesis", 2000, sec. 6.1; Brown 1958). The reduced camera system, in the unknowns of the
// shared intrinsics when cameras share them, is solved with a dense Cholesky factorisation or a
// sparse one (symmetric_block_system.h).
#include <vector>

#include "core/base/status.h"
#include "core/math/lm_loop.h"
#include "core/math/robust_loss.h"
#include "core/optim/bal_problem.h"

namespace reconar {

// The LM settings (core/math/lm_loop.h) with the bundle adjuster's defaults, and its own.
struct BundleAdjustmentOptions : LmOptions {
  BundleAdjustmentOptions() {
    max_iterations = 100;
    function_tolerance = 1e-6;
    gradient_tolerance = 1e-10;  // on g = J^T r over the free parameters
    parameter_tolerance = 1e-8;
    max_consecutive_numeric_failures = 5;  // failed Cholesky factorisations of the reduced system
  }
  // diag(J^T J) is clamped to [min_diagonal, max_diagonal] before scaling the damping.
  double max_diagonal = 1e32;
  RobustLoss loss;
  // Solver of the reduced camera system S dc = b: a block per free camera (its camera
  // parameters, or only its pose when it shares its intrinsics) and one per intrinsics group.
  enum class LinearSolver {
    kDenseCholesky,   // Eigen LLT on dense S: for small problems and dense camera graphs
    kSparseCholesky,  // S's coupled blocks (camera pairs sharing a point, cameras and the groups
                      // they see), AMD camera ordering with the groups last, CHOLMOD supernodal
                      // Cholesky (Eigen SimplicialLDLT when built without CHOLMOD)
    kAuto,            // sparse when S has at least kMinSparseUnknowns unknowns and its coupled
                      // blocks fill at most kMaxSparseFill of its upper triangle, else dense
  };
  // The crossover of kAuto, measured on the mapper's global adjustments (docs/figures.md, "The
  // bundle adjuster's linear solvers"): on a 400-photo corridor walk sparse took 0.78 of dense's
  // time at 570 unknowns and fill 0.53, 0.20 at 2406 and 0.12, but 1.07 at fill 0.65; round the
  // 320-photo bunny (fill 0.66 at the end) dense was faster at every size (sparse 1.1 to 1.5x).
  // Under 500 unknowns either takes under 0.1 s.
  static constexpr int kMinSparseUnknowns = 500;
  static constexpr double kMaxSparseFill = 0.6;
  LinearSolver linear_solver = LinearSolver::kAuto;
  int num_threads = 1;  // <= 0: one per core

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

// RunLm's summary (termination, costs 1/2 sum rho(|r|^2), iterations, accepted steps); the
// kNumericFailure of the bundle adjuster: the initial cost is not finite, or the Cholesky
// factorisation of the reduced camera system failed (or gave a non-finite step)
// max_consecutive_numeric_failures times in a row.
struct BundleAdjustmentSummary : LmSummary {
  double seconds = 0.0;  // wall time of SolveBundleAdjustment (setup included)
  // The solver that ran (kAuto resolved) and the size of its reduced system.
  BundleAdjustmentOptions::LinearSolver linear_solver = BundleAdjustmentOptions::LinearSolver::kDenseCholesky;
  int reduced_unknowns = 0;
};

// Which parameter blocks are held constant; empty vectors mean every block is free, otherwise
// one entry per camera / point (non-zero = constant).
struct BundleAdjustmentConstancy {
  std::vector<char> constant_cameras;
  std::vector<char> constant_points;
  // Parameters held constant in every camera block, as indices into the block (e.g. 9 and 10,
  // the principal point of a RadialProblem camera).
  std::vector<int> constant_camera_parameters;
  // Shared intrinsics: empty, or one entry per camera; free cameras with the same non-negative
  // group share the intrinsic parameters (index 6 onwards of the block: f, k1, k2 [, cx, cy, a]),
  // which must start out equal.
  std::vector<int> intrinsics_group;
};

// Minimises 1/2 sum_k rho(|u(camera, point) - observed|^2) over the free cameras and points of
// `problem`, in place. InvalidArgument for bad options, a malformed problem or mis-sized
// constancy vectors; numeric trouble is reported through summary.termination, with `problem`
// holding the last accepted parameters.
Result<BundleAdjustmentSummary> SolveBundleAdjustment(const BundleAdjustmentOptions& options,
                                                      const BundleAdjustmentConstancy& constancy,
                                                      BalProblem* problem);
// The same for COLMAP RADIAL cameras (radial_camera_model.h), observations in image pixels.
Result<BundleAdjustmentSummary> SolveBundleAdjustment(const BundleAdjustmentOptions& options,
                                                      const BundleAdjustmentConstancy& constancy,
                                                      RadialProblem* problem);

// 1/2 sum_k rho(|r_k|^2) at the current parameters (non-finite if a point projects badly).
double BundleAdjustmentCost(const BalProblem& problem, const RobustLoss& loss);
double BundleAdjustmentCost(const RadialProblem& problem, const RobustLoss& loss);

}  // namespace reconar
