// The `reconar` executable as a user meets it: exit codes, messages naming the file and the
// reason, bad photos skipped while the rest proceed, nothing half-written.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/base/atomic_file.h"
#include "tests/support/run_command.h"

namespace {

namespace fs = std::filesystem;

using reconar::testing::CommandRun;
using reconar::testing::RunCommand;
using reconar::testing::RunReconar;

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("reconar_cli_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

const std::string kTemple = std::string(RECONAR_SOURCE_DIR) + "/data/templeSparseRing";

TEST(Cli, HelpAndUsageErrors) {
  EXPECT_EQ(RunReconar("--help").exit_code, 0);
  EXPECT_EQ(RunReconar("features --help").exit_code, 0);
  EXPECT_EQ(RunReconar("match --help").exit_code, 0);
  const CommandRun unknown = RunReconar("frobnicate");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("unknown command"), std::string::npos);
  const CommandRun bad_option = RunReconar("features x.jpg --project /tmp/x --first-octave 3");
  EXPECT_EQ(bad_option.exit_code, 2);
  EXPECT_NE(bad_option.output.find("--first-octave"), std::string::npos) << bad_option.output;
}

TEST(Cli, MissingFileIsNamed) {
  const CommandRun run = RunReconar("features /nonexistent/photo.jpg --project " + TempDir("missing").string());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("/nonexistent/photo.jpg"), std::string::npos) << run.output;
}

TEST(Cli, BadPhotosInAFolderAreSkippedAndTheRestProceed) {
  const fs::path photos = TempDir("photos");
  fs::copy_file(kTemple + "/templeSR0001.png", photos / "a.png");
  fs::copy_file(kTemple + "/templeSR0002.png", photos / "b.png");
  std::ofstream(photos / "empty.jpg").close();
  std::ofstream(photos / "text.png") << "this is not an image";
  {
    auto bytes = reconar::ReadFileToString(kTemple + "/templeSR0003.png");
    ASSERT_TRUE(bytes.ok());
    std::ofstream(photos / "truncated.png", std::ios::binary) << bytes->substr(0, bytes->size() / 3);
  }
  const fs::path project = TempDir("project");
  const CommandRun run = RunReconar("features " + photos.string() + " --project " + project.string() + " --threads 2");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* bad : {"empty.jpg", "text.png", "truncated.png"}) {
    EXPECT_NE(run.output.find(std::string("skipped ") + (photos / bad).string()), std::string::npos)
        << bad << "\n" << run.output;
  }
  EXPECT_TRUE(fs::exists(project / "features" / "a.png.rfeat"));
  EXPECT_TRUE(fs::exists(project / "features" / "b.png.rfeat"));
  EXPECT_FALSE(fs::exists(project / "features" / "text.png.rfeat"));
  EXPECT_NE(run.output.find("no EXIF"), std::string::npos) << "the default focal prior is announced\n" << run.output;
  for (const auto& entry : fs::directory_iterator(project / "features")) {
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << "temporary left: " << entry.path();
  }
}

TEST(Cli, ProjectFeaturesThenMatchesOnTheBundledTemple) {
  const fs::path project = TempDir("temple");
  const fs::path keys = TempDir("keys");
  CommandRun run = RunReconar("features " + kTemple + " --project " + project.string() + " --key " + keys.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("features: 16 images, 0 skipped"), std::string::npos) << run.output;
  EXPECT_TRUE(fs::exists(keys / "templeSR0001.key"));
  run = RunReconar("match --project " + project.string() + " --threads 2");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("16 images, 120 pairs"), std::string::npos) << run.output;
  EXPECT_TRUE(fs::exists(project / "matches" / "matches.txt"));
  // Under a budget that holds only a few images' features at once, blocks of images are matched
  // two at a time, to the same file.
  auto all_at_once = reconar::ReadFileToString((project / "matches" / "matches.txt").string());
  ASSERT_TRUE(all_at_once.ok());
  run = RunReconar("match --project " + project.string() + " --threads 2 --memory-budget 2");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find(" blocks of images, two at a time"), std::string::npos) << run.output;
  auto in_blocks = reconar::ReadFileToString((project / "matches" / "matches.txt").string());
  ASSERT_TRUE(in_blocks.ok());
  EXPECT_TRUE(*in_blocks == *all_at_once);
  // Matching a project that has no features is a clear usage error.
  run = RunReconar("match --project " + TempDir("empty_project").string());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("reconar features"), std::string::npos) << run.output;
}

TEST(Cli, TwoUnrelatedPhotosAreReportedNotCrashed) {
  const std::string a = kTemple + "/templeSR0001.png";
  const std::string b = std::string(RECONAR_SHARED_DATA_DIR) + "/middlebury_dinoSparseRing/dinoSR0001.png";
  const fs::path out = TempDir("unrelated") / "pairs.txt";
  const CommandRun run = RunReconar("match " + a + " " + b + " --pairs " + out.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("too few inliers"), std::string::npos) << run.output;
}

TEST(Cli, VersionNamesTheBuildAndTheKernelsThisCpuRuns) {
  const CommandRun run = RunReconar("--version");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output.rfind("reconar 0.", 0), 0u) << run.output;
  for (const char* line : {"\ncpu: ", "\nkernel descriptor: ", "\nkernel ncc: ", "\nkernel sift: ", "\nkernel warp: "}) {
    EXPECT_NE(run.output.find(line), std::string::npos) << line << " in\n" << run.output;
  }
  const CommandRun forced = RunCommand(std::string("RECONAR_SIFT_KERNEL=scalar ") + RECONAR_BINARY + " --version");
  EXPECT_EQ(forced.exit_code, 0) << forced.output;
  EXPECT_NE(forced.output.find("\nkernel sift: scalar (of scalar"), std::string::npos) << forced.output;
  EXPECT_NE(forced.output.find("; set by RECONAR_SIFT_KERNEL)\n"), std::string::npos) << forced.output;
}

}  // namespace
