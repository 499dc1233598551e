// `reconar reconstruct` end to end (the room with its tags: reconstruct_room_test.cc).
//  - A run killed with SIGKILL, the run resuming it killed again, three times, then finished, ends
//    with the same files as an uninterrupted run; a full disk (RLIMIT_FSIZE) ends with a clear
//    error and no half-written file.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/mesh/mesh_file.h"
#include "tests/support/json_number.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunReconar;

// Every file of a finished project except the reports (which hold timings and reuse flags).
std::map<std::string, std::string> ProjectFiles(const std::string& project) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(project)) {
    if (!entry.is_regular_file()) continue;
    const std::string relative = fs::relative(entry.path(), project).string();
    const std::string name = entry.path().filename().string();
    // Reports hold seconds; texture_report.json is the texture stage's.
    if (name == "report.json" || name == "texture_report.json" || name == "preview.png" || name == "stages.txt") {
      continue;
    }
    auto text = ReadFileToString(entry.path().string());
    files[relative] = text.ok() ? *text : "(unreadable)";
  }
  return files;
}

TEST(ReconstructCli, KilledRunsResumeToTheSameFiles) {
  const std::string data = std::string(RECONAR_SOURCE_DIR) + "/data/templeSparseRing";
  const std::string dir = testing::MakeTestDirectory("reconar_reconstruct_resume");
  // --max-faces below the temple mesh's ~25,000 triangles: the simplification is part of the run.
  const std::string arguments = " --threads 2 --no-preview --formats ply,glb --max-faces 10000";
  const auto start = std::chrono::steady_clock::now();
  const CommandRun reference = RunReconar("reconstruct " + data + " " + dir + "/reference" + arguments);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(reference.exit_code, 0) << reference.output;
  const auto expected = ProjectFiles(dir + "/reference");
  ASSERT_TRUE(expected.count("mesh/mesh.glb") && expected.count("dense/points.ply") &&
              expected.count("sparse/points3D.txt") && expected.count("mesh/textured.glb") &&
              expected.count("mesh/textured.png"));
  auto mesh_report = ReadJsonFile(dir + "/reference/mesh/report.json");
  ASSERT_TRUE(mesh_report.ok()) << mesh_report.status().ToString();
  EXPECT_TRUE(mesh_report->Find("simplified")->bool_value());
  EXPECT_LE(testing::JsonNumber(*mesh_report, "triangles"), 10000);
  EXPECT_GT(testing::JsonNumber(*mesh_report, "poisson_triangles"), 10000);

  // One project killed three times, each time in the run that resumed it: at about a fifth, half and
  // four fifths of the work (features or matching, then the later stages), then finished by a
  // fourth run. A resumed run that is killed again must resume as well.
  const std::string project = dir + "/killed";
  int interrupted = 0;
  double done_fraction = 0;
  for (const double fraction : {0.2, 0.5, 0.8}) {
    const pid_t pid =
        testing::SpawnCommand(std::string(RECONAR_BINARY) + " reconstruct " + data + " " + project + arguments);
    ASSERT_GT(pid, 0);
    std::this_thread::sleep_for(std::chrono::duration<double>((fraction - done_fraction) * seconds));
    done_fraction = fraction;
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (WIFSIGNALED(status)) ++interrupted;
  }
  const CommandRun resumed = RunReconar("reconstruct " + data + " " + project + arguments);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("reused"), std::string::npos) << resumed.output;
  const auto files = ProjectFiles(project);
  for (const auto& [name, content] : files) {
    EXPECT_TRUE(expected.count(name)) << name << ": not in the uninterrupted run";
  }
  EXPECT_EQ(files.size(), expected.size());
  for (const auto& [name, content] : expected) {
    const auto it = files.find(name);
    ASSERT_NE(it, files.end()) << name << " missing after resuming the killed runs";
    EXPECT_TRUE(it->second == content) << name << " differs after resuming the killed runs";
  }
  std::printf("uninterrupted run %.1f s; %d of 3 runs were killed midway, then the project was finished\n", seconds,
              interrupted);
  EXPECT_GE(interrupted, 2);
}

