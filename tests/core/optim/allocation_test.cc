// The bundle adjuster sizes all its memory before the iteration loop: the number of heap
// allocations made by a solve does not depend on the number of iterations. Counted by
// interposing malloc/calloc/realloc in this executable (glibc; skipped under sanitizers, which
// own malloc). CHOLMOD's numeric factorisation allocates temporaries of its own on every call
// (cholmod_ldlt.h); those are not counted: cholmod_factorize is interposed too and pauses the
// count while the real one runs.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdlib>
#include <random>

#include "core/optim/bundle_adjuster.h"
#include "tests/core/optim/synthetic_bal.h"

#if defined(__SANITIZE_ADDRESS__)
#define RECONAR_OPTIM_COUNT_MALLOC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RECONAR_OPTIM_COUNT_MALLOC 0
#endif
#endif
#ifndef RECONAR_OPTIM_COUNT_MALLOC
#if defined(__GLIBC__)
#define RECONAR_OPTIM_COUNT_MALLOC 1
#else
#define RECONAR_OPTIM_COUNT_MALLOC 0
#endif
#endif

#if RECONAR_OPTIM_COUNT_MALLOC
namespace {
long g_allocations = 0;  // single-threaded use only (num_threads = 1)
bool g_in_cholmod = false;
long g_cholmod_factorizations = 0;
}  // namespace
extern "C" {
void* __libc_malloc(size_t size);
void* __libc_calloc(size_t n, size_t size);
void* __libc_realloc(void* p, size_t size);
void* malloc(size_t size) {
  g_allocations += g_in_cholmod ? 0 : 1;
  return __libc_malloc(size);
}
void* calloc(size_t n, size_t size) {
  g_allocations += g_in_cholmod ? 0 : 1;
  return __libc_calloc(n, size);
}
void* realloc(void* p, size_t size) {
  g_allocations += g_in_cholmod ? 0 : 1;
  return __libc_realloc(p, size);
}
#ifdef RECONAR_HAVE_CHOLMOD
// CHOLMOD's own types stay out of this file: the three arguments are pointers.
int cholmod_factorize(void* a, void* factor, void* common) {
  using Factorize = int (*)(void*, void*, void*);
  static const auto real = reinterpret_cast<Factorize>(dlsym(RTLD_NEXT, "cholmod_factorize"));
  ++g_cholmod_factorizations;
  g_in_cholmod = true;
  const int ok = real(a, factor, common);
  g_in_cholmod = false;
  return ok;
}
#endif
}  // extern "C"
#endif

namespace reconar {
namespace {

#if RECONAR_OPTIM_COUNT_MALLOC
long AllocationsForIterations(int iterations, BundleAdjustmentOptions::LinearSolver solver, bool shared) {
  BalProblem problem = testing::MakeSyntheticBal(8, 120, 3);
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.5);
  for (BalObservation& o : problem.observations) {
    o.x += noise(rng);
    o.y += noise(rng);
  }
  testing::PerturbBal(&problem, 5, 0);
  BundleAdjustmentOptions options;
  options.max_iterations = iterations;
  options.function_tolerance = 0.0;
  options.gradient_tolerance = 0.0;
  options.parameter_tolerance = 0.0;
  options.linear_solver = solver;
  BundleAdjustmentConstancy constancy;
  constancy.constant_cameras.assign(8, 0);
  constancy.constant_cameras[0] = 1;
  if (shared) constancy.intrinsics_group.assign(8, 0);
  const long before = g_allocations;
  Result<BundleAdjustmentSummary> r = SolveBundleAdjustment(options, constancy, &problem);
  const long after = g_allocations;
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r->iterations, iterations);
  return after - before;
}
#endif

TEST(BundleAdjusterAllocationTest, NoAllocationPerIteration) {
#if RECONAR_OPTIM_COUNT_MALLOC
  for (auto solver : {BundleAdjustmentOptions::LinearSolver::kDenseCholesky,
                      BundleAdjustmentOptions::LinearSolver::kSparseCholesky}) {
    for (bool shared : {false, true}) {
      const long factorizations_before = g_cholmod_factorizations;
      const long two = AllocationsForIterations(2, solver, shared);
      const long twelve = AllocationsForIterations(12, solver, shared);
      EXPECT_GT(two, 0);  // the counter works (setup allocates)
      EXPECT_EQ(two, twelve) << "solver " << static_cast<int>(solver) << (shared ? ", shared intrinsics" : "");
      const long factorizations = g_cholmod_factorizations - factorizations_before;
#ifdef RECONAR_HAVE_CHOLMOD
      // The sparse solver factorises with CHOLMOD (not a silent fallback), once per iteration.
      const bool sparse = solver == BundleAdjustmentOptions::LinearSolver::kSparseCholesky;
      EXPECT_EQ(factorizations, sparse ? 14 : 0);
#else
      EXPECT_EQ(factorizations, 0);
#endif
    }
  }
#else
  GTEST_SKIP() << "malloc interposition unavailable (sanitizer or non-glibc)";
#endif
}

}  // namespace
}  // namespace reconar
