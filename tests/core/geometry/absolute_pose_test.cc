// Absolute pose: the P3P and DLT solvers on exact data, the LO-RANSAC registration with noise and
// outliers against the Cramer-Rao bound, the unknown-focal path, the robust refinement, and the
// failure reasons on degenerate input.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/base/prng.h"
#include "core/geometry/absolute_pose.h"

namespace reconar {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Matrix3d RandomRotation(SplitMix64* rng, double max_angle = kPi) {
  Eigen::Vector3d axis(rng->Gaussian(), rng->Gaussian(), rng->Gaussian());
  return Eigen::AngleAxisd(rng->Uniform(0.0, max_angle), axis.normalized()).toRotationMatrix();
}

// Rotation vector of R_a R_b^T: the increment dw with R_a = exp(dw) R_b.
Eigen::Vector3d RotationDifference(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  const Eigen::AngleAxisd delta(R_a * R_b.transpose());
  return delta.angle() * delta.axis();
}

struct SceneOptions {
  int num_points = 200;
  double outlier_fraction = 0.0;
  double noise_px = 0.0;
  double focal = 800.0;
  double k1 = 0.0;
  double k2 = 0.0;
  int width = 1024;
  int height = 768;
  // The points project into the central view_fraction of the image's width and height.
  double view_fraction = 1.0;
  double min_depth = 3.0;
  double max_depth = 8.0;
  uint64_t seed = 1;
};

// A random camera looking at random points at depths min_depth..max_depth that project into the image; outliers
// are uniformly random pixels at least 20 px from the true projection.
struct Scene {
  RadialCamera camera;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector2d> exact_pixels;
  std::vector<Eigen::Vector3d> world;
  std::vector<char> is_inlier;

  int num_inliers() const { return static_cast<int>(std::count(is_inlier.begin(), is_inlier.end(), 1)); }
};

Scene MakeScene(const SceneOptions& options) {
  SplitMix64 rng(options.seed);
  Scene scene;
  scene.camera = RadialCamera{options.focal, 0.5 * options.width + 3.0, 0.5 * options.height - 2.0, options.k1,
                                    options.k2};
  scene.R = RandomRotation(&rng);
  const Eigen::Vector3d centre(rng.Uniform(-2, 2), rng.Uniform(-2, 2), rng.Uniform(-2, 2));
  scene.t = -scene.R * centre;
  const double half_w = 0.5 * options.view_fraction * options.width / options.focal;
  const double half_h = 0.5 * options.view_fraction * options.height / options.focal;
  for (int i = 0; i < options.num_points; ++i) {
    const Eigen::Vector2d p(rng.Uniform(-half_w, half_w), rng.Uniform(-half_h, half_h));
    const Eigen::Vector3d X_cam = rng.Uniform(options.min_depth, options.max_depth) * p.homogeneous();
    scene.world.push_back(scene.R.transpose() * (X_cam - scene.t));
    scene.exact_pixels.push_back(scene.camera.PixelFromNormalised(p));
    scene.pixels.push_back(scene.exact_pixels.back() +
                           options.noise_px * Eigen::Vector2d(rng.Gaussian(), rng.Gaussian()));
    scene.is_inlier.push_back(1);
  }
  const int num_outliers = static_cast<int>(std::lround(options.outlier_fraction * options.num_points));
  for (int k = 0; k < num_outliers; ++k) {
    int i;
    do {
      i = static_cast<int>(rng.UniformInt(static_cast<uint32_t>(options.num_points)));
    } while (!scene.is_inlier[i]);
    scene.is_inlier[i] = 0;
    do {
      scene.pixels[i] = Eigen::Vector2d(rng.Uniform(0, options.width), rng.Uniform(0, options.height));
    } while ((scene.pixels[i] - scene.exact_pixels[i]).norm() < 20.0);
  }
  return scene;
}

// MakeScene with the default options but the number of points and the seed.
Scene MakeSceneOf(int num_points, uint64_t seed) {
  SceneOptions options;
  options.num_points = num_points;
  options.seed = seed;
  return MakeScene(options);
}

std::vector<PoseCorrespondence> NormalisedCorrespondences(const Scene& scene, bool exact) {
  std::vector<PoseCorrespondence> result;
  for (size_t i = 0; i < scene.world.size(); ++i) {
    Eigen::Vector2d p = Eigen::Vector2d::Zero();
    EXPECT_TRUE(scene.camera.Undistort(exact ? scene.exact_pixels[i] : scene.pixels[i], &p));
    result.push_back(PoseCorrespondence{p, scene.world[i]});
  }
  return result;
}

Matrix34d Pose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Matrix34d P;
  P << R, t;
  return P;
}

