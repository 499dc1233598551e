#include "tests/support/sfm_evaluation.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <random>

namespace reconar::testing {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("reconar_sfm_evaluation_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Eigen::Matrix3d RandomRotation(std::mt19937* rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(*rng), normal(*rng), normal(*rng), normal(*rng)).normalized().toRotationMatrix();
}

TEST(SfmEvaluationTest, AlignSimilarityRecoversAKnownTransform) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-5.0, 5.0);
  Similarity3 truth;
  truth.scale = 0.37;
  truth.rotation = RandomRotation(&rng);
  truth.translation = Eigen::Vector3d(1.0, -2.0, 0.5);
  std::vector<Eigen::Vector3d> from, to;
  for (int i = 0; i < 10; ++i) {
    from.emplace_back(uniform(rng), uniform(rng), uniform(rng));
    to.push_back(truth.Apply(from.back()));
  }
  Result<Similarity3> found = AlignSimilarity(from, to);
  ASSERT_TRUE(found.ok()) << found.status().ToString();
  EXPECT_NEAR(found->scale, truth.scale, 1e-12);
  EXPECT_LT((found->rotation - truth.rotation).norm(), 1e-12);
  EXPECT_LT((found->translation - truth.translation).norm(), 1e-12);

  EXPECT_FALSE(AlignSimilarity({from[0], from[1]}, {to[0], to[1]}).ok());
  EXPECT_FALSE(AlignSimilarity({from[0], from[0], from[0]}, {to[0], to[1], to[2]}).ok());
}

TEST(SfmEvaluationTest, CameraErrorsAreMeasuredAfterAlignment) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  Similarity3 estimate_from_gt;
  estimate_from_gt.scale = 2.5;
  estimate_from_gt.rotation = RandomRotation(&rng);
  estimate_from_gt.translation = Eigen::Vector3d(0.3, 0.2, -1.0);
  std::vector<CameraPose> ground_truth, estimated;
  for (int i = 0; i < 6; ++i) {
    CameraPose gt{RandomRotation(&rng), Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng))};
    CameraPose estimate{gt.cam_from_world_rotation * estimate_from_gt.rotation.transpose(),
                        estimate_from_gt.Apply(gt.centre)};
    ground_truth.push_back(gt);
    estimated.push_back(estimate);
  }
  Result<CameraPoseErrors> exact = CameraCenterErrors(estimated, ground_truth);
  ASSERT_TRUE(exact.ok()) << exact.status().ToString();
  EXPECT_NEAR(exact->gt_from_estimate.scale, 1.0 / 2.5, 1e-12);
  EXPECT_LT(exact->centre_max, 1e-12);
  EXPECT_LT(exact->rotation_max_deg, 1e-5);
  EXPECT_LT(exact->relative_rotation_mean_deg, 1e-5);

  // Rotating one camera by 2 degrees about its own axis changes only its rotation error.
  estimated[2].cam_from_world_rotation =
      Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()) * estimated[2].cam_from_world_rotation;
  Result<CameraPoseErrors> rotated = CameraCenterErrors(estimated, ground_truth);
  ASSERT_TRUE(rotated.ok());
  EXPECT_NEAR(rotated->rotation_errors_deg[2], 2.0, 1e-9);
  EXPECT_NEAR(rotated->rotation_max_deg, 2.0, 1e-9);
  EXPECT_NEAR(rotated->rotation_mean_deg, 2.0 / 6, 1e-6);
  EXPECT_NEAR(rotated->relative_rotation_mean_deg, 2.0 * 5 / 15, 1e-6);  // 5 of 15 pairs hold camera 2
  EXPECT_LT(rotated->centre_max, 1e-12);
}

TEST(SfmEvaluationTest, MedianOfEvenCount) {
  std::vector<CameraPose> ground_truth, estimated;
  const Eigen::Vector3d centres[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const Eigen::Vector3d& c : centres) {
    ground_truth.push_back({Eigen::Matrix3d::Identity(), c});
    estimated.push_back({Eigen::Matrix3d::Identity(), c});
  }
  Result<CameraPoseErrors> errors = CameraCenterErrors(estimated, ground_truth);
  ASSERT_TRUE(errors.ok());
  EXPECT_EQ(errors->centre_errors.size(), 4u);
  EXPECT_LT(errors->centre_median, 1e-12);
}

