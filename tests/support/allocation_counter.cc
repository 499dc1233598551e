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

void* CountedAllocate(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t size) { return CountedAllocate(size); }
void* operator new[](std::size_t size) { return CountedAllocate(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

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