// Mahalanobis distance squared of the pose error (and log-focal error) under the Cramer-Rao bound
// sigma^2 (J^T J)^-1 of the true inliers' pixel errors, J by central differences in the
// parameterisation of the refinement (R = exp(dw) R_true, t = t_true + dt, f = f_true exp(df)).
double PoseErrorMahalanobis(const Scene& scene, double sigma_px, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                            double focal, bool with_focal) {
  const int n = with_focal ? 7 : 6;
  const auto project = [&](const Eigen::VectorXd& x, const Eigen::Vector3d& X) {
    RadialCamera camera = scene.camera;
    camera.focal *= std::exp(with_focal ? x(6) : 0.0);
    const Eigen::Matrix3d R_x = Eigen::AngleAxisd(x.head<3>().norm(), x.head<3>().normalized()).toRotationMatrix();
    const Eigen::Vector3d Xc = (x.head<3>().norm() > 0 ? R_x : Eigen::Matrix3d::Identity()) * scene.R * X +
                               scene.t + x.segment<3>(3);
    return camera.PixelFromNormalised(Xc.head<2>() / Xc.z());
  };
  Eigen::MatrixXd JtJ = Eigen::MatrixXd::Zero(n, n);
  for (size_t i = 0; i < scene.world.size(); ++i) {
    if (!scene.is_inlier[i]) continue;
    Eigen::MatrixXd J(2, n);
    for (int k = 0; k < n; ++k) {
      Eigen::VectorXd plus = Eigen::VectorXd::Zero(n), minus = Eigen::VectorXd::Zero(n);
      plus(k) = 1e-6;
      minus(k) = -1e-6;
      J.col(k) = (project(plus, scene.world[i]) - project(minus, scene.world[i])) / 2e-6;
    }
    JtJ += J.transpose() * J;
  }
  Eigen::VectorXd error(n);
  error.head<3>() = RotationDifference(R, scene.R);
  error.segment<3>(3) = t - scene.t;
  if (with_focal) error(6) = std::log(focal / scene.camera.focal);
  return error.dot(JtJ * error) / (sigma_px * sigma_px);
}

// ---------------------------------------------------------------------------------------------
// P3P

// Distances lambda_i = |R X_i + t| of a model, the unknowns of P3P.
Eigen::Vector3d Distances(const Matrix34d& P, const std::vector<PoseCorrespondence>& sample) {
  Eigen::Vector3d lambda;
  for (int i = 0; i < 3; ++i) lambda(i) = (P.leftCols<3>() * sample[i].world + P.col(3)).norm();
  return lambda;
}

// Every positive solution (lambda_1, lambda_2, lambda_3) of the P3P distance equations, found
// independently of the solver: lambda_2 and lambda_3 follow from lambda_1 by the a_12 and a_13
// equations (two branches each); the a_23 equation is scanned for sign changes along lambda_1 on
// a fine grid and bisected.
std::vector<Eigen::Vector3d> BruteForceP3P(const std::vector<PoseCorrespondence>& sample) {
  Eigen::Vector3d y[3];
  for (int i = 0; i < 3; ++i) y[i] = sample[i].point.homogeneous().normalized();
  const double a12 = (sample[0].world - sample[1].world).squaredNorm();
  const double a13 = (sample[0].world - sample[2].world).squaredNorm();
  const double a23 = (sample[1].world - sample[2].world).squaredNorm();
  const double b12 = y[0].dot(y[1]), b13 = y[0].dot(y[2]), b23 = y[1].dot(y[2]);
  const double lambda1_max = std::min(std::sqrt(a12 / (1 - b12 * b12)), std::sqrt(a13 / (1 - b13 * b13)));
  std::vector<Eigen::Vector3d> roots;
  for (double sign2 : {1.0, -1.0}) {
    for (double sign3 : {1.0, -1.0}) {
      const auto lambdas = [&](double l1) {
        const double l2 = b12 * l1 + sign2 * std::sqrt(std::max(0.0, a12 - l1 * l1 * (1 - b12 * b12)));
        const double l3 = b13 * l1 + sign3 * std::sqrt(std::max(0.0, a13 - l1 * l1 * (1 - b13 * b13)));
        return Eigen::Vector3d(l1, l2, l3);
      };
      const auto f = [&](double l1) {
        const Eigen::Vector3d l = lambdas(l1);
        return (l(1) * l(1) + l(2) * l(2) - 2 * b23 * l(1) * l(2) - a23) / a23;
      };
      constexpr int kSteps = 20000;
      double previous_x = 1e-9 * lambda1_max, previous_f = f(previous_x);
      for (int step = 1; step <= kSteps; ++step) {
        const double x = lambda1_max * step / kSteps * (1 - 1e-12);
        const double value = f(x);
        if ((previous_f < 0) != (value < 0)) {
          double lo = previous_x, hi = x, f_lo = previous_f;
          for (int b = 0; b < 100; ++b) {
            const double mid = 0.5 * (lo + hi);
            const double f_mid = f(mid);
            if ((f_mid < 0) == (f_lo < 0)) {
              lo = mid;
              f_lo = f_mid;
            } else {
              hi = mid;
            }
          }
          const Eigen::Vector3d root = lambdas(0.5 * (lo + hi));
          const bool duplicate = std::any_of(roots.begin(), roots.end(), [&](const Eigen::Vector3d& r) {
            return (r - root).norm() < 1e-6 * root.norm();
          });
          if (root.minCoeff() > 0 && !duplicate) roots.push_back(root);
        }
        previous_x = x;
        previous_f = value;
      }
    }
  }
  return roots;
}

