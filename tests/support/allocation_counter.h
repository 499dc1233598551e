#pragma once
// Heap-allocation checks for code that must not allocate (minimal solvers, pose refinement). A
// test executable that links reconar_allocation_counter (tests/support/CMakeLists.txt) has the
// global operator new / delete replaced by counting versions (allocation_counter.cc); its test
// sources are compiled with EIGEN_RUNTIME_NO_MALLOC (and assertions on), so Eigen heap
// allocation aborts while a NoAllocationScope is alive.
#include <Eigen/Core>

#ifndef EIGEN_RUNTIME_NO_MALLOC
#error "tests using allocation_counter.h must be compiled with EIGEN_RUNTIME_NO_MALLOC"
#endif

namespace reconar {
namespace testing {

// Resets the operator-new count and starts counting; stops counting.
void StartCountingAllocations();
void StopCountingAllocations();
// operator-new calls since StartCountingAllocations (while counting).
long CountedAllocations();

// Counts operator-new calls and forbids Eigen heap allocation within its lifetime.
class NoAllocationScope {
 public:
  NoAllocationScope() {
    Eigen::internal::set_is_malloc_allowed(false);
    StartCountingAllocations();
  }
  ~NoAllocationScope() {
    StopCountingAllocations();
    Eigen::internal::set_is_malloc_allowed(true);
  }
  NoAllocationScope(const NoAllocationScope&) = delete;
  NoAllocationScope& operator=(const NoAllocationScope&) = delete;

  long allocations() const { return CountedAllocations(); }
};

}  // namespace testing
}  // namespace reconar
