// Point anchors (bal_problem.h): printed squares as frame blocks whose corners are anchored to
// them, the squares' edge one shared unknown. Against what the anchors mean: after a solve the
// anchored corners form squares of one edge, the edge and the cost do not depend on the problem's
// scale (an anchor whose weight did not scale with the problem let a solve shrink the whole model
// to nothing), and bad anchors are refused.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "core/math/rotation.h"
#include "core/optim/bundle_adjuster.h"
#include "core/optim/radial_camera_model.h"
#include "tests/core/optim/synthetic_bal.h"

namespace reconar {
namespace {

constexpr double kUnits[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
constexpr int kCameras = 8;

struct SquaresProblem {
  RadialProblem problem;
  BundleAdjustmentConstancy constancy;
  std::vector<std::array<int, 4>> squares;  // point ids
};

// The synthetic ring of cameras (one group of intrinsics) with two squares of edge 0.4 in the
// cloud, their corners observed with noise; the squares' frames start at the truth's, their
// corners moved off by 3 % of the edge and the edge started 10 % long.
SquaresProblem MakeSquares(double noise_px) {
  SquaresProblem s;
  std::vector<int> groups(kCameras, 0);
  s.problem = testing::MakeSyntheticRadial(groups, 40, noise_px, 3);
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  const double edge = 0.4;
  const Eigen::Matrix3d rotations[2] = {Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix(),
                                        Eigen::AngleAxisd(-0.5, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix()};
  const Eigen::Vector3d centres[2] = {Eigen::Vector3d(-0.4, 0.2, 0.1), Eigen::Vector3d(0.5, -0.3, -0.2)};
  for (int q = 0; q < 2; ++q) {
    std::array<int, 4> ids;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d corner = rotations[q] * (edge * Eigen::Vector3d(kUnits[k][0], kUnits[k][1], 0)) + centres[q];
      const int j = s.problem.num_points();
      ids[static_cast<size_t>(k)] = j;
      for (int i = 0; i < kCameras; ++i) {
        double uv[2];
        ProjectRadial(s.problem.camera(i), corner.data(), uv, nullptr, nullptr);
        s.problem.observations.push_back({i, j, uv[0] + noise_px * n(rng), uv[1] + noise_px * n(rng)});
      }
      const Eigen::Vector3d start = corner + 0.03 * edge * Eigen::Vector3d(n(rng), n(rng), n(rng));
      s.problem.points.insert(s.problem.points.end(), start.data(), start.data() + 3);
    }
    s.squares.push_back(ids);
    const Eigen::Matrix3d frame_rotation = rotations[q].transpose();
    const Eigen::Vector3d w = AngleAxisFromRotation(frame_rotation);
    const Eigen::Vector3d t = -frame_rotation * centres[q];
    const double block[12] = {w.x(), w.y(), w.z(), t.x(), t.y(), t.z(), 1.1 * edge, 0, 0, 0, 0, 1};
    const int frame = s.problem.num_cameras();
    s.problem.cameras.insert(s.problem.cameras.end(), block, block + 12);
    for (int k = 0; k < 4; ++k) {
      PointAnchor anchor;
      anchor.frame = frame;
      anchor.point = ids[static_cast<size_t>(k)];
      anchor.local[0] = kUnits[k][0];
      anchor.local[1] = kUnits[k][1];
      anchor.weight = 1.0 / 0.001;
      s.problem.point_anchors.push_back(anchor);
    }
  }
  s.constancy.intrinsics_group = groups;
  s.constancy.intrinsics_group.push_back(1);  // the squares' shared edge
  s.constancy.intrinsics_group.push_back(1);
  s.constancy.constant_camera_parameters = {9, 10, 11};
  return s;
}

Eigen::Vector3d Point(const RadialProblem& p, int j) { return Eigen::Vector3d(p.point(j)); }

TEST(PointAnchorTest, AnchoredCornersBecomeSquaresOfOneEdge) {
  SquaresProblem s = MakeSquares(0.3);
  BundleAdjustmentOptions options;
  const auto summary = SolveBundleAdjustment(options, s.constancy, &s.problem);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_NE(summary->termination, BundleAdjustmentSummary::Termination::kNumericFailure);
  EXPECT_LT(summary->final_cost, summary->initial_cost);
  const double edge = s.problem.camera(kCameras)[6];
  EXPECT_EQ(edge, s.problem.camera(kCameras + 1)[6]);  // one unknown for both squares
  for (const std::array<int, 4>& ids : s.squares) {
    for (size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d a = Point(s.problem, ids[k]), b = Point(s.problem, ids[(k + 1) % 4]);
      EXPECT_NEAR((b - a).norm(), edge, 0.005 * edge);  // the anchors' 0.1 % and the pixels' noise
      const Eigen::Vector3d diagonal = Point(s.problem, ids[(k + 2) % 4]) - a;
      if (k < 2) EXPECT_NEAR(diagonal.norm(), std::sqrt(2.0) * edge, 0.005 * edge);
    }
  }
  // The edge in the solution's own units: the ring of cameras, 6 from the centre, sets them.
  EXPECT_NEAR(edge, 0.4, 0.01);
}

TEST(PointAnchorTest, TheCostDoesNotDependOnTheProblemsScale) {
  const SquaresProblem s = MakeSquares(0.0);
  RadialProblem scaled = s.problem;
  const double factor = 3.0;
  for (double& x : scaled.points) x *= factor;
  for (int i = 0; i < scaled.num_cameras(); ++i) {
    for (int d = 3; d < 6; ++d) scaled.camera(i)[d] *= factor;
  }
  for (int i = kCameras; i < scaled.num_cameras(); ++i) scaled.camera(i)[6] *= factor;
  RobustLoss loss;
  const double cost = BundleAdjustmentCost(s.problem, loss);
  EXPECT_GT(cost, 1.0);  // the corners start off their squares
  EXPECT_NEAR(BundleAdjustmentCost(scaled, loss), cost, 1e-9 * cost);
}

TEST(PointAnchorTest, BadAnchorsAreRefused) {
  SquaresProblem s = MakeSquares(0.0);
  BundleAdjustmentOptions options;
  RadialProblem missing_frame = s.problem;
  missing_frame.point_anchors[0].frame = missing_frame.num_cameras();
  EXPECT_FALSE(SolveBundleAdjustment(options, s.constancy, &missing_frame).ok());
  RadialProblem missing_point = s.problem;
  missing_point.point_anchors[0].point = -1;
  EXPECT_FALSE(SolveBundleAdjustment(options, s.constancy, &missing_point).ok());
  RadialProblem not_finite = s.problem;
  not_finite.point_anchors[0].local[1] = std::nan("");
  EXPECT_FALSE(SolveBundleAdjustment(options, s.constancy, &not_finite).ok());
}

}  // namespace
}  // namespace reconar