TEST(P3PEstimator, ExactDataGivesTruePoseTo1e9) {
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    SCOPED_TRACE(seed);
    const Scene scene = MakeSceneOf(3, seed);
    const std::vector<PoseCorrespondence> sample = NormalisedCorrespondences(scene, /*exact=*/true);
    std::array<Matrix34d, P3PEstimator::kMaxModels> models;
    const int num_models = P3PEstimator::Estimate(sample.data(), 3, &models);
    ASSERT_GE(num_models, 1);
    double best = 1e300;
    for (int m = 0; m < num_models; ++m) {
      const Eigen::Matrix3d R = models[m].leftCols<3>();
      EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
      EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
      std::array<double, 3> residuals;
      P3PEstimator::Residuals(sample.data(), 3, models[m], residuals.data());
      for (double r : residuals) EXPECT_LT(r, 1e-24);  // in front and exact: (1e-12)^2
      best = std::min(best, (models[m] - Pose(scene.R, scene.t)).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(best, 1e-9);
  }
}

TEST(P3PEstimator, ReturnsEverySolutionOfTheDistanceEquations) {
  // Wide-angle triples (bearings up to 60 degrees off axis) often have 3 or 4 solutions.
  SplitMix64 rng(42);
  std::array<int, 5> histogram{};
  for (int instance = 0; instance < 400; ++instance) {
    SCOPED_TRACE(instance);
    const Eigen::Matrix3d R = RandomRotation(&rng);
    const Eigen::Vector3d t(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
    std::vector<PoseCorrespondence> sample;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d p(rng.Uniform(-1.7, 1.7), rng.Uniform(-1.7, 1.7));
      const Eigen::Vector3d X_cam = rng.Uniform(1.0, 4.0) * p.homogeneous();
      sample.push_back(PoseCorrespondence{p, R.transpose() * (X_cam - t)});
    }
    std::array<Matrix34d, P3PEstimator::kMaxModels> models;
    const int num_models = P3PEstimator::Estimate(sample.data(), 3, &models);
    const std::vector<Eigen::Vector3d> expected = BruteForceP3P(sample);
    ASSERT_EQ(num_models, static_cast<int>(expected.size()));
    ++histogram[num_models];
    for (const Eigen::Vector3d& lambda : expected) {
      bool found = false;
      for (int m = 0; m < num_models; ++m) {
        found = found || (Distances(models[m], sample) - lambda).norm() < 1e-7 * lambda.norm();
      }
      EXPECT_TRUE(found) << lambda.transpose();
    }
    bool true_pose_found = false;
    for (int m = 0; m < num_models; ++m) {
      true_pose_found = true_pose_found || (models[m] - Pose(R, t)).cwiseAbs().maxCoeff() < 1e-9;
    }
    EXPECT_TRUE(true_pose_found);
  }
  EXPECT_EQ(histogram[0], 0);
  EXPECT_GT(histogram[4], 0) << "no instance exercised four solutions";
  EXPECT_GT(histogram[2], 0);
}

TEST(P3PEstimator, DegenerateSamplesGiveNoModel) {
  std::array<Matrix34d, P3PEstimator::kMaxModels> models;
  // World points on a line: the rotation about it is free.
  std::vector<PoseCorrespondence> collinear = {{Eigen::Vector2d(-0.1, 0.0), Eigen::Vector3d(-1, 0, 5)},
                                               {Eigen::Vector2d(0.0, 0.0), Eigen::Vector3d(0, 0, 5)},
                                               {Eigen::Vector2d(0.1, 0.0), Eigen::Vector3d(1, 0, 5)}};
  EXPECT_EQ(P3PEstimator::Estimate(collinear.data(), 3, &models), 0);
  const PoseCorrespondence same{Eigen::Vector2d(0.1, 0.2), Eigen::Vector3d(1, 2, 3)};
  std::vector<PoseCorrespondence> coincident(3, same);
  EXPECT_EQ(P3PEstimator::Estimate(coincident.data(), 3, &models), 0);
  EXPECT_EQ(P3PEstimator::Estimate(collinear.data(), 2, &models), 0);
}

TEST(P3PEstimator, ResidualEnforcesCheirality) {
  const Matrix34d P = Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  double residual = 0.0;
  const PoseCorrespondence behind{Eigen::Vector2d(0.1, 0.1), Eigen::Vector3d(-0.2, -0.2, -2.0)};  // projects exactly
  P3PEstimator::Residuals(&behind, 1, P, &residual);
  EXPECT_EQ(residual, std::numeric_limits<double>::max());
  const PoseCorrespondence front{Eigen::Vector2d(0.1, 0.1), Eigen::Vector3d(0.2, 0.2, 2.0)};
  P3PEstimator::Residuals(&front, 1, P, &residual);
  EXPECT_LT(residual, 1e-30);
}

// ---------------------------------------------------------------------------------------------
// DLT and decompositions

double ProjectiveDistance34(const Matrix34d& A, const Matrix34d& B) {
  const Matrix34d a = A / A.norm(), b = B / B.norm();
  return std::min((a - b).norm(), (a + b).norm());
}

TEST(DltPoseEstimator, ExactDataGivesTrueProjection) {
  for (uint64_t seed = 1; seed <= 50; ++seed) {
    SCOPED_TRACE(seed);
    const Scene scene = MakeSceneOf(6, seed);
    const std::vector<PoseCorrespondence> sample = NormalisedCorrespondences(scene, /*exact=*/true);
    std::array<Matrix34d, 1> models;
    ASSERT_EQ(DltPoseEstimator::Estimate(sample.data(), 6, &models), 1);
    EXPECT_LT(ProjectiveDistance34(models[0], Pose(scene.R, scene.t)), 1e-9);
    // Scaled so that depths are positive and metric: here P is exactly [R | t].
    EXPECT_LT((models[0] - Pose(scene.R, scene.t)).cwiseAbs().maxCoeff(), 1e-8);
  }
}

TEST(DltPoseEstimator, CoplanarOrCoincidentPointsAreDegenerate) {
  SplitMix64 rng(3);
  std::vector<PoseCorrespondence> planar;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d X(rng.Uniform(-1, 1), rng.Uniform(-1, 1), 0.0);
    const Eigen::Vector3d X_cam = X + Eigen::Vector3d(0.1, -0.2, 5.0);
    planar.push_back(PoseCorrespondence{X_cam.hnormalized(), X});
  }
  std::array<Matrix34d, 1> models;
  EXPECT_EQ(DltPoseEstimator::Estimate(planar.data(), 20, &models), 0);
  const PoseCorrespondence same{Eigen::Vector2d(0.1, 0.2), Eigen::Vector3d(1, 2, 3)};
  std::vector<PoseCorrespondence> coincident(8, same);
  EXPECT_EQ(DltPoseEstimator::Estimate(coincident.data(), 8, &models), 0);
}