TEST(ReconstructCli, FullDiskEndsWithAClearErrorAndNoHalfFile) {
  const std::string data = std::string(RECONAR_SOURCE_DIR) + "/data/templeSparseRing";
  const std::string project = testing::MakeTestDirectory("reconar_reconstruct_full_disk") + "/project";
  // Files may grow to 768 KiB (ulimit -f counts 1024-byte blocks); SIGXFSZ ignored, so writes fail
  // with EFBIG. The temple's feature files and matches stay under it; the sparse model's images.txt
  // (about 1 MiB) is the first file over it, so the disk fills while the model's files are written.
  const CommandRun run =
      testing::RunCommand("bash -c \"trap '' XFSZ; ulimit -f 768; exec " + std::string(RECONAR_BINARY) +
                          " reconstruct " + data + " " + project + " --threads 2 --no-preview\"");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("reconar: error:"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(project), std::string::npos) << "the error names the file: " << run.output;
  std::printf("%s", run.output.substr(run.output.find("reconar: error:")).c_str());
  EXPECT_NE(run.output.find("/sparse/"), std::string::npos) << run.output;
  // The weak-photo round wrote a model before; the failed rewrite leaves no file that marks a
  // finished model beside a mix of the two.
  EXPECT_FALSE(fs::exists(project + "/sparse/points3D.txt"));
  for (const auto& entry : fs::recursive_directory_iterator(project)) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "temporary file left: " << entry.path();
    if (entry.is_regular_file() && (name.size() > 4 && name.substr(name.size() - 4) == ".ply")) {
      EXPECT_TRUE(ReadMeshFile(entry.path().string()).ok()) << "half-written " << entry.path();
    }
  }
}

TEST(ReconstructCli, PhotosWithoutTagsKeepAnArbitraryScaleAndSaySo) {
  const std::string data = std::string(RECONAR_SOURCE_DIR) + "/data/templeSparseRing";
  const std::string project = testing::MakeTestDirectory("reconar_reconstruct_no_tags") + "/project";
  const CommandRun run =
      RunReconar("reconstruct " + data + " " + project + " --tag-size 0.1 --stages sparse --no-preview");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  auto report = ReadJsonFile(project + "/report.json");
  ASSERT_TRUE(report.ok());
  EXPECT_FALSE(report->Find("metric")->bool_value());
  EXPECT_NE(report->Find("scale")->string().find("no tag was detected"), std::string::npos)
      << report->Find("scale")->string();
  EXPECT_NE(run.output.find("scale: no tag was detected"), std::string::npos) << run.output;

  const CommandRun one = RunReconar("reconstruct " + data + "/templeSR0001.png " + project + "_one");
  EXPECT_EQ(one.exit_code, 2) << one.output;
  EXPECT_NE(one.output.find("at least 2 photos"), std::string::npos) << one.output;
  const CommandRun bad = RunReconar("reconstruct " + data + " " + project + " --memory-budget 12Q");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  const CommandRun bad_range = RunReconar("reconstruct " + data + " " + project + " --tag-size 0.1 --scale-tags 0-3,9-7");
  EXPECT_EQ(bad_range.exit_code, 2) << bad_range.output;
  EXPECT_NE(bad_range.output.find("--scale-tags: '9-7'"), std::string::npos) << bad_range.output;
  const CommandRun no_size = RunReconar("reconstruct " + data + " " + project + " --scale-tags 1");
  EXPECT_EQ(no_size.exit_code, 2) << no_size.output;
  EXPECT_NE(no_size.output.find("--scale-tags needs --tag-size"), std::string::npos) << no_size.output;
}

// `sfm` is `reconstruct --stages sparse`: either command continues a project the other started,
// reusing its features, matches and model (the stage lines say "reused", the files stay as they were).
TEST(ReconstructCli, SfmAndReconstructReuseEachOthersStages) {
  const std::string data = std::string(RECONAR_SOURCE_DIR) + "/data/templeSparseRing";
  const std::string dir = testing::MakeTestDirectory("reconar_sfm_then_reconstruct");
  const struct {
    const char* name;
    std::string first, second;
  } orders[] = {{"sfm_first", "sfm", "reconstruct --stages sparse"},
                {"reconstruct_first", "reconstruct --stages sparse", "sfm"}};
  for (const auto& order : orders) {
    const std::string project = dir + "/" + order.name;
    const CommandRun first = RunReconar(order.first + " " + data + " " + project + " --threads 2 --no-preview");
    ASSERT_EQ(first.exit_code, 0) << first.output;
    EXPECT_NE(first.output.find("mapping   done"), std::string::npos) << first.output;
    const auto before = ProjectFiles(project);
    ASSERT_TRUE(before.count("features/images.txt") && before.count("matches/matches.txt") &&
                before.count("sparse/points3D.txt"))
        << order.name;
    const CommandRun second = RunReconar(order.second + " " + data + " " + project + " --threads 2 --no-preview");
    ASSERT_EQ(second.exit_code, 0) << second.output;
    for (const char* stage : {"features ", "matching ", "mapping  "}) {
      EXPECT_NE(second.output.find(std::string(stage) + " reused"), std::string::npos)
          << order.name << ": " << stage << "\n"
          << second.output;
    }
    EXPECT_EQ(second.output.find("done"), std::string::npos) << order.name << ": nothing redone\n" << second.output;
    EXPECT_NE(second.output.find("of 16 images registered"), std::string::npos) << second.output;
    EXPECT_TRUE(ProjectFiles(project) == before) << order.name << ": the files changed";
  }
}

}  // namespace
}  // namespace reconar