TEST(SfmEvaluationTest, ReadsStrechaAndMiddleburyFiles) {
  const fs::path dir = TempDir("gt");
  std::ofstream(dir / "0001.jpg.camera") << "100 0 50\n0 100 40\n0 0 1\n0 0 0\n"
                                            "1 0 0\n0 1 0\n0 0 1\n1 2 3\n100 80\n";
  std::ofstream(dir / "SOURCE.txt") << "not a camera\n";
  Result<GroundTruthByName> strecha = ReadStrechaGroundTruth(dir.string());
  ASSERT_TRUE(strecha.ok()) << strecha.status().ToString();
  ASSERT_EQ(strecha->size(), 1u);
  const GroundTruthCamera& camera = strecha->at("0001.jpg");
  EXPECT_EQ(camera.Centre(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(camera.width, 100);

  std::ofstream(dir / "t_par.txt") << "2\n"
                                      "a.png 1520.4 0 302.32 0 1525.9 246.87 0 0 1 0 1 0 -1 0 0 0 0 1 0.1 0.2 0.3\n"
                                      "b.png 1520.4 0 302.32 0 1525.9 246.87 0 0 1 1 0 0 0 1 0 0 0 1 1 1 1\n";
  Result<GroundTruthByName> middlebury = ReadMiddleburyPar((dir / "t_par.txt").string());
  ASSERT_TRUE(middlebury.ok()) << middlebury.status().ToString();
  ASSERT_EQ(middlebury->size(), 2u);
  const GroundTruthCamera& a = middlebury->at("a.png");
  EXPECT_EQ(a.K(0, 0), 1520.4);
  EXPECT_EQ(a.cam_from_world_rotation(0, 1), 1.0);
  EXPECT_EQ(a.cam_from_world_translation, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_LT((a.Centre() - Eigen::Vector3d(0.2, -0.1, -0.3)).norm(), 1e-15);

  std::ofstream(dir / "bad_par.txt") << "2\na.png 1 2 3\n";
  Result<GroundTruthByName> bad = ReadMiddleburyPar((dir / "bad_par.txt").string());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("bad_par.txt"), std::string::npos);
  EXPECT_FALSE(ReadStrechaGroundTruth((dir / "missing").string()).ok());
}

// Truth written as a COLMAP text model (two sizes of camera) reads back the same to the printed
// digits, keyed by file name; a camera with distortion is refused.
TEST(SfmEvaluationTest, GroundTruthRoundTripsThroughAColmapModel) {
  std::mt19937 rng(7);
  GroundTruthByName truth;
  for (int i = 0; i < 4; ++i) {
    GroundTruthCamera camera;
    camera.width = i < 3 ? 640 : 320;
    camera.height = i < 3 ? 480 : 240;
    camera.K << 520.0 * camera.width / 640, 0.0, 0.5 * camera.width, 0.0, 521.0 * camera.width / 640,
        0.5 * (camera.height - 1), 0.0, 0.0, 1.0;
    camera.cam_from_world_rotation = RandomRotation(&rng);
    camera.cam_from_world_translation = Eigen::Vector3d(0.1 * i, -0.2, 1.0 + i);
    truth["view_" + std::to_string(i) + ".png"] = camera;
  }
  const fs::path dir = TempDir("truth_model");
  ASSERT_TRUE(WriteGroundTruthModel(truth, dir.string()).ok());
  const Result<GroundTruthByName> read = ReadGroundTruthModel(dir.string());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->size(), truth.size());
  for (const auto& [name, camera] : truth) {
    const GroundTruthCamera& back = read->at(name);
    EXPECT_EQ(back.width, camera.width);
    EXPECT_EQ(back.height, camera.height);
    EXPECT_LT((back.K - camera.K).norm(), 1e-9) << name;
    EXPECT_LT(RotationAngleDeg(back.cam_from_world_rotation, camera.cam_from_world_rotation), 1e-9) << name;
    EXPECT_LT((back.cam_from_world_translation - camera.cam_from_world_translation).norm(), 1e-12) << name;
  }

  std::ofstream(dir / "cameras.txt") << "1 RADIAL 640 480 520 320.5 240 0.1 0\n2 RADIAL 320 240 260 160.5 120 0 0\n";
  const Result<GroundTruthByName> distorted = ReadGroundTruthModel(dir.string());
  EXPECT_EQ(distorted.status().code(), StatusCode::kUnsupported);
}

}  // namespace
}  // namespace reconar::testing
