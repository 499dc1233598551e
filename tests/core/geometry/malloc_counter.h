#pragma once
// Counts malloc / calloc / realloc calls from every object of the test executable, including the
// reconar libraries it links as they are built for the product (compiled once, without
// EIGEN_RUNTIME_NO_MALLOC): the executable is linked with -Wl,--wrap=malloc,--wrap=calloc,
// --wrap=realloc (tests/core/geometry/CMakeLists.txt), which sends those calls through the counting
// __wrap_ functions of malloc_counter.cc. Eigen's heap allocations are mallocs, so a solver in the
// library that allocated would be counted here; operator new is counted by allocation_counter.h.
namespace reconar {
namespace testing {

// Counts while alive.
class MallocCountScope {
 public:
  MallocCountScope();
  ~MallocCountScope();
  MallocCountScope(const MallocCountScope&) = delete;
  MallocCountScope& operator=(const MallocCountScope&) = delete;

  long mallocs() const;
};

// Makes one Eigen heap allocation in this archive member (compiled without
// EIGEN_RUNTIME_NO_MALLOC), so a test can check that library code is counted.
void AllocateEigenHeapMatrix();

}  // namespace testing
}  // namespace reconar
