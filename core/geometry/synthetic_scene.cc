#include "core/geometry/synthetic_scene.h"

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "core/base/prng.h"
#include "core/geometry/residuals.h"

namespace reconar {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;
constexpr double kCameraDistance = 5.0;
constexpr int kMaxAttemptsPerPoint = 1000;

Eigen::Vector3d RandomUnitVector(SplitMix64* rng) {
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(rng->Gaussian(), rng->Gaussian(), rng->Gaussian());
  } while (!(v.norm() > 1e-6));
  return v.normalized();
}

// A random unit vector orthogonal to the unit vector `v`.
Eigen::Vector3d RandomOrthogonalUnitVector(const Eigen::Vector3d& v, SplitMix64* rng) {
  Eigen::Vector3d u;
  do {
    u = RandomUnitVector(rng);
    u -= u.dot(v) * v;
  } while (!(u.norm() > 1e-3));
  return u.normalized();
}

Eigen::Matrix3d Rotation(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// World-to-camera rotation of a camera at `center` whose optical axis (+z) points at `target`,
// rolled by `roll` radians about that axis.
Eigen::Matrix3d LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target, double roll) {
  const Eigen::Vector3d z = (target - center).normalized();
  const Eigen::Vector3d helper = std::abs(z.y()) < 0.9 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = helper.cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  return Rotation(Eigen::Vector3d::UnitZ(), roll) * R;
}

// Projects a world point; false if it is behind the camera or outside the image.
bool Project(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& X,
             int width, int height, Eigen::Vector2d* pixel) {
  const Eigen::Vector3d x = K * (R * X + t);
  if (!(x.z() > 1e-3)) return false;
  *pixel = x.head<2>() / x.z();
  return pixel->x() >= 0.0 && pixel->x() < width && pixel->y() >= 0.0 && pixel->y() < height;
}

Eigen::Matrix3d UnitNorm(const Eigen::Matrix3d& M) {
  const double norm = M.norm();
  return norm > 0.0 ? Eigen::Matrix3d(M / norm) : M;
}

}  // namespace

Status SyntheticSceneOptions::Check() const {
  if (num_points < 1) return InvalidArgument("SyntheticSceneOptions.num_points must be >= 1");
  if (!(outlier_fraction >= 0.0 && outlier_fraction < 1.0)) {
    return InvalidArgument("SyntheticSceneOptions.outlier_fraction must be in [0, 1), got " +
                           std::to_string(outlier_fraction));
  }
  if (!(noise_sigma >= 0.0) || !std::isfinite(noise_sigma)) {
    return InvalidArgument("SyntheticSceneOptions.noise_sigma must be >= 0");
  }
  if (width < 16 || height < 16) return InvalidArgument("SyntheticSceneOptions: image must be at least 16x16");
  if (!(min_outlier_distance >= 0.0) || !(min_outlier_distance < 0.1 * std::min(width, height))) {
    return InvalidArgument("SyntheticSceneOptions.min_outlier_distance must be in [0, min(width, height) / 10)");
  }
  if (!(focal > 0.0) || !std::isfinite(focal)) return InvalidArgument("SyntheticSceneOptions.focal must be positive");
  return Status::Ok();
}

Eigen::Matrix3d CrossProductMatrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d M;
  M << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return M;
}

std::vector<Correspondence> SyntheticTwoViewScene::Correspondences(bool normalised) const {
  std::vector<Correspondence> result(points_a.size());
  const Eigen::Matrix3d K_inverse = K.inverse();
  for (size_t i = 0; i < points_a.size(); ++i) {
    if (normalised) {
      result[i].x1 = (K_inverse * points_a[i].homogeneous()).hnormalized();
      result[i].x2 = (K_inverse * points_b[i].homogeneous()).hnormalized();
    } else {
      result[i].x1 = points_a[i];
      result[i].x2 = points_b[i];
    }
  }
  return result;
}

int SyntheticTwoViewScene::num_inliers() const {
  int count = 0;
  for (char inlier : is_inlier) count += inlier ? 1 : 0;
  return count;
}

