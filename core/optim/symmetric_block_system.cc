#include "core/optim/symmetric_block_system.h"

#include <algorithm>

#include "core/base/check.h"

namespace reconar {

SymmetricBlockSystem::Shape SymmetricBlockSystem::ShapeOf(const std::vector<int>& block_sizes,
                                                           const std::vector<std::pair<int, int>>& coupled) {
  Shape shape;
  double stored = 0.0;
  for (int size : block_sizes) {
    shape.unknowns += size;
    stored += 0.5 * size * (size + 1.0);
  }
  for (const auto& [a, b] : coupled) {
    if (a != b) stored += static_cast<double>(block_sizes[static_cast<size_t>(a)]) * block_sizes[static_cast<size_t>(b)];
  }
  if (shape.unknowns > 0) shape.fill = stored / (0.5 * shape.unknowns * (shape.unknowns + 1.0));
  return shape;
}

void SymmetricBlockSystem::Build(const std::vector<int>& block_sizes, const std::vector<std::pair<int, int>>& coupled,
                                 int border, Storage storage) {
  storage_ = storage;
  const auto num_blocks = static_cast<int>(block_sizes.size());
  const int ordered = num_blocks - border;
  position_.resize(block_sizes.size());
  for (int k = 0; k < num_blocks; ++k) position_[static_cast<size_t>(k)] = k;
  if (storage == Storage::kSparse && ordered > 1) {
    std::vector<Eigen::Triplet<int>> triplets;
    for (int k = 0; k < ordered; ++k) triplets.emplace_back(k, k, 1);
    for (const auto& [a, b] : coupled) {
      if (a >= ordered || b >= ordered) continue;
      triplets.emplace_back(a, b, 1);
      triplets.emplace_back(b, a, 1);
    }
    Eigen::SparseMatrix<int> graph(ordered, ordered);
    graph.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> pinv;
    Eigen::AMDOrdering<int> amd;
    amd(graph, pinv);  // pinv.indices()[place] = block
    if (pinv.size() == ordered) {
      for (int p = 0; p < ordered; ++p) position_[static_cast<size_t>(pinv.indices()[p])] = p;
    }
  }
  std::vector<int> size_at(block_sizes.size());
  for (int k = 0; k < num_blocks; ++k) {
    size_at[static_cast<size_t>(position_[static_cast<size_t>(k)])] = block_sizes[static_cast<size_t>(k)];
  }
  column_.assign(block_sizes.size() + 1, 0);
  for (int p = 0; p < num_blocks; ++p) column_[static_cast<size_t>(p) + 1] = column_[static_cast<size_t>(p)] + size_at[static_cast<size_t>(p)];
  size_ = column_.back();
  rhs_.setZero(size_);
  solution_.setZero(size_);
  column_start_.resize(static_cast<size_t>(size_));
  if (storage == Storage::kDense) {
    for (int j = 0; j < size_; ++j) column_start_[static_cast<size_t>(j)] = static_cast<std::ptrdiff_t>(j) * size_;
    dense_.setZero(size_, size_);
    // Constructed in place: Eigen's LLT leaves its status member unset until compute(), so
    // copying a fresh one reads an indeterminate value (UBSan reports it).
    dense_llt_.emplace(size_);
    return;
  }

  // Per place, the places stored above it (and itself, last), sorted.
  std::vector<std::vector<int>> rows_of(block_sizes.size());
  for (int p = 0; p < num_blocks; ++p) rows_of[static_cast<size_t>(p)].push_back(p);
  for (const auto& [a, b] : coupled) {
    const int pa = position_[static_cast<size_t>(a)], pb = position_[static_cast<size_t>(b)];
    if (pa != pb) rows_of[static_cast<size_t>(std::max(pa, pb))].push_back(std::min(pa, pb));
  }
  place_row_offsets_.assign(block_sizes.size() + 1, 0);
  place_rows_.clear();
  place_row_offset_in_column_.clear();
  Eigen::VectorXi column_sizes(size_);
  for (int p = 0; p < num_blocks; ++p) {
    std::vector<int>& rows = rows_of[static_cast<size_t>(p)];
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    std::ptrdiff_t offset = 0;
    for (int r : rows) {
      place_rows_.push_back(r);
      place_row_offset_in_column_.push_back(offset);
      offset += size_at[static_cast<size_t>(r)];
    }
    place_row_offsets_[static_cast<size_t>(p) + 1] = static_cast<int>(place_rows_.size());
    // Column b of the place holds the blocks above in full and the diagonal block's rows 0..b.
    const std::ptrdiff_t above = offset - size_at[static_cast<size_t>(p)];
    for (int b = 0; b < size_at[static_cast<size_t>(p)]; ++b) {
      column_sizes[column_[static_cast<size_t>(p)] + b] = static_cast<int>(above + b + 1);
    }
  }
  sparse_.resize(size_, size_);
  sparse_.reserve(column_sizes);
  for (int p = 0; p < num_blocks; ++p) {
    const std::vector<int>& rows = rows_of[static_cast<size_t>(p)];
    for (int b = 0; b < size_at[static_cast<size_t>(p)]; ++b) {
      const int j = column_[static_cast<size_t>(p)] + b;
      for (int r : rows) {
        const int first = column_[static_cast<size_t>(r)];
        const int last = r == p ? j + 1 : column_[static_cast<size_t>(r) + 1];
        for (int i = first; i < last; ++i) sparse_.insert(i, j) = 0.0;
      }
    }
  }
  sparse_.makeCompressed();
  for (int j = 0; j < size_; ++j) column_start_[static_cast<size_t>(j)] = sparse_.outerIndexPtr()[j];
  use_cholmod_ = SparseCholesky::IsAvailable() &&
                 cholmod_.Analyze(size_, sparse_.outerIndexPtr(), sparse_.innerIndexPtr()).ok();
  if (!use_cholmod_) ldlt_.analyzePattern(sparse_);
}

std::ptrdiff_t SymmetricBlockSystem::stored_entries() const {
  return storage_ == Storage::kSparse ? sparse_.nonZeros() : static_cast<std::ptrdiff_t>(size_) * size_;
}

std::ptrdiff_t SymmetricBlockSystem::SparseRowOffset(int r, int c, int pr, int pc) const {
  const auto first = place_rows_.begin() + place_row_offsets_[static_cast<size_t>(pc)];
  const auto last = place_rows_.begin() + place_row_offsets_[static_cast<size_t>(pc) + 1];
  const auto it = std::lower_bound(first, last, pr);
  RECONAR_CHECK(it != last && *it == pr) << "SymmetricBlockSystem::Find: blocks " << r << " and " << c
                                        << " are not coupled";
  return place_row_offset_in_column_[static_cast<size_t>(it - place_rows_.begin())];
}

void SymmetricBlockSystem::SetZero() {
  if (storage_ == Storage::kSparse) {
    std::fill(sparse_.valuePtr(), sparse_.valuePtr() + sparse_.nonZeros(), 0.0);
  } else {
    dense_.setZero();
  }
  rhs_.setZero();
}

void SymmetricBlockSystem::SetDiagonal(int k, int i, double value) {
  const Block block = Find(k, k);
  values()[column_start_[static_cast<size_t>(block.column + i)] + block.row_offset + i] = value;
}

bool SymmetricBlockSystem::Factorize() {
  if (storage_ == Storage::kDense) {
    dense_llt_->compute(dense_);  // reads the upper triangle only
    return dense_llt_->info() == Eigen::Success;
  }
  if (use_cholmod_) return cholmod_.Factorize(sparse_.valuePtr());
  ldlt_.FactorizeInPlace(sparse_);  // reads the upper triangle only
  return ldlt_.info() == Eigen::Success;
}

void SymmetricBlockSystem::Solve() {
  if (storage_ == Storage::kDense) {
    solution_ = rhs_;
    dense_llt_->solveInPlace(solution_);
  } else if (use_cholmod_) {
    cholmod_.Solve(rhs_.data(), solution_.data());
  } else {
    solution_ = ldlt_.solve(rhs_);
  }
}

}  // namespace reconar
