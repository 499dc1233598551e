#pragma once
// Helpers shared by the geometry tests.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/geometry/correspondence.h"
#include "core/geometry/synthetic_scene.h"

namespace reconar::geometry_test {

// Distance between two projective 3x3 matrices: both scaled to unit Frobenius norm, then the
// smaller of ||A - B|| and ||A + B|| (the sign is arbitrary).
inline double ProjectiveDistance(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  const Eigen::Matrix3d a = A / A.norm();
  const Eigen::Matrix3d b = B / B.norm();
  return std::min((a - b).norm(), (a + b).norm());
}

inline SyntheticTwoViewScene MakeScene(const SyntheticSceneOptions& options) {
  Result<SyntheticTwoViewScene> scene = MakeSyntheticTwoViewScene(options);
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  return std::move(scene).value();
}

// The first `count` true correspondences of a scene.
inline std::vector<Correspondence> FirstInliers(const SyntheticTwoViewScene& scene, int count, bool normalised = false) {
  const std::vector<Correspondence> all = scene.Correspondences(normalised);
  std::vector<Correspondence> result;
  for (size_t i = 0; i < all.size() && static_cast<int>(result.size()) < count; ++i) {
    if (scene.is_inlier[i]) result.push_back(all[i]);
  }
  return result;
}

// Noise-free correspondences of the scene's inliers (its 3D points projected by both cameras),
// in pixels or, with `normalised`, in normalised image coordinates.
inline std::vector<Correspondence> ExactInlierCorrespondences(const SyntheticTwoViewScene& scene,
                                                              bool normalised = false) {
  const Eigen::Matrix3d K = normalised ? Eigen::Matrix3d::Identity() : scene.K;
  std::vector<Correspondence> result;
  for (size_t i = 0; i < scene.points3d.size(); ++i) {
    if (!scene.is_inlier[i]) continue;
    const Eigen::Vector3d& X = scene.points3d[i];
    result.push_back(Correspondence{(K * (scene.R_a * X + scene.t_a)).hnormalized(),
                                    (K * (scene.R_b * X + scene.t_b)).hnormalized()});
  }
  return result;
}

// Root-mean-square of an estimator's residual for `model` over `samples`.
template <typename Estimator>
double RmsResidual(const std::vector<Correspondence>& samples, const Eigen::Matrix3d& model) {
  std::vector<double> squared(samples.size());
  Estimator::Residuals(samples.data(), static_cast<int>(samples.size()), model, squared.data());
  double sum = 0.0;
  for (double r : squared) sum += r;
  return std::sqrt(sum / static_cast<double>(samples.size()));
}

// Recall and false-inlier fraction of an estimated inlier mask against the scene's truth.
struct MaskQuality {
  double recall = 0.0;          // true inliers found / true inliers
  double false_fraction = 0.0;  // false inliers / reported inliers
};

inline MaskQuality CompareMasks(const std::vector<char>& estimated, const std::vector<char>& truth) {
  int true_positive = 0, false_positive = 0, positives = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    positives += truth[i] ? 1 : 0;
    if (estimated[i] && truth[i]) ++true_positive;
    if (estimated[i] && !truth[i]) ++false_positive;
  }
  MaskQuality quality;
  quality.recall = positives > 0 ? static_cast<double>(true_positive) / positives : 0.0;
  const int reported = true_positive + false_positive;
  quality.false_fraction = reported > 0 ? static_cast<double>(false_positive) / reported : 0.0;
  return quality;
}

}  // namespace reconar::geometry_test
