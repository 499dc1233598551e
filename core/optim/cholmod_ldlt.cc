#include "core/optim/cholmod_ldlt.h"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#ifdef RECONAR_HAVE_CHOLMOD
#include <cholmod.h>
#endif

namespace reconar {

namespace {

// The pattern contract of SparseCholesky::Analyze, checked before CHOLMOD sees it.
Status CheckUpperCsc(int n, const int* col_ptr, const int* row_idx) {
  if (n < 1) return InvalidArgument("sparse Cholesky: matrix size must be >= 1, got " + std::to_string(n));
  if (col_ptr == nullptr || (row_idx == nullptr && col_ptr[n] != 0)) {
    return InvalidArgument("sparse Cholesky: null pattern array");
  }
  if (col_ptr[0] != 0) return InvalidArgument("sparse Cholesky: col_ptr[0] must be 0");
  for (int j = 0; j < n; ++j) {
    if (col_ptr[j + 1] < col_ptr[j]) {
      return InvalidArgument("sparse Cholesky: col_ptr decreases at column " + std::to_string(j));
    }
    for (int k = col_ptr[j]; k < col_ptr[j + 1]; ++k) {
      const int i = row_idx[k];
      if (i < 0 || i > j) {
        return InvalidArgument("sparse Cholesky: row " + std::to_string(i) + " in column " + std::to_string(j) +
                               " is outside the upper triangle");
      }
      if (k > col_ptr[j] && i <= row_idx[k - 1]) {
        return InvalidArgument("sparse Cholesky: rows of column " + std::to_string(j) +
                               " are not strictly increasing");
      }
    }
  }
  return Status::Ok();
}

}  // namespace

#ifdef RECONAR_HAVE_CHOLMOD

struct SparseCholesky::Impl {
  cholmod_common common;
  cholmod_sparse matrix;              // header over col_ptr / row_idx (ours) and the caller's values
  cholmod_factor* factor = nullptr;   // owned: symbolic after Analyze, numeric after Factorize
  cholmod_dense* solution = nullptr;  // owned solve buffers, reused by cholmod_solve2
  cholmod_dense* work_y = nullptr;
  cholmod_dense* work_e = nullptr;
  std::vector<int> col_ptr, row_idx;
  int n = 0;
  bool factorized = false;

  Impl() {
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.quick_return_if_not_posdef = 1;
    common.print = 0;  // failures are reported through our return values, not printed
    std::memset(&matrix, 0, sizeof(matrix));
  }

  ~Impl() {
    FreeFactorAndBuffers();
    cholmod_finish(&common);
  }

  void FreeFactorAndBuffers() {
    cholmod_free_factor(&factor, &common);
    cholmod_free_dense(&solution, &common);
    cholmod_free_dense(&work_y, &common);
    cholmod_free_dense(&work_e, &common);
    n = 0;
    factorized = false;
  }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

bool SparseCholesky::IsAvailable() { return true; }

int SparseCholesky::size() const { return impl_->n; }

Status SparseCholesky::Analyze(int n, const int* col_ptr, const int* row_idx) {
  Impl& m = *impl_;
  m.FreeFactorAndBuffers();
  if (Status s = CheckUpperCsc(n, col_ptr, row_idx); !s.ok()) return s;
  const int nnz = col_ptr[n];
  m.col_ptr.assign(col_ptr, col_ptr + n + 1);
  m.row_idx.assign(row_idx, row_idx + nnz);

  cholmod_sparse& a = m.matrix;
  a.nrow = static_cast<size_t>(n);
  a.ncol = static_cast<size_t>(n);
  a.nzmax = static_cast<size_t>(nnz);
  a.p = m.col_ptr.data();
  a.i = m.row_idx.data();
  a.nz = nullptr;
  a.x = nullptr;
  a.z = nullptr;
  a.stype = 1;  // symmetric, upper triangle stored
  a.itype = CHOLMOD_INT;
  a.xtype = CHOLMOD_PATTERN;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 1;
  a.packed = 1;

  m.factor = cholmod_analyze(&a, &m.common);
  if (m.factor == nullptr) {
    const std::string reason = "sparse Cholesky: CHOLMOD analysis failed (status " +
                               std::to_string(m.common.status) + ")";
    return m.common.status == CHOLMOD_OUT_OF_MEMORY ? ResourceExhausted(reason) : Internal(reason);
  }
  m.n = n;
  return Status::Ok();
}

bool SparseCholesky::Factorize(const double* values) {
  Impl& m = *impl_;
  RECONAR_CHECK(m.factor != nullptr) << "SparseCholesky::Factorize needs a successful Analyze";
  m.factorized = false;
  const int nnz = m.col_ptr[m.n];
  for (int k = 0; k < nnz; ++k) {
    if (!std::isfinite(values[k])) return false;
  }
  // CHOLMOD only reads A; the header borrows the caller's values for the duration of the call.
  m.matrix.x = const_cast<double*>(values);
  m.matrix.xtype = CHOLMOD_REAL;
  const int ok = cholmod_factorize(&m.matrix, m.factor, &m.common);
  m.matrix.x = nullptr;
  m.matrix.xtype = CHOLMOD_PATTERN;
  // CHOLMOD_NOT_POSDEF is a warning (ok stays true) with factor->minor < n.
  m.factorized = ok && m.common.status == CHOLMOD_OK && m.factor->minor == m.factor->n;
  return m.factorized;
}

void SparseCholesky::Solve(const double* rhs, double* x) {
  Impl& m = *impl_;
  RECONAR_CHECK(m.factorized) << "SparseCholesky::Solve needs a successful Factorize";
  cholmod_dense b;
  std::memset(&b, 0, sizeof(b));
  b.nrow = static_cast<size_t>(m.n);
  b.ncol = 1;
  b.nzmax = static_cast<size_t>(m.n);
  b.d = static_cast<size_t>(m.n);
  b.x = const_cast<double*>(rhs);  // read only
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  const int ok = cholmod_solve2(CHOLMOD_A, m.factor, &b, nullptr, &m.solution, nullptr, &m.work_y, &m.work_e,
                                &m.common);
  // With a valid factor and sizes, cholmod_solve2 fails only when it cannot allocate its buffers
  // (first call after Analyze); there is no input error to report.
  RECONAR_CHECK(ok && m.solution != nullptr) << "cholmod_solve2 failed, status " << m.common.status;
  std::memcpy(x, m.solution->x, sizeof(double) * static_cast<size_t>(m.n));
}

#else  // !RECONAR_HAVE_CHOLMOD

struct SparseCholesky::Impl {};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

bool SparseCholesky::IsAvailable() { return false; }

int SparseCholesky::size() const { return 0; }

Status SparseCholesky::Analyze(int n, const int* col_ptr, const int* row_idx) {
  if (Status s = CheckUpperCsc(n, col_ptr, row_idx); !s.ok()) return s;
  return Unsupported("sparse Cholesky: reconar was built without SuiteSparse CHOLMOD (RECONAR_WITH_CHOLMOD=OFF)");
}

bool SparseCholesky::Factorize(const double*) {
  RECONAR_CHECK(false) << "SparseCholesky::Factorize needs a successful Analyze (built without CHOLMOD)";
  return false;
}

void SparseCholesky::Solve(const double*, double*) {
  RECONAR_CHECK(false) << "SparseCholesky::Solve needs a successful Factorize (built without CHOLMOD)";
}

#endif  // RECONAR_HAVE_CHOLMOD

}  // namespace reconar
