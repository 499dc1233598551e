#include "tests/core/geometry/malloc_counter.h"

#include <Eigen/Core>
#include <atomic>
#include <cstddef>

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_mallocs{0};

void Count() {
  if (g_counting.load(std::memory_order_relaxed)) g_mallocs.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

// The linker's --wrap: calls to malloc reach __wrap_malloc, __real_malloc is the C library's.
extern "C" {
void* __real_malloc(std::size_t size);
void* __real_calloc(std::size_t count, std::size_t size);
void* __real_realloc(void* p, std::size_t size);

void* __wrap_malloc(std::size_t size) {
  Count();
  return __real_malloc(size);
}
void* __wrap_calloc(std::size_t count, std::size_t size) {
  Count();
  return __real_calloc(count, size);
}
void* __wrap_realloc(void* p, std::size_t size) {
  Count();
  return __real_realloc(p, size);
}
}

namespace reconar {
namespace testing {

MallocCountScope::MallocCountScope() {
  g_mallocs = 0;
  g_counting = true;
}
MallocCountScope::~MallocCountScope() { g_counting = false; }
long MallocCountScope::mallocs() const { return g_mallocs.load(); }

void AllocateEigenHeapMatrix() {
  Eigen::MatrixXd heap(20, 20);
  heap.setZero();
  volatile double sink = heap.sum();
  (void)sink;
}

}  // namespace testing
}  // namespace reconar
