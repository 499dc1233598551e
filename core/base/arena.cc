#include "core/base/arena.h"

#include <sys/mman.h>

#include <cstdlib>

#include "core/base/check.h"

namespace reconar {

void Arena::FreeDeleter::operator()(void* p) const { std::free(p); }

namespace {
// Large arenas hold image planes walked by many row streams at once; 2 MiB pages keep them
// in the TLB and make first touch one fault per 2 MiB instead of per 4 KiB.
constexpr size_t kHugePage = size_t{2} << 20;
}  // namespace

Arena::Arena(size_t capacity_bytes) : capacity_(capacity_bytes) {
  if (capacity_ > 0) {
    const size_t alignment = capacity_ >= 2 * kHugePage ? kHugePage : kDefaultAlignment;
    const size_t rounded = (capacity_ + alignment - 1) / alignment * alignment;
    block_.reset(static_cast<uint8_t*>(std::aligned_alloc(alignment, rounded)));
    if (!block_) {
      capacity_ = 0;  // every Allocate will then fail and be counted
    } else if (alignment == kHugePage) {
      ::madvise(block_.get(), rounded, MADV_HUGEPAGE);  // a hint; failure only costs speed
    }
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