TEST(PoseLocalEstimator, RefinesAPerturbedPoseToTheTruthOnExactData) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE(seed);
    const Scene scene = MakeSceneOf(12, seed);
    const std::vector<PoseCorrespondence> samples = NormalisedCorrespondences(scene, /*exact=*/true);
    SplitMix64 rng(seed + 100);
    const Eigen::Matrix3d R_start = RandomRotation(&rng, 2.0 * kPi / 180.0) * scene.R;
    const Eigen::Vector3d t_start = scene.t + 0.05 * (1.0 + scene.t.norm()) * Eigen::Vector3d(1, -1, 0.5).normalized();
    std::array<Matrix34d, 1> models;
    ASSERT_EQ(PoseLocalEstimator::Refine(samples.data(), 12, Pose(R_start, t_start), &models), 1);
    EXPECT_LT(RotationDifference(models[0].leftCols<3>(), scene.R).norm(), 1e-9);
    EXPECT_LT((models[0].col(3) - scene.t).norm(), 1e-9 * (1.0 + scene.t.norm()));
    // Still a rotation.
    EXPECT_LT((models[0].leftCols<3>() * models[0].leftCols<3>().transpose() - Eigen::Matrix3d::Identity()).norm(),
              1e-12);
  }
}

TEST(PoseLocalEstimator, TooFewSamplesOrAPointBehindTheStartGiveNoModel) {
  const Scene scene = MakeSceneOf(12, SceneOptions().seed);
  std::vector<PoseCorrespondence> samples = NormalisedCorrespondences(scene, /*exact=*/true);
  std::array<Matrix34d, 1> models;
  EXPECT_EQ(PoseLocalEstimator::Refine(samples.data(), 3, Pose(scene.R, scene.t), &models), 0);
  // The mirror image of a world point through the camera centre projects to the same pixel.
  const Eigen::Vector3d centre = -scene.R.transpose() * scene.t;
  samples[5].world = 2.0 * centre - samples[5].world;
  EXPECT_EQ(PoseLocalEstimator::Refine(samples.data(), 12, Pose(scene.R, scene.t), &models), 0);
}

