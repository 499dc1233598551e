#include "core/base/arena.h"

#include <cstdlib>

#include "core/base/check.h"

namespace reconar {

void Arena::FreeDeleter::operator()(void* p) const { std::free(p); }

Arena::Arena(size_t capacity_bytes) : capacity_(capacity_bytes) {
  if (capacity_ > 0) {
    const size_t rounded = (capacity_ + kDefaultAlignment - 1) / kDefaultAlignment * kDefaultAlignment;
    block_.reset(static_cast<uint8_t*>(std::aligned_alloc(kDefaultAlignment, rounded)));
    if (!block_) capacity_ = 0;  // every Allocate will then fail and be counted
  }
}

void* Arena::Allocate(size_t bytes, size_t alignment) {
  RECONAR_CHECK(alignment != 0 && (alignment & (alignment - 1)) == 0) << "alignment " << alignment;
  const uintptr_t base = reinterpret_cast<uintptr_t>(block_.get());
  const uintptr_t current = base + used_;
  const uintptr_t aligned = (current + alignment - 1) & ~(uintptr_t(alignment) - 1);
  const size_t padding = aligned - current;
  if (bytes > capacity_ || used_ + padding > capacity_ - bytes) {
    ++failed_allocations_;
    return nullptr;
  }
  used_ += padding + bytes;
  wasted_ += padding;
  if (used_ > peak_used_) peak_used_ = used_;
  return reinterpret_cast<void*>(aligned);
}

void Arena::ResetTo(size_t mark) {
  RECONAR_CHECK(mark <= used_) << "arena reset to " << mark << " beyond used " << used_;
  used_ = mark;
}

}  // namespace reconar
