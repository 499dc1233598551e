// `reconar reconstruct` end to end.
//  - AprilTag registration on a real room (../shared/data/apriltag_swatbotics_mapping: 72 iPhone
//    photos, 20 tags of 0.127 m, the camera's checkerboard calibration, the ids visible per photo):
//    most photos registered; detected ids only where groundtruth.txt lists them; the focal within
//    1 % of the calibration; every tag's edges in metres with a spread under 1 % of the tag size;
//    the AR view of the project places the model through the tags where SfM put the cameras.
//  - A run killed with SIGKILL, the run resuming it killed again, three times, then finished, ends
//    with the same files as an uninterrupted run; a full disk (RLIMIT_FSIZE) ends with a clear error and no half-written file.
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
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/math/rigid3.h"
#include "core/mesh/mesh_file.h"
#include "core/sfm/model_io.h"
#include "core/sfm/tag_observations.h"
#include "tests/support/ground_truth.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunReconar;

constexpr double kSwatTagSize = 0.127;
constexpr double kSwatCalibratedFx = 765.00;  // calibration/calib.txt (SOURCE.txt)

double Number(const JsonValue& object, const char* key) {
  const JsonValue* value = object.Find(key);
  return value != nullptr && value->is_number() ? value->number() : std::nan("");
}

// Each tag measured at the scale set by the other tags (tags.json "held_out_*"): the plain mean
// over all tags is the tag size by construction.
struct TagFigures {
  int tags = 0;
  double edge_mean = 0.0, edge_std = 0.0, edge_max_error = 0.0;
};

TagFigures ReadTagFigures(const std::string& project) {
  TagFigures figures;
  auto tags = ReadJsonFile(project + "/tags.json");
  EXPECT_TRUE(tags.ok()) << tags.status().ToString();
  if (!tags.ok()) return figures;
  const JsonValue* list = tags->Find("tags");
  figures.tags = list != nullptr ? static_cast<int>(list->size()) : 0;
  figures.edge_mean = Number(*tags, "held_out_edge_mean_m");
  figures.edge_std = Number(*tags, "held_out_edge_std_m");
  figures.edge_max_error = Number(*tags, "held_out_edge_max_abs_error_m");
  return figures;
}