TEST(DecomposeProjection, RecoversCalibrationAndPose) {
  SplitMix64 rng(5);
  for (int instance = 0; instance < 20; ++instance) {
    Eigen::Matrix3d K;
    K << rng.Uniform(500, 2000), rng.Uniform(-1, 1), rng.Uniform(-50, 50), 0, rng.Uniform(500, 2000),
        rng.Uniform(-50, 50), 0, 0, 1;
    const Eigen::Matrix3d R = RandomRotation(&rng);
    const Eigen::Vector3d t(rng.Uniform(-3, 3), rng.Uniform(-3, 3), rng.Uniform(-3, 3));
    Matrix34d P;
    P << K * R, K * t;
    P *= rng.Uniform(0.01, 100.0);
    Eigen::Matrix3d K_out, R_out;
    Eigen::Vector3d t_out;
    ASSERT_TRUE(DecomposeProjection(P, &K_out, &R_out, &t_out));
    EXPECT_LT((K_out - K).cwiseAbs().maxCoeff(), 1e-9 * K.norm());
    EXPECT_LT((R_out - R).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((t_out - t).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_FALSE(DecomposeProjection(-P, &K_out, &R_out, &t_out));  // det < 0: points behind
  }
}

TEST(NearestPose, ProjectsScaledPoseOntoRotation) {
  SplitMix64 rng(6);
  const Eigen::Matrix3d R = RandomRotation(&rng);
  const Eigen::Vector3d t(1, -2, 3);
  Eigen::Matrix3d R_out;
  Eigen::Vector3d t_out;
  ASSERT_TRUE(NearestPose(2.5 * Pose(R, t), &R_out, &t_out));
  EXPECT_LT((R_out - R).norm(), 1e-12);
  EXPECT_LT((t_out - t).norm(), 1e-12);
  EXPECT_FALSE(NearestPose(-Pose(R, t), &R_out, &t_out));
}

// ---------------------------------------------------------------------------------------------
// Registration

TEST(EstimateAbsolutePose, RecoversPoseFromNoisyDataWithOutliers) {
  for (double outlier_fraction : {0.3, 0.5}) {
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      SCOPED_TRACE(testing::Message() << "outliers " << outlier_fraction << " seed " << seed);
      SceneOptions options;
      options.num_points = 300;
      options.outlier_fraction = outlier_fraction;
      options.noise_px = 0.5;
      options.k1 = -0.08;
      options.k2 = 0.01;
      options.seed = seed;
      const Scene scene = MakeScene(options);
      const Result<AbsolutePoseResult> result =
          EstimateAbsolutePose(scene.pixels, scene.world, scene.camera, AbsolutePoseOptions());
      ASSERT_TRUE(result.ok()) << result.status().ToString();
      ASSERT_TRUE(result->success()) << result->reason;
      EXPECT_TRUE(result->reason.empty());
      EXPECT_TRUE(result->refined);
      EXPECT_TRUE(result->refinement.converged()) << TerminationName(result->refinement.termination);
      // Every true inlier within 4 px (noise 0.5 px: ~2e-14 miss probability) and no outlier (>= 20 px off).
      EXPECT_EQ(result->num_inliers, scene.num_inliers());
      for (int i : result->inliers) EXPECT_TRUE(scene.is_inlier[i]) << i;
      EXPECT_NEAR(result->mean_inlier_error_px, 0.5 * std::sqrt(kPi / 2), 0.1);  // Rayleigh mean
      // The ML estimate is within the Cramer-Rao ellipsoid: chi^2_6 has its 99.9 % quantile at 22.5.
      EXPECT_LT(PoseErrorMahalanobis(scene, options.noise_px, result->cam_from_world.rotation,
                                     result->cam_from_world.translation, result->focal, false),
                22.5);
      EXPECT_LT(RotationDifference(result->cam_from_world.rotation, scene.R).norm(), 1e-3);
      EXPECT_EQ(result->focal, scene.camera.focal);
    }
  }
}

TEST(EstimateAbsolutePose, WithoutRefinementTheRansacPoseIsClose) {
  SceneOptions options;
  options.num_points = 300;
  options.outlier_fraction = 0.4;
  options.noise_px = 0.5;
  const Scene scene = MakeScene(options);
  AbsolutePoseOptions pose_options;
  pose_options.refine = false;
  const Result<AbsolutePoseResult> result = EstimateAbsolutePose(scene.pixels, scene.world, scene.camera, pose_options);
  ASSERT_TRUE(result.ok());
  ASSERT_TRUE(result->success()) << result->reason;
  EXPECT_FALSE(result->refined);
  EXPECT_LT(RotationDifference(result->cam_from_world.rotation, scene.R).norm(), 5e-3);
  EXPECT_LT((result->cam_from_world.translation - scene.t).norm(), 5e-3 * (1 + scene.t.norm()));
  EXPECT_GE(result->num_inliers, scene.num_inliers() * 0.97);
}

// Few points of a nearly flat patch in a narrow cone of view, as when a handheld video's new
// keyframe sees a corner of the model: the local optimisation must keep the pose a pose. An
// 11-parameter DLT as the local step fits such inliers with a 3x4 matrix no rotation is near,
// and its nearest pose loses them (it failed 10 of these 100 scenes).
TEST(EstimateAbsolutePose, FewPointsOfANearlyFlatPatchInANarrowConeOfView) {
  int poses = 0;
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    SceneOptions options;
    options.num_points = 40;
    options.outlier_fraction = 0.25;
    options.noise_px = 1.0;
    options.view_fraction = 0.1;  // about 7 by 5 degrees of a 65 by 51 degree view
    options.min_depth = 4.0;
    options.max_depth = 4.08;
    options.seed = seed;
    const Scene scene = MakeScene(options);
    AbsolutePoseOptions pose_options;
    pose_options.min_inliers = 20;
    const Result<AbsolutePoseResult> result =
        EstimateAbsolutePose(scene.pixels, scene.world, scene.camera, pose_options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    EXPECT_TRUE(result->success()) << result->reason;
    if (!result->success()) continue;
    ++poses;
    // Noise 1 px: a true inlier is beyond 4 px with probability exp(-8) = 3e-4.
    EXPECT_GE(result->num_inliers, scene.num_inliers() - 2);
    for (int i : result->inliers) EXPECT_TRUE(scene.is_inlier[i]) << i;
    // The robust cost the refinement minimises, over the pose's inliers.
    const auto robust_cost = [&](const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
      const RobustLoss loss{pose_options.refinement.loss, pose_options.refinement.loss_scale_px};
      double cost = 0.0;
      for (int i : result->inliers) {
        double rho = 0.0, weight = 0.0;
        loss.Evaluate(SquaredPixelError(scene.camera, R, t, scene.world[i], scene.pixels[i]), &rho, &weight);
        cost += rho;
      }
      return cost;
    };
    const double ours = robust_cost(result->cam_from_world.rotation, result->cam_from_world.translation);
    const double truth = robust_cost(scene.R, scene.t);
    // The pose is the least-cost one: it explains the data at least as well as the truth does.
    // (The truth is no test of the pose itself here: in so flat and narrow a view the rotation and
    // translation trade off, several degrees apart at nearly the same cost, beyond the reach of
    // the linearised Cramer-Rao bound.)
    EXPECT_LE(ours, truth);
  }
  EXPECT_EQ(poses, 100);
}

// Two poses in one set of correspondences: 45 that one pose projects exactly, and 50 that another
// projects within 2.4 px a side. RANSAC's truncated cost prefers the 45 exact ones; the second
// pose from the outliers explains more, and is taken, the first kept as the alternative.
TEST(EstimateAbsolutePose, TheSecondPoseFromTheOutliersIsTakenWhenItExplainsMore) {
  SceneOptions exact_options;
  exact_options.num_points = 45;
  exact_options.seed = 11;
  const Scene exact = MakeScene(exact_options);
  SceneOptions noisy_options = exact_options;
  noisy_options.num_points = 50;
  noisy_options.seed = 12;
  const Scene noisy = MakeScene(noisy_options);
  ASSERT_GT(RotationDifference(exact.R, noisy.R).norm(), 0.5);
  std::vector<Eigen::Vector2d> pixels = exact.pixels;
  std::vector<Eigen::Vector3d> world = exact.world;
  SplitMix64 rng(5);
  for (size_t i = 0; i < noisy.pixels.size(); ++i) {
    pixels.push_back(noisy.pixels[i] + Eigen::Vector2d(rng.Uniform(-2.4, 2.4), rng.Uniform(-2.4, 2.4)));
    world.push_back(noisy.world[i]);
  }
  AbsolutePoseOptions options;
  const auto first = EstimateAbsolutePose(pixels, world, exact.camera, options);
  ASSERT_TRUE(first.ok() && first->success());
  EXPECT_LT(RotationDifference(first->cam_from_world.rotation, exact.R).norm(), 1e-6)
      << "the least truncated cost is the exact pose's";
  EXPECT_TRUE(first->alternatives.empty());

  options.second_pose_from_outliers = true;
  const auto second = EstimateAbsolutePose(pixels, world, exact.camera, options);
  ASSERT_TRUE(second.ok() && second->success());
  EXPECT_LT(RotationDifference(second->cam_from_world.rotation, noisy.R).norm(), 0.01);
  EXPECT_EQ(second->num_inliers, 50);
  ASSERT_EQ(second->alternatives.size(), 1u);
  EXPECT_LT(RotationDifference(second->alternatives[0].cam_from_world.rotation, exact.R).norm(), 1e-6);
  EXPECT_EQ(second->alternatives[0].inliers.size(), 45u);
}

TEST(EstimateAbsolutePose, DeterministicForAFixedSeed) {
  SceneOptions options;
  options.outlier_fraction = 0.4;
  options.noise_px = 1.0;
  const Scene scene = MakeScene(options);
  const auto a = EstimateAbsolutePose(scene.pixels, scene.world, scene.camera, AbsolutePoseOptions());
  const auto b = EstimateAbsolutePose(scene.pixels, scene.world, scene.camera, AbsolutePoseOptions());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->cam_from_world.rotation, b->cam_from_world.rotation);
  EXPECT_EQ(a->cam_from_world.translation, b->cam_from_world.translation);
  EXPECT_EQ(a->inliers, b->inliers);
}

