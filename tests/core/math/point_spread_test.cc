#include "core/math/point_spread.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace reconar {
namespace {

TEST(PointSpread, PointsOnAPlaneHaveItsNormalAsTheirThinnestAxis) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 3; ++j) points.push_back(Eigen::Vector3d(2.0 * i, j, 5.0));
  }
  const PointSpread spread = SpreadOfPoints(points);
  EXPECT_LT((spread.mean - Eigen::Vector3d(3.0, 1.0, 5.0)).norm(), 1e-12);
  EXPECT_NEAR(spread.eigenvalues[0], 0.0, 1e-12);
  EXPECT_NEAR(std::abs(spread.ThinnestAxis().z()), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(spread.axes.col(2).x()), 1.0, 1e-12);  // the longest side
  EXPECT_LE(spread.eigenvalues[1], spread.eigenvalues[2]);
}

TEST(PointSpread, PointsOnALineHaveOneEigenvalueOnly) {
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, 2.0, -2.0).normalized();
  const PointSpread spread = SpreadOfPoints({direction, 2.0 * direction, -4.0 * direction});
  EXPECT_NEAR(spread.eigenvalues[1], 0.0, 1e-12);
  EXPECT_NEAR(std::abs(spread.axes.col(2).dot(direction)), 1.0, 1e-12);
}

TEST(PointSpread, NoPointsSpreadNowhere) {
  const PointSpread spread = SpreadOfPoints({});
  EXPECT_EQ(spread.mean, Eigen::Vector3d::Zero());
  EXPECT_EQ(spread.eigenvalues, Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace reconar