TEST(ReconstructCli, SwatboticsRoomIsRegisteredInMetresByItsTags) {
  const std::string data = testing::SharedDataPath("apriltag_swatbotics_mapping");
  const std::string project = testing::MakeTestDirectory("reconar_reconstruct_swat") + "/project";
  const CommandRun run =
      RunReconar("reconstruct " + data + " " + project + " --tag-size 0.127 --stages sparse --threads 2 --no-preview");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  auto report = ReadJsonFile(project + "/report.json");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  const JsonValue& table1 = *report->Find("table1");
  const double registered = Number(table1, "registered");
  EXPECT_EQ(Number(table1, "images"), 72);
  EXPECT_GE(registered, 0.8 * 72) << "most photos registered";
  const double focal = Number(table1, "mean_focal_ratio") * 816;
  EXPECT_LT(std::abs(focal - kSwatCalibratedFx) / kSwatCalibratedFx, 0.01) << focal;
  EXPECT_TRUE(report->Find("metric")->bool_value());

  // Detections against the ids listed per photo (human-made, groundtruth.txt).
  auto listed_ids = testing::ReadListedTagIds(data + "/groundtruth.txt");
  ASSERT_TRUE(listed_ids.ok()) << listed_ids.status().ToString();
  std::map<std::string, std::set<int>>& listed = *listed_ids;
  auto detections = ReadTagDetections(project + "/tags/detections.txt");
  ASSERT_TRUE(detections.ok()) << detections.status().ToString();
  int found = 0, false_ids = 0, total = 0;
  for (const auto& [name, ids] : listed) total += static_cast<int>(ids.size());
  for (const ImageTagObservations& image : detections->images) {
    for (const TagObservation& tag : image.tags) {
      (listed[image.image_name].count(tag.tag_id) ? found : false_ids) += 1;
    }
  }
  std::printf("tags: %d of %d listed instances detected, %d not listed\n", found, total, false_ids);
  EXPECT_EQ(false_ids, 0);
  EXPECT_GE(found, 0.95 * total);

  const TagFigures with = ReadTagFigures(project);
  std::printf("with tags in BA: %d tags, held-out edges mean %.5f m, spread %.5f m (%.2f %%), max |error| %.5f m "
              "(%.2f %%)\n",
              with.tags, with.edge_mean, with.edge_std, 100 * with.edge_std / kSwatTagSize, with.edge_max_error,
              100 * with.edge_max_error / kSwatTagSize);
  EXPECT_GE(with.tags, 18);
  EXPECT_LT(std::abs(with.edge_mean - kSwatTagSize), 0.01 * kSwatTagSize);
  EXPECT_LT(with.edge_std, 0.01 * kSwatTagSize);

  // The AR view of the project: each photo as a video frame, the model posed from all project tags
  // in view (tags.layout) with the project's camera. That pose, cam_from_world, must be where
  // structure from motion put the photo's camera.
  const std::string frames = testing::MakeTestDirectory("reconar_reconstruct_swat_frames");
  const std::vector<std::string> names = {"IMG_1375.JPG", "IMG_1390.JPG", "IMG_1410.JPG"};
  for (const std::string& name : names) fs::create_symlink(data + "/" + name, frames + "/" + name);
  const CommandRun view =
      RunReconar("view --project " + project + " --frames " + frames + " --out " + frames + "/out --decimate 1");
  ASSERT_EQ(view.exit_code, 0) << view.output;
  EXPECT_NE(view.output.find("3 frames, model drawn on 3"), std::string::npos) << view.output;
  auto model = ReadColmapTextModel(project + "/sparse");
  ASSERT_TRUE(model.ok());
  const SfmCamera& camera = model->cameras.front();
  char intrinsics[256];
  std::snprintf(intrinsics, sizeof(intrinsics), "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", camera.focal,
                camera.aspect * camera.focal, camera.cx, camera.cy, camera.k1, camera.k2);
  const CommandRun track = RunReconar("track " + frames + " --intrinsics " + intrinsics +
                                          " --tag-size 0.127 --decimate 1 --layout " + project + "/tags.layout --json",
                                      testing::StderrMode::kSeparate);
  ASSERT_EQ(track.exit_code, 0) << track.error;
  std::istringstream lines(track.output);
  std::string line;
  int compared = 0;
  while (std::getline(lines, line)) {
    auto frame = ParseJson(line, "track output");
    ASSERT_TRUE(frame.ok()) << line;
    const std::string name = frame->Find("frame")->string();
    const SfmImage* image = nullptr;
    for (const SfmImage& i : model->images) image = i.name == name && i.registered ? &i : image;
    const JsonValue* pose = frame->Find("cam_from_layout");
    if (image == nullptr || pose == nullptr) continue;
    Rigid3 cam_from_world;
    for (int e = 0; e < 9; ++e)
      cam_from_world.rotation(e / 3, e % 3) = (*pose->Find("R"))[static_cast<size_t>(e)].number();
    for (int e = 0; e < 3; ++e) cam_from_world.translation[e] = (*pose->Find("t"))[static_cast<size_t>(e)].number();
    const double distance = (cam_from_world.Inverse().translation - image->Center()).norm();
    const double degrees = RotationAngle(cam_from_world.rotation, image->cam_from_world.rotation) * 180.0 / M_PI;
    std::printf("%s from %d tags: camera %.3f m and %.2f deg from the SfM camera\n", name.c_str(),
                static_cast<int>(*frame->Find("layout_tags")->AsInteger()), distance, degrees);
    // A few centimetres at 1-4 m: what the single photo's tag corners (0.1-0.2 px) can fix.
    EXPECT_LT(distance, 0.05);
    EXPECT_LT(degrees, 1.5);
    ++compared;
  }
  EXPECT_EQ(compared, 3);

  // The same photos with the tags only triangulated from the final cameras (paper sec. 3.4: what
  // the markers add); only the mapping stage is redone. Without the tags' tracks some photos
  // register only provisionally, and the photos mapped weakly would be extracted again
  // (docs/reconstruct.md): --no-reextraction keeps the features the run with tags had, so that
  // the two differ by the tags alone.
  const CommandRun without =
      RunReconar("reconstruct " + data + " " + project +
                 " --tag-size 0.127 --stages sparse --threads 2 --no-preview --no-tags-in-ba --no-reextraction");
  ASSERT_EQ(without.exit_code, 0) << without.output;
  EXPECT_NE(without.output.find("features  reused"), std::string::npos) << without.output;
  const TagFigures alone = ReadTagFigures(project);
  std::printf("tags not in BA:  %d tags, held-out edges mean %.5f m, spread %.5f m (%.2f %%), max |error| %.5f m "
              "(%.2f %%)\n",
              alone.tags, alone.edge_mean, alone.edge_std, 100 * alone.edge_std / kSwatTagSize, alone.edge_max_error,
              100 * alone.edge_max_error / kSwatTagSize);
  // What the corner constraints are for: the tags measure at least as well with them as without.
  EXPECT_EQ(alone.tags, with.tags);
  EXPECT_LE(with.edge_std, alone.edge_std);
}

// Every file of a finished project except the reports (which hold timings and reuse flags).
std::map<std::string, std::string> ProjectFiles(const std::string& project) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(project)) {
    if (!entry.is_regular_file()) continue;
    const std::string relative = fs::relative(entry.path(), project).string();
    const std::string name = entry.path().filename().string();
    if (name == "report.json" || name == "preview.png" || name == "stages.txt") continue;
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
              expected.count("sparse/points3D.txt"));
  auto mesh_report = ReadJsonFile(dir + "/reference/mesh/report.json");
  ASSERT_TRUE(mesh_report.ok()) << mesh_report.status().ToString();
  EXPECT_TRUE(mesh_report->Find("simplified")->bool_value());
  EXPECT_LE(Number(*mesh_report, "triangles"), 10000);
  EXPECT_GT(Number(*mesh_report, "poisson_triangles"), 10000);

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