TEST(EstimateAbsolutePose, FewerThanFourPointsIsAClearFailure) {
  SceneOptions options;
  options.num_points = 3;
  const Scene scene = MakeScene(options);
  AbsolutePoseOptions pose_options;
  pose_options.min_inliers = 4;
  const Result<AbsolutePoseResult> result = EstimateAbsolutePose(scene.pixels, scene.world, scene.camera, pose_options);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->outcome, AbsolutePoseResult::Outcome::kTooFewCorrespondences);
  EXPECT_EQ(result->reason, "3 usable correspondences (of 3), need at least 4");
  // The default min_inliers (12) is the bar too.
  const auto defaults = EstimateAbsolutePose(scene.pixels, scene.world, scene.camera, AbsolutePoseOptions());
  ASSERT_TRUE(defaults.ok());
  EXPECT_EQ(defaults->reason, "3 usable correspondences (of 3), need at least 12");
  const auto empty = EstimateAbsolutePose({}, {}, scene.camera, AbsolutePoseOptions());
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(empty->outcome, AbsolutePoseResult::Outcome::kTooFewCorrespondences);
}

TEST(EstimateAbsolutePose, CollinearWorldPointsGiveNoModel) {
  const RadialCamera camera{800.0, 512.0, 384.0};
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  for (int i = 0; i < 30; ++i) {
    const Eigen::Vector3d X(-1.5 + 0.1 * i, 0.3 - 0.05 * i, 5.0 + 0.02 * i);
    world.push_back(X);
    pixels.push_back(camera.PixelFromNormalised(X.hnormalized()));
  }
  const Result<AbsolutePoseResult> result = EstimateAbsolutePose(pixels, world, camera, AbsolutePoseOptions());
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->outcome, AbsolutePoseResult::Outcome::kNoModel);
  EXPECT_NE(result->reason.find("degenerate"), std::string::npos) << result->reason;
}

// A camera with a pixel aspect ratio (fy = a f): its exact projections give the exact pose.
TEST(EstimateAbsolutePose, HonoursTheAspectRatio) {
  RadialCamera camera{800.0, 512.0, 384.0, -0.1, 0.02};
  camera.aspect = 1.05;
  SplitMix64 rng(12);
  const Eigen::Matrix3d R = RandomRotation(&rng, 0.5);
  const Eigen::Vector3d t(0.2, -0.1, 0.3);
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector2d p(rng.Uniform(-0.5, 0.5), rng.Uniform(-0.4, 0.4));
    const Eigen::Vector3d X_cam = rng.Uniform(3.0, 8.0) * p.homogeneous();
    world.push_back(R.transpose() * (X_cam - t));
    pixels.push_back(camera.PixelFromNormalised(p));
  }
  const Result<AbsolutePoseResult> result = EstimateAbsolutePose(pixels, world, camera, AbsolutePoseOptions());
  ASSERT_TRUE(result.ok());
  ASSERT_TRUE(result->success()) << result->reason;
  EXPECT_EQ(result->num_inliers, 60);
  EXPECT_LT((result->cam_from_world.rotation - R).norm(), 1e-8);
  EXPECT_LT((result->cam_from_world.translation - t).norm(), 1e-8);
  EXPECT_LT(result->mean_inlier_error_px, 1e-6);
}

