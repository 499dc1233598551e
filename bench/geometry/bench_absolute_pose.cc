// Absolute pose speed and accuracy on synthetic 2D-3D correspondences with known truth, one
// thread, side by side in the same process with OpenCV when it is found at build time.
//   bench_absolute_pose [--scenes N]
// Scenes (N of each, seeded): a 640x480 camera of focal 800 px, points at depths 3..8 (or a
// nearly flat patch 4..4.08 m in a 7 by 5 degree cone), 1 px Gaussian noise, a fraction of the
// correspondences replaced by uniformly random pixels. On every scene, alternating:
//  - ours: EstimateAbsolutePose with its defaults (P3P LO-RANSAC, the local step Levenberg-Marquardt
//    from the best pose, with the LO's inner RANSAC; then the robust refinement);
//  - ours without the LO's inner RANSAC (RansacOptions::local_inner_samples = 0), to show what it
//    costs;
//  - OpenCV: cv::solvePnPRansac with SOLVEPNP_P3P (4 px, confidence 0.999, 10000 iterations), then
//    cv::solvePnPRefineLM on its inliers.
// Reported per method: median and 90th percentile thread CPU time, scenes with a pose of at
// least 12 inliers, the fraction of the true inliers within 4 px of the pose, and the median
// rotation (degrees) and centre (fraction of the mean depth) errors against the truth.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "bench/common/thread_cpu_time.h"
#include "core/base/prng.h"
#include "core/geometry/absolute_pose.h"

#if defined(RECONAR_BENCH_WITH_OPENCV)
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#endif

namespace {

using reconar::AbsolutePoseOptions;
using reconar::RadialCamera;
using reconar::SplitMix64;

constexpr double kMaxErrorPx = 4.0;
constexpr int kMinInliers = 12;
constexpr double kPi = 3.14159265358979323846;

struct SceneConfig {
  const char* name;
  int num_points;
  double outlier_fraction;
  bool flat_narrow;
};

struct Scene {
  RadialCamera camera{800.0, 320.0, 240.0, 0.0, 0.0};
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  double mean_depth = 0.0;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  std::vector<char> is_inlier;
};

Scene MakeScene(const SceneConfig& config, uint64_t seed) {
  SplitMix64 rng(seed);
  Scene scene;
  const Eigen::Vector3d axis(rng.Gaussian(), rng.Gaussian(), rng.Gaussian());
  scene.R = Eigen::AngleAxisd(rng.Uniform(0.0, kPi), axis.normalized()).toRotationMatrix();
  scene.t = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
  const double view = config.flat_narrow ? 0.1 : 1.0;
  const double min_depth = config.flat_narrow ? 4.0 : 3.0, max_depth = config.flat_narrow ? 4.08 : 8.0;
  for (int i = 0; i < config.num_points; ++i) {
    const Eigen::Vector2d p(view * rng.Uniform(-0.4, 0.4), view * rng.Uniform(-0.3, 0.3));
    const double depth = rng.Uniform(min_depth, max_depth);
    scene.mean_depth += depth / config.num_points;
    scene.world.push_back(scene.R.transpose() * (depth * p.homogeneous() - scene.t));
    Eigen::Vector2d pixel = scene.camera.PixelFromNormalised(p) + Eigen::Vector2d(rng.Gaussian(), rng.Gaussian());
    const bool inlier = rng.Uniform(0.0, 1.0) >= config.outlier_fraction;
    if (!inlier) pixel = Eigen::Vector2d(rng.Uniform(0.0, 640.0), rng.Uniform(0.0, 480.0));
    scene.pixels.push_back(pixel);
    scene.is_inlier.push_back(inlier ? 1 : 0);
  }
  return scene;
}

double ThreadCpuMs() { return 1e3 * reconar::bench::ThreadCpuSeconds(); }

struct Pose {
  bool ok = false;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
};

struct Tally {
  std::vector<double> ms, rotation_deg, centre_error;
  int posed = 0;
  long true_inliers_found = 0, true_inliers = 0;

  void Add(const Scene& scene, const Pose& pose, double ms_taken) {
    ms.push_back(ms_taken);
    for (size_t i = 0; i < scene.world.size(); ++i) true_inliers += scene.is_inlier[i];
    if (!pose.ok) return;
    int inliers = 0;
    for (size_t i = 0; i < scene.world.size(); ++i) {
      const bool within = reconar::SquaredPixelError(scene.camera, pose.R, pose.t, scene.world[i], scene.pixels[i]) <
                          kMaxErrorPx * kMaxErrorPx;
      inliers += within;
      true_inliers_found += within && scene.is_inlier[i];
    }
    if (inliers < kMinInliers) return;
    ++posed;
    rotation_deg.push_back(Eigen::AngleAxisd(pose.R * scene.R.transpose()).angle() * 180.0 / kPi);
    const Eigen::Vector3d centre = -pose.R.transpose() * pose.t, true_centre = -scene.R.transpose() * scene.t;
    centre_error.push_back((centre - true_centre).norm() / scene.mean_depth);
  }
};

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(q * static_cast<double>(values.size() - 1))];
}

