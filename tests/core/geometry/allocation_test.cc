// The minimal solvers and residual functions must not touch the heap (they run thousands of
// times per image pair). This executable links reconar_geometry as the product builds it and counts
// every malloc (Eigen's heap allocations included) through the linker's --wrap
// (malloc_counter.h) and every operator new (tests/support/allocation_counter.h).
#include <array>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "core/geometry/essential_five_point.h"
#include "core/geometry/fundamental_eight_point.h"
#include "core/geometry/fundamental_seven_point.h"
#include "core/geometry/homography_four_point.h"
#include "core/geometry/synthetic_scene.h"
#include "tests/core/geometry/malloc_counter.h"
#include "tests/support/allocation_counter.h"

namespace reconar {
namespace {

using testing::MallocCountScope;
using testing::NoAllocationScope;

template <typename Estimator>
void ExpectNoAllocation(const std::vector<Correspondence>& samples) {
  std::array<typename Estimator::Model, Estimator::kMaxModels> models;
  std::array<double, Estimator::kMinSamples> residuals;
  int num_models = 0;
  long allocations = 0;
  {
    NoAllocationScope scope;
    MallocCountScope mallocs;
    for (int repeat = 0; repeat < 3; ++repeat) {
      num_models = Estimator::Estimate(samples.data(), Estimator::kMinSamples, &models);
      Estimator::Residuals(samples.data(), Estimator::kMinSamples, models[0], residuals.data());
    }
    allocations = scope.allocations() + mallocs.mallocs();
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

// The library is compiled without the Eigen guard: its heap use is seen by the malloc count.
TEST(MinimalSolverAllocation, MallocCountSeesLibraryCode) {
  MallocCountScope mallocs;
  testing::AllocateEigenHeapMatrix();
  EXPECT_GE(mallocs.mallocs(), 1);
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
