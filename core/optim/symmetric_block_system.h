#pragma once
// A symmetric positive definite system A x = b whose unknowns come in blocks of varying size,
// refilled with new values of the same pattern at every Levenberg-Marquardt iteration (the
// bundle adjuster's reduced camera system). The upper triangle of A is stored either densely
// (Eigen LLT) or as a sparse matrix holding the coupled blocks only (CHOLMOD's supernodal
// Cholesky, cholmod_ldlt.h; Eigen's SimplicialLDLT when built without CHOLMOD or when CHOLMOD
// refuses the pattern). The sparse storage orders the blocks by approximate minimum degree on
// the block graph (Amestoy, Davis & Duff, SIAM J. Matrix Anal. Appl. 17(4), 1996), the trailing
// `border` blocks (coupled to many others) kept last; CHOLMOD orders the scalar pattern again.
//
// Use: Build once; then per iteration SetZero, Add the blocks, write Rhs, Factorize, Solve, read
// Solution. Blocks are named by their index in Build's numbering. Every buffer is sized by Build:
// SetZero, Add, Factorize and Solve make no allocation of ours (CHOLMOD allocates temporaries of
// its own inside a factorisation).
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "core/optim/cholmod_ldlt.h"

namespace reconar {

class SymmetricBlockSystem {
 public:
  enum class Storage { kDense, kSparse };

  // Where block A(r, c) lives: its entry (a, b) is at
  // values[column_start[column + b] + row_offset + a], of A(c, r) when `transposed`; a diagonal
  // block stores its upper triangle only.
  struct Block {
    int column = 0;
    std::ptrdiff_t row_offset = 0;
    bool transposed = false;
    bool diagonal = false;
  };

  // The number of unknowns, and the share of the upper triangle (diagonal included) that the
  // coupled blocks cover.
  struct Shape {
    int unknowns = 0;
    double fill = 0.0;
  };
  static Shape ShapeOf(const std::vector<int>& block_sizes, const std::vector<std::pair<int, int>>& coupled);

  // block_sizes[k] unknowns in block k; `coupled` lists the pairs of blocks (either order,
  // repeats allowed) whose A block may be non-zero besides the diagonal ones (ShapeOf: without
  // repeats); the last `border`
  // blocks stay last in the sparse ordering.
  void Build(const std::vector<int>& block_sizes, const std::vector<std::pair<int, int>>& coupled, int border,
             Storage storage);

  int size() const { return size_; }
  bool sparse() const { return storage_ == Storage::kSparse; }
  // Stored non-zeros of the upper triangle (the sparse pattern, or size^2 dense).
  std::ptrdiff_t stored_entries() const;

  // Block A(r, c) of a coupled pair, or of a block with itself (r == c).
  Block Find(int r, int c) const {
    int pr = position_[static_cast<size_t>(r)], pc = position_[static_cast<size_t>(c)];
    Block block;
    block.transposed = pr > pc;
    if (block.transposed) std::swap(pr, pc);
    block.diagonal = pr == pc;
    block.column = column_[static_cast<size_t>(pc)];
    block.row_offset = storage_ == Storage::kDense ? column_[static_cast<size_t>(pr)] : SparseRowOffset(r, c, pr, pc);
    return block;
  }

  void SetZero();
  // A(r, c) += m, m the rows(r) x cols(c) block (only its upper triangle is read on the diagonal).
  template <typename M>
  void Add(const Block& block, const Eigen::MatrixBase<M>& m) {
    if (block.transposed) {
      AddStored<1>(block, m.transpose());
    } else {
      AddStored<1>(block, m);
    }
  }
  // A(r, c) -= a b^T: a has rows(r) rows, b has cols(c) rows (fixed sizes).
  template <typename A, typename B>
  void SubtractProduct(const Block& block, const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
    if (block.transposed) {
      SubtractStoredProduct(block, b, a);
    } else {
      SubtractStoredProduct(block, a, b);
    }
  }
  // The stored block -= m, m in the stored orientation (of A(c, r) when `transposed`).
  template <typename M>
  void SubtractStored(const Block& block, const Eigen::MatrixBase<M>& m) {
    AddStored<-1>(block, m);
  }
  // A(k, k)(i, i) = value (a constant unknown: its row and column are otherwise zero).
  void SetDiagonal(int k, int i, double value);