Pose Ours(const Scene& scene, bool inner_ransac) {
  AbsolutePoseOptions options;
  options.min_inliers = kMinInliers;
  options.max_error_px = kMaxErrorPx;
  if (!inner_ransac) options.ransac.local_inner_samples = 0;
  const auto result = reconar::EstimateAbsolutePose(scene.pixels, scene.world, scene.camera, options);
  Pose pose;
  if (!result.ok() || !result->success()) return pose;
  pose.ok = true;
  pose.R = result->cam_from_world.rotation;
  pose.t = result->cam_from_world.translation;
  return pose;
}

#if defined(RECONAR_BENCH_WITH_OPENCV)
Pose OpenCv(const Scene& scene) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < scene.world.size(); ++i) {
    object.emplace_back(scene.world[i].x(), scene.world[i].y(), scene.world[i].z());
    image.emplace_back(scene.pixels[i].x(), scene.pixels[i].y());
  }
  const cv::Matx33d K(scene.camera.focal, 0, scene.camera.cx, 0, scene.camera.fy(), scene.camera.cy, 0, 0, 1);
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  Pose pose;
  if (!cv::solvePnPRansac(object, image, K, cv::noArray(), rvec, tvec, false, 10000, static_cast<float>(kMaxErrorPx),
                          0.999, inliers, cv::SOLVEPNP_P3P) ||
      static_cast<int>(inliers.size()) < 4) {
    return pose;
  }
  std::vector<cv::Point3d> object_inliers;
  std::vector<cv::Point2d> image_inliers;
  for (int i : inliers) {
    object_inliers.push_back(object[static_cast<size_t>(i)]);
    image_inliers.push_back(image[static_cast<size_t>(i)]);
  }
  cv::solvePnPRefineLM(object_inliers, image_inliers, K, cv::noArray(), rvec, tvec);
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  pose.ok = true;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.R(r, c) = R.at<double>(r, c);
    pose.t(r) = tvec.at<double>(r);
  }
  return pose;
}
#endif

void Print(const char* method, const Tally& tally, int scenes) {
  std::printf(
      "  %-26s median %7.3f ms  p90 %7.3f ms  posed %3d/%d  true inliers found %6.2f %%  "
      "rotation median %.4f deg  centre median %.5f of depth\n",
      method, Quantile(tally.ms, 0.5), Quantile(tally.ms, 0.9), tally.posed, scenes,
      100.0 * static_cast<double>(tally.true_inliers_found) / static_cast<double>(std::max(1L, tally.true_inliers)),
      Quantile(tally.rotation_deg, 0.5), Quantile(tally.centre_error, 0.5));
}

}  // namespace

int main(int argc, char** argv) {
  int scenes = 200;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--scenes=", 9) == 0) {
      scenes = std::atoi(argv[i] + 9);
    } else if (std::strcmp(argv[i], "--scenes") == 0 && i + 1 < argc) {
      scenes = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: bench_absolute_pose [--scenes N]\n");
      return 2;
    }
  }
  if (scenes < 1) {
    std::fprintf(stderr, "bench_absolute_pose: --scenes must be at least 1\n");
    return 2;
  }
  const SceneConfig configs[] = {
      {"600 points, 30 % outliers", 600, 0.3, false},
      {"100 points, 50 % outliers", 100, 0.5, false},
      {"300 points, 80 % outliers", 300, 0.8, false},
      {"40 points of a nearly flat patch in a 7x5 degree cone, 25 % outliers", 40, 0.25, true},
  };
  std::printf("bench_absolute_pose: %d scenes each, 1 px noise, 4 px threshold, thread CPU time\n", scenes);
  for (const SceneConfig& config : configs) {
    Tally ours, ours_without_inner, opencv;
    for (int s = 0; s < scenes; ++s) {
      const Scene scene = MakeScene(config, static_cast<uint64_t>(s + 1));
      double start = ThreadCpuMs();
      const Pose a = Ours(scene, true);
      ours.Add(scene, a, ThreadCpuMs() - start);
      start = ThreadCpuMs();
      const Pose b = Ours(scene, false);
      ours_without_inner.Add(scene, b, ThreadCpuMs() - start);
#if defined(RECONAR_BENCH_WITH_OPENCV)
      start = ThreadCpuMs();
      const Pose c = OpenCv(scene);
      opencv.Add(scene, c, ThreadCpuMs() - start);
#endif
    }
    std::printf("%s:\n", config.name);
    Print("reconar (default)", ours, scenes);
    Print("reconar, no inner RANSAC", ours_without_inner, scenes);
#if defined(RECONAR_BENCH_WITH_OPENCV)
    Print("OpenCV P3P RANSAC + LM", opencv, scenes);
    std::printf("  ratio reconar / OpenCV: median time %.3f\n", Quantile(ours.ms, 0.5) / Quantile(opencv.ms, 0.5));
#endif
  }
  return 0;
}
