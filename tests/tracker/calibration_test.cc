// Synthetic tests of CalibrateIntrinsics (Zhang closed form + joint LM) and the intrinsics file.
// Tags of known pose are projected with known intrinsics (incl. k1, k2) and Gaussian corner noise;
// the bounds come from the noise through the reported standard deviations.
#include "tracker/calibration.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/base/atomic_file.h"

namespace reconar {
namespace {

constexpr double kTagSize = 0.127;
constexpr int kWidth = 816;
constexpr int kHeight = 612;

CameraIntrinsics TrueIntrinsics() {
  CameraIntrinsics k;
  k.width = kWidth;
  k.height = kHeight;
  k.fx = 770.0;
  k.fy = 762.0;
  k.cx = 401.3;
  k.cy = 298.6;
  k.k1 = -0.12;
  k.k2 = 0.09;
  return k;
}

struct SceneOptions {
  int num_images = 12;
  int tags_per_image = 6;
  double min_tilt_deg = 15.0;  // angle between the tag normal and the direction to the camera
  double max_tilt_deg = 55.0;
  double noise_px = 0.3;  // Gaussian sigma per coordinate
  bool parallel_to_image = false;  // tags face along the optical axis instead of the viewing ray
  unsigned seed = 1;
};

// Each image sees `tags_per_image` tags at 0.6-1.6 m, spread over the field of view, each tilted
// by a random angle in [min_tilt, max_tilt] about a random in-plane axis. Corners are in the
// program's pixel convention, as TagDetector reports them.
CalibrationObservations MakeScene(const CameraIntrinsics& k, const SceneOptions& options,
                                  std::vector<Rigid3>* cam_from_tags = nullptr) {
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, options.noise_px);
  const double h = 0.5 * kTagSize;
  const Eigen::Vector3d tag_corners[4] = {{-h, -h, 0.0}, {h, -h, 0.0}, {h, h, 0.0}, {-h, h, 0.0}};
  CalibrationObservations observations;
  observations.tag_size = kTagSize;
  int id = 0;
  for (int i = 0; i < options.num_images; ++i) {
    CalibrationImage image;
    image.name = "synthetic_" + std::to_string(i);
    image.width = kWidth;
    image.height = kHeight;
    while (static_cast<int>(image.tags.size()) < options.tags_per_image) {
      // Tag centre: a pixel in the central 80 % of the image at a random depth.
      const Eigen::Vector2d pixel(kWidth * (0.1 + 0.8 * uniform(rng)), kHeight * (0.1 + 0.8 * uniform(rng)));
      const double depth = 0.6 + 1.0 * uniform(rng);
      const Eigen::Vector3d centre = depth * Eigen::Vector3d((pixel.x() - k.cx) / k.fx, (pixel.y() - k.cy) / k.fy, 1.0);
      // Facing the camera (tag z toward it), then tilted and spun in-plane.
      const Eigen::Vector3d z = options.parallel_to_image ? Eigen::Vector3d(-Eigen::Vector3d::UnitZ()) : Eigen::Vector3d(-centre.normalized());
      const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
      Eigen::Matrix3d facing;
      facing << x, z.cross(x), z;
      const double tilt = (options.min_tilt_deg + (options.max_tilt_deg - options.min_tilt_deg) * uniform(rng)) * M_PI / 180.0;
      const double axis_angle = 2.0 * M_PI * uniform(rng);
      const Eigen::Vector3d axis(std::cos(axis_angle), std::sin(axis_angle), 0.0);
      const double spin = (uniform(rng) - 0.5) * 0.6;
      Rigid3 cam_from_tag;
      cam_from_tag.rotation = facing * Eigen::AngleAxisd(tilt, axis).toRotationMatrix() *
                              Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      cam_from_tag.translation = centre;
      TagCorners tag;
      tag.tag_id = id++ % 20;
      bool inside = true;
      for (int c = 0; c < 4; ++c) {
        const Eigen::Vector2d p = k.Project(cam_from_tag * tag_corners[c]);
        inside = inside && p.x() > 0.0 && p.y() > 0.0 && p.x() < kWidth - 1 && p.y() < kHeight - 1;
        tag.corners[c] = p + Eigen::Vector2d(noise(rng), noise(rng));
      }
      if (!inside) continue;
      image.tags.push_back(tag);
      if (cam_from_tags != nullptr) cam_from_tags->push_back(cam_from_tag);
    }
    observations.images.push_back(image);
  }
  return observations;
}

void ExpectWithin(const CalibrationReport& report, const CameraIntrinsics& truth, double sigmas) {
  const double values[6] = {report.intrinsics.fx, report.intrinsics.fy, report.intrinsics.cx,
                            report.intrinsics.cy, report.intrinsics.k1, report.intrinsics.k2};
  const double expected[6] = {truth.fx, truth.fy, truth.cx, truth.cy, truth.k1, truth.k2};
  const char* names[6] = {"fx", "fy", "cx", "cy", "k1", "k2"};
  for (int j = 0; j < 6; ++j) {
    EXPECT_GT(report.stddev[j], 0.0) << names[j];
    EXPECT_NEAR(values[j], expected[j], sigmas * report.stddev[j]) << names[j];
  }
}

void Print(const char* label, const CalibrationReport& r) {
  std::printf("%s: fx %.3f fy %.3f cx %.3f cy %.3f k1 %.5f k2 %.5f | sd %.3f %.3f %.3f %.3f %.5f %.5f | rms %.4f "
              "(initial %.3f) targets %d corners %d iterations %d\n",
              label, r.intrinsics.fx, r.intrinsics.fy, r.intrinsics.cx, r.intrinsics.cy, r.intrinsics.k1,
              r.intrinsics.k2, r.stddev[0], r.stddev[1], r.stddev[2], r.stddev[3], r.stddev[4], r.stddev[5],
              r.rms_px, r.initial_rms_px, r.num_targets, r.num_corners, r.iterations);
}

TEST(CalibrationTest, NoiseFreeRecoversExactly) {
  SceneOptions scene;
  scene.noise_px = 0.0;
  const CameraIntrinsics truth = TrueIntrinsics();
  Result<CalibrationReport> report = CalibrateIntrinsics(MakeScene(truth, scene), CalibrationOptions());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  Print("noise-free", *report);
  EXPECT_TRUE(report->converged);
  EXPECT_LT(report->rms_px, 1e-6);
  EXPECT_NEAR(report->intrinsics.fx, truth.fx, 1e-5);
  EXPECT_NEAR(report->intrinsics.fy, truth.fy, 1e-5);
  EXPECT_NEAR(report->intrinsics.cx, truth.cx, 1e-5);
  EXPECT_NEAR(report->intrinsics.cy, truth.cy, 1e-5);
  EXPECT_NEAR(report->intrinsics.k1, truth.k1, 1e-8);
  EXPECT_NEAR(report->intrinsics.k2, truth.k2, 1e-8);
  EXPECT_EQ(report->num_targets, scene.num_images * scene.tags_per_image);
  EXPECT_EQ(report->num_corners, 4 * scene.num_images * scene.tags_per_image);
  EXPECT_TRUE(report->principal_point_from_closed_form);
}

TEST(CalibrationTest, NoisyCornersWithinReportedUncertainty) {
  // With 0.3 px Gaussian noise the estimate is unbiased to first order and its error is
  // N(0, sigma) with the sigma of the covariance: 4 sigma fails with probability ~6e-5 per value.
  // The residual RMS (of the 2D corner error) estimates the noise: with N corners (2N residuals)
  // and p parameters it is 0.3 * sqrt(2 (2N - p) / 2N), within 10 % (chi-square with ~140 degrees of
  // freedom has a relative spread of ~6 % in the RMS).
  const CameraIntrinsics truth = TrueIntrinsics();
  for (unsigned seed : {1u, 2u, 3u}) {
    SceneOptions scene;
    scene.seed = seed;
    Result<CalibrationReport> report = CalibrateIntrinsics(MakeScene(truth, scene), CalibrationOptions());
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    Print("noisy", *report);
    EXPECT_TRUE(report->converged);
    ExpectWithin(*report, truth, 4.0);
    const double n = 2.0 * report->num_corners;
    const double p = 6.0 + 6.0 * report->num_targets;
    EXPECT_NEAR(report->rms_px, scene.noise_px * std::sqrt(2.0 * (n - p) / n), 0.1 * scene.noise_px);
    // Single small tags constrain the focal only through their foreshortening: ~1 % here.
    EXPECT_LT(report->stddev[0], 0.02 * truth.fx);
    ASSERT_EQ(report->image_rms_px.size(), static_cast<size_t>(scene.num_images));
    for (double rms : report->image_rms_px) EXPECT_GT(rms, 0.0);
  }
}

TEST(CalibrationTest, PosesMatchTruthOnNoiseFreeData) {
  SceneOptions scene;
  scene.noise_px = 0.0;
  std::vector<Rigid3> truth_poses;
  const CalibrationObservations observations = MakeScene(TrueIntrinsics(), scene, &truth_poses);
  Result<CalibrationReport> report = CalibrateIntrinsics(observations, CalibrationOptions());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_EQ(report->targets.size(), truth_poses.size());
  for (size_t t = 0; t < truth_poses.size(); ++t) {
    EXPECT_LT(RotationAngle(report->targets[t].cam_from_target.rotation, truth_poses[t].rotation), 1e-7);
    EXPECT_LT((report->targets[t].cam_from_target.translation - truth_poses[t].translation).norm(), 1e-7);
  }
}

TEST(CalibrationTest, FixedPrincipalPointAndAspectAndNoDistortion) {
  CameraIntrinsics truth = TrueIntrinsics();
  truth.cx = 0.5 * (kWidth - 1);
  truth.cy = 0.5 * (kHeight - 1);
  truth.fy = truth.fx;
  truth.k1 = truth.k2 = 0.0;
  SceneOptions scene;
  scene.noise_px = 0.0;
  CalibrationOptions options;
  options.fix_principal_point = true;
  options.fix_aspect_ratio = true;
  options.estimate_k1 = options.estimate_k2 = false;
  Result<CalibrationReport> report = CalibrateIntrinsics(MakeScene(truth, scene), options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_NEAR(report->intrinsics.fx, truth.fx, 1e-5);
  EXPECT_EQ(report->intrinsics.fy, report->intrinsics.fx);
  EXPECT_EQ(report->intrinsics.cx, truth.cx);
  EXPECT_EQ(report->intrinsics.cy, truth.cy);
  EXPECT_EQ(report->intrinsics.k1, 0.0);
  EXPECT_EQ(report->intrinsics.k2, 0.0);
  EXPECT_EQ(report->stddev[2], 0.0);
  EXPECT_EQ(report->stddev[4], 0.0);
  EXPECT_EQ(report->stddev[1], report->stddev[0]);
}

TEST(CalibrationTest, FewViewsStartFromTheImageCentre) {
  // Two tilted tags: too few for the principal point in closed form, enough for the focal.
  SceneOptions scene;
  scene.num_images = 1;
  scene.tags_per_image = 3;
  scene.noise_px = 0.0;
  CalibrationOptions options;
  options.estimate_k1 = options.estimate_k2 = false;
  CameraIntrinsics truth = TrueIntrinsics();
  truth.k1 = truth.k2 = 0.0;
  Result<CalibrationReport> report = CalibrateIntrinsics(MakeScene(truth, scene), options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_FALSE(report->principal_point_from_closed_form);
  EXPECT_NEAR(report->intrinsics.fx, truth.fx, 1e-4);
}

TEST(CalibrationTest, FrontoParallelTagsAreDegenerate) {
  SceneOptions scene;
  scene.min_tilt_deg = 0.0;
  scene.max_tilt_deg = 0.5;
  scene.parallel_to_image = true;
  scene.noise_px = 0.2;
  Result<CalibrationReport> report = CalibrateIntrinsics(MakeScene(TrueIntrinsics(), scene), CalibrationOptions());
  if (report.ok()) Print("fronto-parallel", *report);
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(report.status().message().find("degenerate"), std::string::npos) << report.status().message();
  std::printf("%s\n", report.status().ToString().c_str());
}

TEST(CalibrationTest, ExactlyFrontoParallelTagsFailTheConstraintRank) {
  SceneOptions scene;
  scene.min_tilt_deg = scene.max_tilt_deg = 0.0;
  scene.parallel_to_image = true;
  scene.noise_px = 0.0;
  CameraIntrinsics pinhole = TrueIntrinsics();  // distortion would make the homographies projective
  pinhole.k1 = pinhole.k2 = 0.0;
  Result<CalibrationReport> report = CalibrateIntrinsics(MakeScene(pinhole, scene), CalibrationOptions());
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(report.status().message().find("nearly fronto-parallel"), std::string::npos) << report.status().message();
}

TEST(CalibrationTest, TooFewTargets) {
  SceneOptions scene;
  scene.num_images = 1;
  scene.tags_per_image = 2;
  Result<CalibrationReport> report = CalibrateIntrinsics(MakeScene(TrueIntrinsics(), scene), CalibrationOptions());
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(report.status().message().find("too few"), std::string::npos);
  CalibrationObservations empty;
  empty.tag_size = kTagSize;
  EXPECT_EQ(CalibrateIntrinsics(empty, CalibrationOptions()).status().code(), StatusCode::kFailedPrecondition);
}

TEST(CalibrationTest, BadInputIsInvalidArgument) {
  const CalibrationObservations good = MakeScene(TrueIntrinsics(), SceneOptions());
  CalibrationObservations bad = good;
  bad.tag_size = 0.0;
  EXPECT_EQ(CalibrateIntrinsics(bad, CalibrationOptions()).status().code(), StatusCode::kInvalidArgument);
  bad = good;
  bad.images[1].width = 640;
  EXPECT_EQ(CalibrateIntrinsics(bad, CalibrationOptions()).status().code(), StatusCode::kInvalidArgument);
  bad = good;
  bad.images[2].tags[0].corners[1].x() = std::nan("");
  EXPECT_EQ(CalibrateIntrinsics(bad, CalibrationOptions()).status().code(), StatusCode::kInvalidArgument);
  CalibrationOptions options;
  options.estimate_k1 = false;  // k2 without k1
  EXPECT_EQ(CalibrateIntrinsics(good, options).status().code(), StatusCode::kInvalidArgument);
}

TEST(CalibrationTest, OutlierCornersDoNotRuinIt) {
  // 5 % of the tags get one corner displaced by 15-30 px (a bad detection). The Huber loss keeps
  // their influence bounded: the estimate stays within 4 sigma of the truth; the plain least
  // squares estimate of the same data is pulled far away.
  const CameraIntrinsics truth = TrueIntrinsics();
  SceneOptions scene;
  CalibrationObservations observations = MakeScene(truth, scene);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int corrupted = 0;
  int index = 0;
  for (CalibrationImage& image : observations.images) {
    for (TagCorners& tag : image.tags) {
      if (index++ % 20 != 3) continue;
      const double angle = 2.0 * M_PI * uniform(rng);
      tag.corners[corrupted % 4] += (15.0 + 15.0 * uniform(rng)) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      ++corrupted;
    }
  }
  ASSERT_GE(corrupted, 3);
  Result<CalibrationReport> robust = CalibrateIntrinsics(observations, CalibrationOptions());
  ASSERT_TRUE(robust.ok()) << robust.status().ToString();
  Print("outliers, Huber", *robust);
  EXPECT_TRUE(robust->converged);
  // The outlier-free sigma: the same scene without outliers.
  Result<CalibrationReport> clean = CalibrateIntrinsics(MakeScene(truth, scene), CalibrationOptions());
  ASSERT_TRUE(clean.ok());
  CalibrationReport judged = *robust;
  judged.stddev = clean->stddev;
  ExpectWithin(judged, truth, 4.0);

  CalibrationOptions plain;
  plain.loss.type = LossType::kTrivial;
  plain.max_relative_focal_stddev = 1.0;  // its sigma is inflated by the outliers; get the estimate
  Result<CalibrationReport> least_squares = CalibrateIntrinsics(observations, plain);
  ASSERT_TRUE(least_squares.ok()) << least_squares.status().ToString();
  Print("outliers, least squares", *least_squares);
  EXPECT_GT(std::abs(least_squares->intrinsics.fx - truth.fx), std::abs(robust->intrinsics.fx - truth.fx));
}

TEST(CalibrationTest, RigidLayoutSharesOneBoardPosePerImage) {
  // Six tags on two perpendicular walls; each image sees the whole board.
  // Mixed sizes: the layout's own size applies to its tags.
  TagLayout layout;
  std::map<int, Rigid3> board_from_tag;
  for (int id = 0; id < 6; ++id) {
    Rigid3 pose;
    if (id < 3) {
      pose.translation = Eigen::Vector3d(0.3 * id - 0.3, 0.0, 0.0);
    } else {
      pose.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
      pose.translation = Eigen::Vector3d(-0.5, 0.0, 0.2 + 0.3 * (id - 3));
    }
    board_from_tag[id] = pose;
    ASSERT_TRUE(layout.Add(LayoutTag{id, id % 2 == 0 ? kTagSize : 0.1, pose}).ok());
  }
  const CameraIntrinsics truth = TrueIntrinsics();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.3);
  const double h = 0.5 * kTagSize;
  const Eigen::Vector3d tag_corners[4] = {{-h, -h, 0.0}, {h, -h, 0.0}, {h, h, 0.0}, {-h, h, 0.0}};
  CalibrationObservations observations;
  observations.tag_size = kTagSize;
  observations.layout = layout;
  while (observations.images.size() < 8) {
    // Camera about 1.6 m from the board's corner region, looking at (-0.2, 0, 0.3) in the board frame.
    const Eigen::Vector3d target(-0.2, 0.0, 0.3);
    const Eigen::Vector3d eye = target + Eigen::Vector3d(0.9 + 0.3 * uniform(rng), 0.4 * uniform(rng), 1.2 + 0.2 * uniform(rng));
    const Eigen::Vector3d z = (target - eye).normalized();
    const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitY()).normalized();
    Eigen::Matrix3d board_from_cam_rotation;
    board_from_cam_rotation << x, z.cross(x), z;
    const Rigid3 cam_from_board = Rigid3{board_from_cam_rotation, eye}.Inverse();
    CalibrationImage image;
    image.name = "board_" + std::to_string(observations.images.size());
    image.width = kWidth;
    image.height = kHeight;
    bool inside = true;
    for (const auto& [id, pose] : board_from_tag) {
      TagCorners tag;
      tag.tag_id = id;
      for (int c = 0; c < 4; ++c) {
        const double scale = layout.Find(id)->size / kTagSize;
        const Eigen::Vector3d in_cam = cam_from_board * (pose * (scale * tag_corners[c]));
        const Eigen::Vector2d p = truth.Project(in_cam);
        inside = inside && in_cam.z() > 0.0 && p.x() > 0.0 && p.y() > 0.0 && p.x() < kWidth - 1 && p.y() < kHeight - 1;
        tag.corners[c] = p + Eigen::Vector2d(noise(rng), noise(rng));
      }
      image.tags.push_back(tag);
    }
    if (inside) observations.images.push_back(image);
  }
  Result<CalibrationReport> report = CalibrateIntrinsics(observations, CalibrationOptions());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  Print("layout", *report);
  EXPECT_EQ(report->num_targets, 8);
  for (const CalibrationTargetPose& target : report->targets) EXPECT_EQ(target.tag_id, -1);
  ExpectWithin(*report, truth, 4.0);
}

}  // namespace
}  // namespace reconar