TEST(EstimateAbsolutePose, PointsBehindTheCameraGiveNoPose) {
  // Observations of points behind the camera: the mirrored structure is no rigid motion of them.
  const RadialCamera camera{800.0, 512.0, 384.0};
  SplitMix64 rng(11);
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector2d p(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.45, 0.45));
    world.push_back(-rng.Uniform(3.0, 8.0) * p.homogeneous());
    pixels.push_back(camera.PixelFromNormalised(p));
  }
  const Result<AbsolutePoseResult> result = EstimateAbsolutePose(pixels, world, camera, AbsolutePoseOptions());
  ASSERT_TRUE(result.ok());
  EXPECT_FALSE(result->success());
  EXPECT_FALSE(result->reason.empty());
  EXPECT_LT(result->num_inliers, 12);
}

TEST(EstimateAbsolutePose, NonFiniteCorrespondencesAreNeverInliers) {
  SceneOptions options;
  options.noise_px = 0.3;
  Scene scene = MakeScene(options);
  scene.pixels[3] = Eigen::Vector2d(std::nan(""), 1.0);
  scene.world[7] = Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0, 0);
  const Result<AbsolutePoseResult> result =
      EstimateAbsolutePose(scene.pixels, scene.world, scene.camera, AbsolutePoseOptions());
  ASSERT_TRUE(result.ok());
  ASSERT_TRUE(result->success()) << result->reason;
  EXPECT_EQ(result->num_inliers, options.num_points - 2);
  EXPECT_EQ(std::count(result->inliers.begin(), result->inliers.end(), 3), 0);
  EXPECT_EQ(std::count(result->inliers.begin(), result->inliers.end(), 7), 0);
}

TEST(EstimateAbsolutePose, InvalidInputIsAnError) {
  const RadialCamera camera{800.0, 512.0, 384.0};
  const std::vector<Eigen::Vector2d> pixels(5, Eigen::Vector2d(1, 2));
  const std::vector<Eigen::Vector3d> world(4, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(EstimateAbsolutePose(pixels, world, camera, AbsolutePoseOptions()).status().code(),
            StatusCode::kInvalidArgument);
  AbsolutePoseOptions options;
  options.min_inliers = 3;
  const std::vector<Eigen::Vector3d> five(5, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(EstimateAbsolutePose(pixels, five, camera, options).status().code(), StatusCode::kInvalidArgument);
  const RadialCamera bad{0.0, 512.0, 384.0};
  EXPECT_EQ(EstimateAbsolutePose(pixels, five, bad, AbsolutePoseOptions()).status().code(),
            StatusCode::kInvalidArgument);
  options = AbsolutePoseOptions();
  options.max_error_px = -1.0;
  EXPECT_FALSE(options.Check().ok());
  options = AbsolutePoseOptions();
  options.refinement.loss_scale_px = 0.0;
  EXPECT_FALSE(options.Check().ok());
  options = AbsolutePoseOptions();
  options.ransac.confidence = 1.0;
  EXPECT_FALSE(options.Check().ok());
}

TEST(EstimateAbsolutePoseUnknownFocal, RecoversFocalWithinOnePercent) {
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE(seed);
    SceneOptions options;
    options.num_points = 300;
    options.outlier_fraction = 0.3;
    options.noise_px = 0.5;
    options.focal = 1100.0;
    options.seed = seed;
    const Scene scene = MakeScene(options);
    RadialCamera prior = scene.camera;
    prior.focal = 800.0;
    for (bool refine : {false, true}) {
      AbsolutePoseOptions pose_options;
      pose_options.refine = refine;
      const Result<AbsolutePoseResult> result =
          EstimateAbsolutePoseUnknownFocal(scene.pixels, scene.world, prior, pose_options);
      ASSERT_TRUE(result.ok());
      ASSERT_TRUE(result->success()) << result->reason;
      EXPECT_NEAR(result->focal, options.focal, 0.01 * options.focal) << "refine " << refine;
      EXPECT_LT(RotationDifference(result->cam_from_world.rotation, scene.R).norm(), 1e-2);
      if (refine) {
        EXPECT_EQ(result->num_inliers, scene.num_inliers());
        EXPECT_LT(PoseErrorMahalanobis(scene, options.noise_px, result->cam_from_world.rotation,
                                       result->cam_from_world.translation, result->focal, true),
                  24.3);  // chi^2_7, 99.9 %
      }
    }
  }
}

TEST(EstimateAbsolutePoseUnknownFocal, CoplanarPointsGiveNoModel) {
  const RadialCamera camera{800.0, 512.0, 384.0};
  SplitMix64 rng(12);
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d X(rng.Uniform(-2, 2), rng.Uniform(-2, 2), 0.0);
    world.push_back(X);
    pixels.push_back(camera.PixelFromNormalised((X + Eigen::Vector3d(0, 0, 6)).hnormalized()));
  }
  const auto result = EstimateAbsolutePoseUnknownFocal(pixels, world, camera, AbsolutePoseOptions());
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->outcome, AbsolutePoseResult::Outcome::kNoModel);
  EXPECT_FALSE(result->reason.empty());
  // With the focal known, P3P registers the planar scene.
  const auto known = EstimateAbsolutePose(pixels, world, camera, AbsolutePoseOptions());
  ASSERT_TRUE(known.ok());
  EXPECT_TRUE(known->success()) << known->reason;
}

// ---------------------------------------------------------------------------------------------
// Refinement

struct Perturbed {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  RadialCamera camera;
};