  Eigen::Ref<Eigen::VectorXd> Rhs(int k) { return rhs_.segment(column_[static_cast<size_t>(position_[static_cast<size_t>(k)])], BlockSize(k)); }
  Eigen::Ref<const Eigen::VectorXd> Solution(int k) const {
    return solution_.segment(column_[static_cast<size_t>(position_[static_cast<size_t>(k)])], BlockSize(k));
  }

  // False if A is not positive definite (or not finite).
  bool Factorize();
  void Solve();

 private:
  int BlockSize(int k) const {
    const int p = position_[static_cast<size_t>(k)];
    return column_[static_cast<size_t>(p) + 1] - column_[static_cast<size_t>(p)];
  }
  double* values() { return storage_ == Storage::kSparse ? sparse_.valuePtr() : dense_.data(); }

  std::ptrdiff_t SparseRowOffset(int r, int c, int pr, int pc) const;

  // The stored block -= a b^T.
  template <typename A, typename B>
  void SubtractStoredProduct(const Block& block, const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
    using Product = Eigen::Matrix<double, A::RowsAtCompileTime, B::RowsAtCompileTime>;
    if (storage_ == Storage::kDense && !block.diagonal) {
      DenseBlock<Product>(block).noalias() -= a.lazyProduct(b.transpose());
      return;
    }
    const Product m = a.lazyProduct(b.transpose());
    AddStored<-1>(block, m);
  }

  // A block of the dense storage off the diagonal: one stride.
  template <typename Fixed>
  Eigen::Map<Fixed, Eigen::Unaligned, Eigen::OuterStride<>> DenseBlock(const Block& block) {
    return Eigen::Map<Fixed, Eigen::Unaligned, Eigen::OuterStride<>>(
        dense_.data() + column_start_[static_cast<size_t>(block.column)] + block.row_offset, Eigen::OuterStride<>(size_));
  }

  // The stored block += kSign * m.
  template <int kSign, typename M>
  void AddStored(const Block& block, const Eigen::MatrixBase<M>& m) {
    double* const v = values() + block.row_offset;
    const std::ptrdiff_t* const start = column_start_.data() + block.column;
    if (block.diagonal) {
      for (Eigen::Index b = 0; b < m.cols(); ++b) {
        for (Eigen::Index a = 0; a <= b; ++a) v[start[b] + a] += kSign * m(a, b);
      }
      return;
    }
    if (storage_ == Storage::kDense) {
      auto stored = DenseBlock<Eigen::Matrix<double, M::RowsAtCompileTime, M::ColsAtCompileTime>>(block);
      if (kSign > 0) {
        stored += m;
      } else {
        stored -= m;
      }
      return;
    }
    for (Eigen::Index b = 0; b < m.cols(); ++b) {
      Eigen::Map<Eigen::Matrix<double, M::RowsAtCompileTime, 1>> column(v + start[b], m.rows());
      if (kSign > 0) {
        column += m.col(b);
      } else {
        column -= m.col(b);
      }
    }
  }

  // SimplicialLDLT whose numeric factorisation reads our upper-triangular, already ordered matrix
  // in place: Eigen 3.4's factorize() builds a temporary SparseMatrix header (a heap allocation)
  // on every call even when it then uses the input directly. Its work vectors are on the stack up
  // to EIGEN_STACK_ALLOCATION_LIMIT (128 KiB: about 16000 unknowns), on the heap beyond.
  class InPlaceLdlt : public Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper,
                                                   Eigen::NaturalOrdering<int>> {
   public:
    void FactorizeInPlace(const Eigen::SparseMatrix<double>& upper) {
      this->template factorize_preordered<true>(upper);
    }
  };

  Storage storage_ = Storage::kDense;
  int size_ = 0;
  std::vector<int> position_;                // block -> its place in the ordering
  std::vector<int> column_;                  // place -> first unknown; one past the end last
  std::vector<std::ptrdiff_t> column_start_; // unknown -> offset of its column's first stored entry
  // Sparse: per place, the places of the blocks stored above it in its columns and their row
  // offsets (place_rows_[place_row_offsets_[c] ..]), sorted.
  std::vector<int> place_row_offsets_;
  std::vector<int> place_rows_;
  std::vector<std::ptrdiff_t> place_row_offset_in_column_;
  Eigen::MatrixXd dense_;
  std::optional<Eigen::LLT<Eigen::MatrixXd, Eigen::Upper>> dense_llt_;
  Eigen::SparseMatrix<double> sparse_;
  SparseCholesky cholmod_;
  bool use_cholmod_ = false;
  InPlaceLdlt ldlt_;
  Eigen::VectorXd rhs_, solution_;
};

}  // namespace reconar
