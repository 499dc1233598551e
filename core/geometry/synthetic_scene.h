#pragma once
// Seeded synthetic two-view scenes for tests and benchmarks: random 3D points seen by two random
// pinhole cameras with known K, R, t, Gaussian pixel noise and uniformly random outlier matches.
// The same options (including the seed) always give the same scene (across platforms up to the
// last-bit rounding of libm functions).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/geometry/correspondence.h"

namespace reconar {

struct SyntheticSceneOptions {
  // Inliers are uniformly random pixels of image a back-projected into the scene, kept when
  // camera b sees them too. Camera a looks at the origin from distance 5; camera b:
  enum class Kind {
    kGeneral,       // orbits camera a by 8..20 degrees about the origin (baseline ~0.7..1.7);
                    // points at depths 3..7 in camera a
    kPlanar,        // as kGeneral, points on a plane through the origin tilted <= 40 degrees
                    // away from facing camera a
    kPureRotation,  // shares camera a's centre (zero baseline), turned by 4..10 degrees
  };
  Kind kind = Kind::kGeneral;
  int num_points = 500;            // correspondences, inliers and outliers together
  double outlier_fraction = 0.0;   // in [0, 1): round(fraction * num_points) outliers at random indices
  double noise_sigma = 0.0;        // pixels; isotropic Gaussian noise on both images' inlier points
  // Outliers are redrawn until their distance (sqrt of Sampson error under the true F; transfer
  // error under the true H for kPlanar / kPureRotation) is at least this many pixels, so that
  // "outlier" means geometrically inconsistent. 0 keeps them purely uniform.
  double min_outlier_distance = 0.0;
  int width = 1024;
  int height = 768;
  double focal = 800.0;            // pixels; principal point at the image centre
  uint64_t seed = 1;

  Status Check() const;
};

struct SyntheticTwoViewScene {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  // World-to-camera poses: X_a = R_a X + t_a, X_b = R_b X + t_b.
  Eigen::Matrix3d R_a = Eigen::Matrix3d::Identity(), R_b = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_a = Eigen::Vector3d::Zero(), t_b = Eigen::Vector3d::Zero();
  // Relative pose X_b = R X_a + t and the induced two-view models, x_b^T F x_a = 0.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();  // [t]x R, unit Frobenius norm (zero for pure rotation)
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();  // K^-T E K^-1, unit Frobenius norm (zero for pure rotation)
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // x_b ~ H x_a for kPlanar / kPureRotation, else zero
  std::vector<Eigen::Vector3d> points3d;        // world points of the inliers (NaN for outliers)
  std::vector<Eigen::Vector2d> points_a;        // pixels, noisy, outliers included
  std::vector<Eigen::Vector2d> points_b;
  std::vector<char> is_inlier;                  // 1 for true correspondences

  // points_a[i] <-> points_b[i] as correspondences; with `normalised`, K^-1 is applied (for E).
  std::vector<Correspondence> Correspondences(bool normalised = false) const;
  int num_inliers() const;
};

// InvalidArgument for options failing Check(); Internal if points visible in both images could
// not be placed (does not happen for the documented option ranges).
Result<SyntheticTwoViewScene> MakeSyntheticTwoViewScene(const SyntheticSceneOptions& options);

// [v]x, the cross-product matrix.
Eigen::Matrix3d CrossProductMatrix(const Eigen::Vector3d& v);

}  // namespace reconar