Result<SyntheticTwoViewScene> MakeSyntheticTwoViewScene(const SyntheticSceneOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  using Kind = SyntheticSceneOptions::Kind;
  SplitMix64 rng(options.seed);
  SyntheticTwoViewScene scene;
  scene.K << options.focal, 0.0, 0.5 * options.width,  //
      0.0, options.focal, 0.5 * options.height,        //
      0.0, 0.0, 1.0;

  // Cameras: a looks at the origin from distance 5; b orbits it (or only turns, for rotation).
  const Eigen::Vector3d center_a = kCameraDistance * RandomUnitVector(&rng);
  const Eigen::Vector3d jitter_a = 0.1 * RandomUnitVector(&rng);
  scene.R_a = LookAt(center_a, jitter_a, rng.Uniform(-kPi, kPi));
  Eigen::Vector3d center_b = center_a;
  if (options.kind == Kind::kPureRotation) {
    scene.R_b = Rotation(RandomUnitVector(&rng), rng.Uniform(4.0, 10.0) * kDegree) * scene.R_a;
  } else {
    const Eigen::Vector3d axis = RandomOrthogonalUnitVector(center_a.normalized(), &rng);
    center_b = Rotation(axis, rng.Uniform(8.0, 20.0) * kDegree) * center_a;
    const Eigen::Vector3d jitter_b = 0.1 * RandomUnitVector(&rng);
    scene.R_b = LookAt(center_b, jitter_b, rng.Uniform(-kPi, kPi));
  }
  scene.t_a = -scene.R_a * center_a;
  scene.t_b = -scene.R_b * center_b;
  scene.R = scene.R_b * scene.R_a.transpose();
  scene.t = scene.t_b - scene.R * scene.t_a;
  if (options.kind != Kind::kPureRotation) {
    scene.E = UnitNorm(CrossProductMatrix(scene.t) * scene.R);
    const Eigen::Matrix3d K_inv = scene.K.inverse();
    scene.F = UnitNorm(K_inv.transpose() * scene.E * K_inv);
  }

  // The plane n^T X = 0 (world) for kPlanar: its normal is within 40 degrees of the direction
  // to camera a, so the plane is seen from the front, never edge-on.
  Eigen::Vector3d plane_normal = center_a.normalized();
  plane_normal = Rotation(RandomOrthogonalUnitVector(plane_normal, &rng), rng.Uniform(0.0, 40.0) * kDegree) * plane_normal;
  if (options.kind == Kind::kPlanar) {
    // In camera a, n_a^T X_a = d_a with n_a = R_a n, d_a = n_a^T t_a; then X_b = (R + t n_a^T / d_a) X_a.
    const Eigen::Vector3d n_a = scene.R_a * plane_normal;
    const double d_a = n_a.dot(scene.t_a);
    scene.H = UnitNorm(scene.K * (scene.R + scene.t * n_a.transpose() / d_a) * scene.K.inverse());
  } else if (options.kind == Kind::kPureRotation) {
    scene.H = UnitNorm(scene.K * scene.R * scene.K.inverse());
  }
  const Eigen::Matrix3d K_inverse = scene.K.inverse();

  const int n = options.num_points;
  const int num_outliers = static_cast<int>(std::lround(options.outlier_fraction * n));
  std::vector<int> order(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) order[i] = i;
  for (int i = n - 1; i > 0; --i) std::swap(order[i], order[rng.UniformInt(static_cast<uint32_t>(i + 1))]);
  scene.is_inlier.assign(static_cast<size_t>(n), 1);
  for (int i = 0; i < num_outliers; ++i) scene.is_inlier[order[i]] = 0;

  scene.points3d.assign(static_cast<size_t>(n), Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  scene.points_a.resize(static_cast<size_t>(n));
  scene.points_b.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    bool placed = false;
    for (int attempt = 0; attempt < kMaxAttemptsPerPoint && !placed; ++attempt) {
      if (scene.is_inlier[i]) {
        // A uniformly random pixel of image a, back-projected to a random depth in
        // [kCameraDistance - 2, kCameraDistance + 2] or onto the plane: inliers cover image a.
        const Eigen::Vector3d pixel(rng.Uniform(0.0, options.width), rng.Uniform(0.0, options.height), 1.0);
        const Eigen::Vector3d ray = scene.R_a.transpose() * (K_inverse * pixel);  // world direction, unit depth
        double depth = rng.Uniform(kCameraDistance - 2.0, kCameraDistance + 2.0);
        if (options.kind == Kind::kPlanar) depth = -plane_normal.dot(center_a) / plane_normal.dot(ray);
        if (!(depth > 0.5)) continue;
        const Eigen::Vector3d X = center_a + depth * ray;
        Eigen::Vector2d a, b;
        if (!Project(scene.K, scene.R_a, scene.t_a, X, options.width, options.height, &a) ||
            !Project(scene.K, scene.R_b, scene.t_b, X, options.width, options.height, &b)) {
          continue;
        }
        scene.points3d[i] = X;
        scene.points_a[i] = a + options.noise_sigma * Eigen::Vector2d(rng.Gaussian(), rng.Gaussian());
        scene.points_b[i] = b + options.noise_sigma * Eigen::Vector2d(rng.Gaussian(), rng.Gaussian());
        placed = true;
      } else {
        const Eigen::Vector2d a(rng.Uniform(0.0, options.width), rng.Uniform(0.0, options.height));
        const Eigen::Vector2d b(rng.Uniform(0.0, options.width), rng.Uniform(0.0, options.height));
        const double squared_distance = options.kind == Kind::kGeneral ? SquaredSampsonError(scene.F, a, b)
                                                                       : SquaredTransferError(scene.H, a, b);
        if (squared_distance < options.min_outlier_distance * options.min_outlier_distance) continue;
        scene.points_a[i] = a;
        scene.points_b[i] = b;
        placed = true;
      }
    }
    if (!placed) {
      return Internal("MakeSyntheticTwoViewScene: could not place correspondence " + std::to_string(i) +
                      " (seed " + std::to_string(options.seed) + ")");
    }
  }
  return scene;
}

}  // namespace reconar
