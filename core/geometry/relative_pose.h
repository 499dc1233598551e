#pragma once
// Relative pose from an essential matrix (Hartley & Zisserman, sec. 9.6.2): E = U diag(1,1,0) V^T
// yields the four candidates (U W V^T or U W^T V^T, +-u3); the one placing the most triangulated
// correspondences in front of both cameras (cheirality) is chosen.
// Convention: X2 = R X1 + t (camera 1 is [I | 0], camera 2 is [R | t]), E = [t]x R, x2^T E x1 = 0,
// ||t|| = 1.
#include <array>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/geometry/correspondence.h"

namespace reconar {

struct RelativePose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();  // unit length
  int num_in_front = 0;                         // correspondences with positive depth in both views
  std::vector<char> in_front_mask;              // per correspondence: 1 if it passed cheirality
};

// The two rotations and the translation direction u3 of E: the candidates are (R[0], +t),
// (R[0], -t), (R[1], +t), (R[1], -t). Both rotations have determinant +1.
void DecomposeEssential(const Eigen::Matrix3d& E, std::array<Eigen::Matrix3d, 2>* rotations, Eigen::Vector3d* t);

// Chooses among the four decompositions of E the pose with the most correspondences (normalised
// image coordinates K^-1 x) triangulated at positive depth in both cameras.
// InvalidArgument if E is not finite or has rank < 2, or `count` < 1;
// NumericFailure if no candidate puts any correspondence in front of both cameras.
Result<RelativePose> RelativePoseFromEssential(const Eigen::Matrix3d& E, const Correspondence* correspondences,
                                               int count);

}  // namespace reconar
