#pragma once
// Correspondence: the sample type of every two-view estimator. x1 is the point in the first
// image (a), x2 its putative match in the second image (b). Epipolar models follow the
// convention x2^T F x1 = 0 and homographies map x2 ~ H x1 (Hartley & Zisserman, ch. 9 and 4).
#include <Eigen/Core>

namespace reconar {

struct Correspondence {
  Eigen::Vector2d x1;  // image a: pixels (F, H) or normalised coordinates K^-1 x (E)
  Eigen::Vector2d x2;  // image b: same units as x1
};

}  // namespace reconar
