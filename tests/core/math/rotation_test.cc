#include "core/math/rotation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace reconar {
namespace {

TEST(Rotation, AngleAxisRoundTrip) {
  for (const Eigen::Vector3d& w :
       {Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(2.0, 1.0, -0.5), Eigen::Vector3d(0.0, 0.0, 3.0)}) {
    const Eigen::Matrix3d R = RotationFromAngleAxis(w);
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
    EXPECT_LT((AngleAxisFromRotation(R) - w).norm(), 1e-12) << w.transpose();
    EXPECT_LT((R - Eigen::Matrix3d(Eigen::AngleAxisd(w.norm(), w.normalized()))).norm(), 1e-15);
  }
}

TEST(Rotation, SmallAnglesAreFirstOrder) {
  EXPECT_EQ(RotationFromAngleAxis(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
  const Eigen::Vector3d w(1e-13, -2e-13, 3e-13);
  EXPECT_EQ(RotationFromAngleAxis(w), Eigen::Matrix3d(Eigen::Matrix3d::Identity() + Skew(w)));
  EXPECT_EQ(AngleAxisFromRotation(Eigen::Matrix3d::Identity()), Eigen::Vector3d::Zero());
}

TEST(Rotation, SkewIsTheCrossProduct) {
  const Eigen::Vector3d v(1.0, -2.0, 0.5), a(0.3, 0.7, -1.1);
  EXPECT_LT((Skew(v) * a - v.cross(a)).norm(), 1e-15);
}

TEST(Rotation, NearestRotationProjectsOntoSO3) {
  const Eigen::Matrix3d R = RotationFromAngleAxis(Eigen::Vector3d(0.4, -0.1, 0.2));
  Eigen::Matrix3d noisy = R;
  noisy(0, 1) += 1e-3;
  noisy(2, 0) -= 2e-3;
  const Eigen::Matrix3d nearest = NearestRotation(noisy);
  EXPECT_LT((nearest.transpose() * nearest - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(nearest.determinant(), 1.0, 1e-14);
  EXPECT_LT(RotationAngle(nearest, R), 2e-3);
  EXPECT_LT((NearestRotation(2.0 * R) - R).norm(), 1e-14);
  // A reflection maps to a proper rotation.
  EXPECT_NEAR(NearestRotation(-R).determinant(), 1.0, 1e-14);
}

TEST(Rotation, RotationAngleOfRelativeRotation) {
  const Eigen::Matrix3d a = RotationFromAngleAxis(Eigen::Vector3d(0.1, 0.2, -0.3));
  const Eigen::Matrix3d b = a * RotationFromAngleAxis(Eigen::Vector3d(0.0, 0.25, 0.0));
  EXPECT_NEAR(RotationAngle(a, b), 0.25, 1e-14);
  EXPECT_NEAR(RotationAngle(a, a), 0.0, 1e-15);
}

}  // namespace
}  // namespace reconar