Perturbed Perturb(const Scene& scene, double angle, double shift, double focal_factor) {
  SplitMix64 rng(99);
  Perturbed p;
  p.R = Eigen::AngleAxisd(angle, Eigen::Vector3d(rng.Gaussian(), rng.Gaussian(), rng.Gaussian()).normalized()) *
        scene.R;
  p.t = scene.t + shift * Eigen::Vector3d(rng.Gaussian(), rng.Gaussian(), rng.Gaussian()).normalized();
  p.camera = scene.camera;
  p.camera.focal *= focal_factor;
  return p;
}

std::vector<int> AllIndices(const Scene& scene) {
  std::vector<int> indices;
  for (size_t i = 0; i < scene.world.size(); ++i) {
    if (scene.is_inlier[i]) indices.push_back(static_cast<int>(i));
  }
  return indices;
}

TEST(RefineAbsolutePose, ConvergesWithFocalAndDistortionOnExactData) {
  SceneOptions options;
  options.focal = 900.0;
  options.k1 = -0.12;
  options.k2 = 0.03;
  const Scene scene = MakeScene(options);
  for (auto loss : {PoseRefinementOptions::Loss::kTrivial, PoseRefinementOptions::Loss::kHuber,
                    PoseRefinementOptions::Loss::kCauchy}) {
    SCOPED_TRACE(static_cast<int>(loss));
    Perturbed start = Perturb(scene, 3.0 * kPi / 180, 0.2, 1.1);
    PoseRefinementOptions refine;
    refine.loss = loss;
    refine.refine_focal = true;
    const Result<NormalLmSummary> summary = RefineAbsolutePose(scene.exact_pixels, scene.world, AllIndices(scene),
                                                               refine, &start.camera, &start.R, &start.t);
    ASSERT_TRUE(summary.ok()) << summary.status().ToString();
    EXPECT_TRUE(summary->converged()) << TerminationName(summary->termination);
    EXPECT_LT(summary->final_cost, 1e-16);
    EXPECT_LT(RotationDifference(start.R, scene.R).norm(), 1e-10);
    EXPECT_LT((start.t - scene.t).norm(), 1e-9);
    EXPECT_NEAR(start.camera.focal, scene.camera.focal, 1e-7);
    EXPECT_EQ(start.camera.k1, options.k1);  // distortion is modelled, not refined
  }
}

TEST(RefineAbsolutePose, NoisyDataWithinCramerRaoBound) {
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE(seed);
    SceneOptions options;
    options.focal = 700.0;
    options.k1 = 0.1;
    options.k2 = -0.02;
    options.noise_px = 0.7;
    options.seed = seed;
    const Scene scene = MakeScene(options);
    for (bool with_focal : {false, true}) {
      Perturbed start = Perturb(scene, 1.0 * kPi / 180, 0.1, with_focal ? 0.95 : 1.0);
      PoseRefinementOptions refine;
      refine.refine_focal = with_focal;
      const auto summary =
          RefineAbsolutePose(scene.pixels, scene.world, AllIndices(scene), refine, &start.camera, &start.R, &start.t);
      ASSERT_TRUE(summary.ok());
      EXPECT_TRUE(summary->converged());
      EXPECT_LT(PoseErrorMahalanobis(scene, options.noise_px, start.R, start.t, start.camera.focal, with_focal),
                with_focal ? 24.3 : 22.5);
    }
  }
}

TEST(RefineAbsolutePose, GrossOutliersAmongTheInliersAreDownWeighted) {
  SceneOptions options;
  options.noise_px = 0.5;
  Scene scene = MakeScene(options);
  for (int i = 0; i < options.num_points; i += 25) scene.pixels[i] += Eigen::Vector2d(3.0, -2.5);  // ~8 sigma
  std::vector<int> all(options.num_points);
  for (int i = 0; i < options.num_points; ++i) all[i] = i;
  Perturbed huber = Perturb(scene, 0.5 * kPi / 180, 0.05, 1.0);
  Perturbed trivial = huber;
  PoseRefinementOptions refine;
  ASSERT_TRUE(RefineAbsolutePose(scene.pixels, scene.world, all, refine, &huber.camera, &huber.R, &huber.t).ok());
  refine.loss = PoseRefinementOptions::Loss::kTrivial;
  ASSERT_TRUE(RefineAbsolutePose(scene.pixels, scene.world, all, refine, &trivial.camera, &trivial.R, &trivial.t).ok());
  EXPECT_LT(RotationDifference(huber.R, scene.R).norm(), RotationDifference(trivial.R, scene.R).norm());
}

TEST(RefineAbsolutePose, InvalidInputIsAnError) {
  const Scene scene = MakeScene(SceneOptions());
  Perturbed start = Perturb(scene, 0.01, 0.01, 1.0);
  const PoseRefinementOptions refine;
  EXPECT_EQ(RefineAbsolutePose(scene.pixels, scene.world, {0, 1, 2}, refine, &start.camera, &start.R, &start.t)
                .status()
                .code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(RefineAbsolutePose(scene.pixels, scene.world, {0, 1, 2, 1000}, refine, &start.camera, &start.R, &start.t)
                .status()
                .code(),
            StatusCode::kInvalidArgument);
  std::vector<Eigen::Vector3d> world = scene.world;
  world[2] = scene.R.transpose() * (Eigen::Vector3d(0, 0, -1) - scene.t);  // behind the camera
  const auto behind = RefineAbsolutePose(scene.pixels, world, {0, 1, 2, 3}, refine, &start.camera, &start.R, &start.t);
  EXPECT_EQ(behind.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(behind.status().message().find("behind"), std::string::npos);
}

}  // namespace
}  // namespace reconar
