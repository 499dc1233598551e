// The counting global operator new / delete of allocation_counter.h. Built as an object library
// so that every linking test executable gets the replacement (an archive member would only be
// pulled in by chance).
#include <atomic>
#include <cstdlib>
#include <new>

#include "tests/support/allocation_counter.h"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};

void* CountedAllocateNoThrow(std::size_t size) noexcept {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}

void* CountedAllocate(std::size_t size) {
  if (void* p = CountedAllocateNoThrow(size)) return p;
  throw std::bad_alloc();
}

void* CountedAllocateAligned(std::size_t size, std::align_val_t alignment) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t align = static_cast<std::size_t>(alignment);
  const std::size_t rounded = (size + align - 1) / align * align;
  if (void* p = std::aligned_alloc(align, rounded == 0 ? align : rounded)) return p;
  throw std::bad_alloc();
}
}  // namespace

// Every replaceable form is replaced, so that no allocation escapes the count and no block is
// freed by a different allocator than the one that made it (ASan's alloc-dealloc check).

void* operator new(std::size_t size) { return CountedAllocate(size); }
void* operator new[](std::size_t size) { return CountedAllocate(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return CountedAllocateNoThrow(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return CountedAllocateNoThrow(size); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void* operator new(std::size_t size, std::align_val_t alignment) { return CountedAllocateAligned(size, alignment); }
void* operator new[](std::size_t size, std::align_val_t alignment) { return CountedAllocateAligned(size, alignment); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace reconar {
namespace testing {

void StartCountingAllocations() {
  g_allocations = 0;
  g_counting = true;
}

void StopCountingAllocations() { g_counting = false; }

long CountedAllocations() { return g_allocations.load(); }

}  // namespace testing
}  // namespace reconar
