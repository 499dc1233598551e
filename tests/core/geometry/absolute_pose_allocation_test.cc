// The pose refinement runs after every registration and bundle adjustment, and the P3P / DLT
// solvers thousands of times per image: none of them may touch the heap. As allocation_test.cc, it
// counts every malloc (malloc_counter.h) and operator new (tests/support/allocation_counter.h)
// made while they run, in reconar_geometry as the product builds it.
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/geometry/absolute_pose.h"
#include "tests/core/geometry/malloc_counter.h"
#include "tests/support/allocation_counter.h"

namespace reconar {
namespace {

using testing::MallocCountScope;
using testing::NoAllocationScope;

// 100 points on a grid of depths in front of a distorted camera, noise-free pixels.
struct Data {
  RadialCamera camera{750.0, 320.0, 240.0, -0.1, 0.02};
  Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::Vector3d t = Eigen::Vector3d(0.3, -0.2, 1.0);
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  std::vector<PoseCorrespondence> normalised;
  std::vector<int> indices;

  Data() {
    for (int i = 0; i < 100; ++i) {
      const Eigen::Vector2d p(-0.4 + 0.08 * (i % 10), -0.3 + 0.06 * (i / 10));
      const Eigen::Vector3d X_cam = (3.0 + 0.37 * (i % 7)) * p.homogeneous();
      world.push_back(R.transpose() * (X_cam - t));
      pixels.push_back(camera.PixelFromNormalised(p));
      normalised.push_back(PoseCorrespondence{p, world.back()});
      indices.push_back(i);
    }
  }
};

TEST(AbsolutePoseAllocation, EigenHeapGuardIsActive) {
  EXPECT_DEATH(
      {
        NoAllocationScope scope;
        Eigen::MatrixXd heap(20, 20);
        heap.setZero();
      },
      "heap allocation is forbidden");
}

// The library is compiled without the Eigen guard: its heap use is seen by the malloc count.
TEST(AbsolutePoseAllocation, MallocCountSeesLibraryCode) {
  MallocCountScope mallocs;
  testing::AllocateEigenHeapMatrix();
  EXPECT_GE(mallocs.mallocs(), 1);
}

TEST(AbsolutePoseAllocation, RefinementOfPoseAndFocal) {
  const Data data;
  for (bool refine_focal : {false, true}) {
    SCOPED_TRACE(refine_focal);
    PoseRefinementOptions options;
    options.refine_focal = refine_focal;
    RadialCamera camera = data.camera;
    camera.focal *= refine_focal ? 1.05 : 1.0;
    Eigen::Matrix3d R = Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitY()) * data.R;
    Eigen::Vector3d t = data.t + Eigen::Vector3d(0.05, 0.0, -0.05);
    NormalLmSummary summary;
    long allocations = 0;
    {
      NoAllocationScope scope;
    MallocCountScope mallocs;
      summary = RefineAbsolutePoseInPlace(data.pixels.data(), data.world.data(), data.indices.data(),
                                          static_cast<int>(data.indices.size()), options, &camera, &R, &t);
      allocations = scope.allocations() + mallocs.mallocs();
    }
    EXPECT_EQ(allocations, 0);
    EXPECT_TRUE(summary.converged());
    EXPECT_GT(summary.iterations, 2);
    EXPECT_LT((R - data.R).norm(), 1e-9);
    EXPECT_LT((t - data.t).norm(), 1e-9);
  }
}

TEST(AbsolutePoseAllocation, MinimalAndLeastSquaresSolvers) {
  const Data data;
  std::array<Matrix34d, P3PEstimator::kMaxModels> p3p_models;
  std::array<Matrix34d, DltPoseEstimator::kMaxModels> dlt_models;
  std::array<double, 100> residuals;
  // Spread over the grid (rows of the grid are coplanar with the camera centre).
  const std::array<PoseCorrespondence, 6> sample = {data.normalised[0], data.normalised[47], data.normalised[93],
                                                    data.normalised[15], data.normalised[62], data.normalised[38]};
  int num_p3p = 0, num_dlt = 0, num_least_squares = 0;
  long allocations = 0;
  {
    NoAllocationScope scope;
    MallocCountScope mallocs;
    num_p3p = P3PEstimator::Estimate(sample.data(), 3, &p3p_models);
    P3PEstimator::Residuals(data.normalised.data(), 100, p3p_models[0], residuals.data());
    num_dlt = DltPoseEstimator::Estimate(sample.data(), 6, &dlt_models);
    num_least_squares = DltPoseEstimator::Estimate(data.normalised.data(), 100, &dlt_models);
    DltPoseEstimator::Residuals(data.normalised.data(), 100, dlt_models[0], residuals.data());
    allocations = scope.allocations() + mallocs.mallocs();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_GE(num_p3p, 1);
  EXPECT_EQ(num_dlt, 1);
  EXPECT_EQ(num_least_squares, 1);
}

}  // namespace
}  // namespace reconar
