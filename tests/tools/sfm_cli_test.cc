// Structure from motion end to end through `reconar sfm`, scored against independent ground
// truth: the Strecha benchmark's camera calibrations (../shared/data/strecha_*, SOURCE.txt).
// Bars from the issue: fountain-P11 11/11 registered, mean camera-centre error <= 2.43 mm after a
// 7-DoF similarity alignment (Theia's published figure), every focal within 0.5 % of the ground
// truth; Herz-Jesu-P8 8/8 with mean <= 3.58 mm.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/sfm/model_io.h"
#include "tests/support/ground_truth.h"
#include "tests/support/run_command.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

using testing::CommandRun;
using testing::RunReconar;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("reconar_sfm_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

struct Score {
  int registered = 0;
  testing::CameraPoseErrors errors;
  std::vector<double> focals_x, focals_y;
};

Score RunAndScore(const std::string& dataset, const fs::path& project) {
  Score score;
  const std::string data = testing::SharedDataPath(dataset);
  const CommandRun run = RunReconar("sfm " + data + "/images " + project.string() + " --threads 2");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  auto model = ReadColmapTextModel((project / "sparse").string());
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  if (!model.ok()) return score;
  auto truth = testing::ReadStrechaGroundTruth(data + "/gt_cameras");
  EXPECT_TRUE(truth.ok()) << truth.status().ToString();
  if (!truth.ok()) return score;
  std::vector<testing::CameraPose> estimated, reference;
  for (const SfmImage& image : model->images) {
    if (!image.registered) continue;
    ++score.registered;
    const auto gt = truth->find(image.name);
    if (gt == truth->end()) {
      ADD_FAILURE() << image.name << " has no ground truth";
      continue;
    }
    estimated.push_back({image.cam_from_world.rotation, image.Center()});
    reference.push_back(testing::PoseOf(gt->second));
    const SfmCamera& camera = model->cameras[static_cast<size_t>(image.camera_id)];
    score.focals_x.push_back(camera.focal);
    score.focals_y.push_back(camera.focal * camera.aspect);
  }
  auto errors = testing::CameraCenterErrors(estimated, reference);
  EXPECT_TRUE(errors.ok()) << errors.status().ToString();
  if (errors.ok()) score.errors = *errors;
  std::printf("%s: %d registered, mean centre error %.3f mm (median %.3f, max %.3f), rotation %.3f deg\n",
              dataset.c_str(), score.registered, 1000.0 * score.errors.centre_mean,
              1000.0 * score.errors.centre_median, 1000.0 * score.errors.centre_max,
              score.errors.rotation_mean_deg);
  return score;
}

TEST(SfmCli, FountainP11MillimetreCameraCentresAndFocal) {
  const fs::path project = FreshDir("fountain");
  const Score score = RunAndScore("strecha_fountain-P11", project);
  EXPECT_EQ(score.registered, 11);
  EXPECT_LE(1000.0 * score.errors.centre_mean, 2.43);
  for (size_t i = 0; i < score.focals_x.size(); ++i) {
    EXPECT_NEAR(score.focals_x[i] / 2759.48, 1.0, 0.005) << "fx of camera " << i;
    EXPECT_NEAR(score.focals_y[i] / 2764.16, 1.0, 0.005) << "fy of camera " << i;
  }
  // Re-running reuses every stage and leaves the model as it was.
  std::ifstream before((project / "sparse" / "images.txt").string());
  std::stringstream before_text;
  before_text << before.rdbuf();
  const CommandRun again = RunReconar("sfm " + testing::SharedDataPath("strecha_fountain-P11") + "/images " +
                                      project.string());
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("mapping   reused"), std::string::npos) << again.output;
  std::ifstream after((project / "sparse" / "images.txt").string());
  std::stringstream after_text;
  after_text << after.rdbuf();
  EXPECT_EQ(before_text.str(), after_text.str());
  fs::remove_all(project);
}

TEST(SfmCli, HerzJesuP8MillimetreCameraCentres) {
  const fs::path project = FreshDir("herzjesu");
  const Score score = RunAndScore("strecha_herzjesu-P8", project);
  EXPECT_EQ(score.registered, 8);
  EXPECT_LE(1000.0 * score.errors.centre_mean, 3.58);
  fs::remove_all(project);
}

TEST(SfmCli, UnrelatedOrTooFewPhotosFailWithAReason) {
  const fs::path project = FreshDir("unrelated");
  // One fountain photo and one of the Herz-Jesu church: nothing to match.
  const fs::path images = project / "photos";
  fs::create_directories(images);
  fs::copy_file(testing::SharedDataPath("strecha_fountain-P11/images/0000.jpg"), images / "a.jpg");
  fs::copy_file(testing::SharedDataPath("strecha_herzjesu-P8/images/0000.jpg"), images / "b.jpg");
  const CommandRun run = RunReconar("sfm " + images.string() + " " + (project / "out").string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no image pair"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(project / "out" / "sparse" / "points3D.txt"));
  fs::remove(images / "b.jpg");
  const CommandRun one = RunReconar("sfm " + images.string() + " " + (project / "out1").string());
  EXPECT_NE(one.exit_code, 0) << one.output;
  EXPECT_NE(one.output.find("at least 2 photos"), std::string::npos) << one.output;
  fs::remove_all(project);
}

}  // namespace
}  // namespace reconar
