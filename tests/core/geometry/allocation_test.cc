// The minimal solvers and residual functions must not touch the heap (they run thousands of
// times per image pair). This executable compiles the estimator sources itself with
// EIGEN_RUNTIME_NO_MALLOC and assertions on, so any Eigen heap allocation aborts, and it
// replaces the global operator new to count every other allocation.
#include <array>
#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "core/geometry/essential_five_point.h"
#include "core/geometry/fundamental_eight_point.h"
#include "core/geometry/fundamental_seven_point.h"
#include "core/geometry/homography_four_point.h"
#include "core/geometry/synthetic_scene.h"

#ifndef EIGEN_RUNTIME_NO_MALLOC
#error "allocation_test.cc must be compiled with EIGEN_RUNTIME_NO_MALLOC"
#endif

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
namespace {

// Counts operator-new calls and forbids Eigen heap allocation within its lifetime.
class NoAllocationScope {
 public:
  NoAllocationScope() {
    g_allocations = 0;
    Eigen::internal::set_is_malloc_allowed(false);
    g_counting = true;
  }
  ~NoAllocationScope() {
    g_counting = false;
    Eigen::internal::set_is_malloc_allowed(true);
  }
  long allocations() const { return g_allocations.load(); }
};

template <typename Estimator>
void ExpectNoAllocation(const std::vector<Correspondence>& samples) {
  std::array<typename Estimator::Model, Estimator::kMaxModels> models;
  std::array<double, Estimator::kMinSamples> residuals;
  int num_models = 0;
  long allocations = 0;
  {
    NoAllocationScope scope;
    for (int repeat = 0; repeat < 3; ++repeat) {
      num_models = Estimator::Estimate(samples.data(), Estimator::kMinSamples, &models);
      Estimator::Residuals(samples.data(), Estimator::kMinSamples, models[0], residuals.data());
    }
    allocations = scope.allocations();
  }
  EXPECT_GE(num_models, 1);
  EXPECT_EQ(allocations, 0);
}

SyntheticTwoViewScene Scene(SyntheticSceneOptions::Kind kind) {
  SyntheticSceneOptions options;
  options.kind = kind;
  options.num_points = 20;
  return MakeSyntheticTwoViewScene(options).value();
}

TEST(MinimalSolverAllocation, EigenHeapGuardIsActive) {
  EXPECT_DEATH(
      {
        NoAllocationScope scope;
        Eigen::MatrixXd heap(20, 20);
        heap.setZero();
      },
      "heap allocation is forbidden");
}

TEST(MinimalSolverAllocation, FundamentalEightPoint) {
  ExpectNoAllocation<FundamentalEightPoint>(Scene(SyntheticSceneOptions::Kind::kGeneral).Correspondences());
}

TEST(MinimalSolverAllocation, FundamentalSevenPoint) {
  ExpectNoAllocation<FundamentalSevenPoint>(Scene(SyntheticSceneOptions::Kind::kGeneral).Correspondences());
}

TEST(MinimalSolverAllocation, EssentialFivePoint) {
  ExpectNoAllocation<EssentialFivePoint>(Scene(SyntheticSceneOptions::Kind::kGeneral).Correspondences(true));
}

TEST(MinimalSolverAllocation, HomographyFourPoint) {
  ExpectNoAllocation<HomographyFourPoint>(Scene(SyntheticSceneOptions::Kind::kPlanar).Correspondences());
}

}  // namespace
}  // namespace reconar
