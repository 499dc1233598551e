#pragma once
// Sparse Cholesky factorisation A = L L^T of a symmetric positive definite matrix with SuiteSparse
// CHOLMOD (Chen, Davis, Hager & Rajamanickam, "Algorithm 887: CHOLMOD, Supernodal Sparse
// Cholesky Factorization and Update/Downdate", ACM TOMS 35(3), 2008): supernodal numeric
// factorisation, fill-reducing ordering (AMD, or METIS when CHOLMOD finds it better) chosen by
// CHOLMOD during Analyze.
//
// Use: Analyze once per sparsity pattern, then Factorize + Solve as often as the values change
// (e.g. every Levenberg-Marquardt iteration). The CHOLMOD workspace, the symbolic and numeric
// factor and the solve buffers live in this object and are reused; Factorize and Solve make no
// heap allocation of ours (CHOLMOD may still allocate temporaries internally).
//
// Built without CHOLMOD (RECONAR_WITH_CHOLMOD=OFF), IsAvailable() is false and Analyze returns
// Unsupported. Not thread-safe: one object per thread.
#include <memory>

#include "core/base/status.h"

namespace reconar {

class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  // True when reconar was built with CHOLMOD (RECONAR_HAVE_CHOLMOD).
  static bool IsAvailable();

  // Symbolic analysis of the n x n symmetric matrix whose upper triangle (diagonal included) is
  // given in compressed sparse column form: column j holds row indices
  // row_idx[col_ptr[j] .. col_ptr[j+1]), strictly increasing and each in [0, j]; col_ptr has
  // n + 1 entries starting at 0. The pattern is copied. InvalidArgument for a malformed pattern,
  // Unsupported without CHOLMOD, ResourceExhausted / Internal when CHOLMOD fails. Replaces any
  // earlier analysis.
  Status Analyze(int n, const int* col_ptr, const int* row_idx);

  // Numeric factorisation of the analysed pattern with `values` (col_ptr[n] entries, in the order
  // of row_idx). False if the matrix is not positive definite (or not finite), in which case
  // Solve must not be called until a later Factorize succeeds. Requires a successful Analyze.
  bool Factorize(const double* values);

  // x = A^-1 rhs with the last successful factorisation; rhs and x hold n values and may alias.
  void Solve(const double* rhs, double* x);

  int size() const;  // n of the last successful Analyze, 0 before

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace reconar
