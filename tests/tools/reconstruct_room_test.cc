// `reconar reconstruct` on a real room with AprilTags (../shared/data/apriltag_swatbotics_mapping:
// 72 iPhone photos, 20 tags of 0.127 m, the camera's checkerboard calibration, the ids visible per
// photo): most photos registered; detected ids only where groundtruth.txt lists them; the focal
// within 1 % of the calibration; every tag's edges in metres with a spread under 1 % of the tag
// size; the AR view of the project places the model through the tags where SfM put the cameras.
// Its project is shared with LocalizeRoom (tests/support/run_command.h SharedProjectDirectory).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "core/base/json_reader.h"
#include "core/math/rigid3.h"
#include "core/sfm/model_io.h"
#include "core/sfm/tag_observations.h"
#include "tests/support/ground_truth.h"
#include "tests/support/json_number.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunReconar;

constexpr double kSwatTagSize = 0.127;
constexpr double kSwatCalibratedFx = 765.00;  // calibration/calib.txt (SOURCE.txt)

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
  figures.edge_mean = testing::JsonNumber(*tags, "held_out_edge_mean_m");
  figures.edge_std = testing::JsonNumber(*tags, "held_out_edge_std_m");
  figures.edge_max_error = testing::JsonNumber(*tags, "held_out_edge_max_abs_error_m");
  return figures;
}

TEST(ReconstructCli, SwatboticsRoomIsRegisteredInMetresByItsTags) {
  const std::string data = testing::SharedDataPath("apriltag_swatbotics_mapping");
  // The project LocalizeRoom takes its reference from: made by whichever of the two gets there first.
  const std::string project = testing::SharedProjectDirectory("swatbotics_room_sparse", RECONAR_BINARY);
  const CommandRun run =
      RunReconar("reconstruct " + data + " " + project + " --tag-size 0.127 --stages sparse --threads 2 --no-preview");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  auto report = ReadJsonFile(project + "/report.json");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  const JsonValue& table1 = *report->Find("table1");
  const double registered = testing::JsonNumber(table1, "registered");
  EXPECT_EQ(testing::JsonNumber(table1, "images"), 72);
  EXPECT_GE(registered, 0.8 * 72) << "most photos registered";
  const double focal = testing::JsonNumber(table1, "mean_focal_ratio") * 816;
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
  // On a copy: the shared project stays as the defaults made it.
  const std::string copy = testing::MakeTestDirectory("reconar_reconstruct_swat") + "/project";
  fs::copy(project, copy, fs::copy_options::recursive);
  const CommandRun without =
      RunReconar("reconstruct " + data + " " + copy +
                 " --tag-size 0.127 --stages sparse --threads 2 --no-preview --no-tags-in-ba --no-reextraction");
  ASSERT_EQ(without.exit_code, 0) << without.output;
  EXPECT_NE(without.output.find("features  reused"), std::string::npos) << without.output;
  const TagFigures alone = ReadTagFigures(copy);
  std::printf("tags not in BA:  %d tags, held-out edges mean %.5f m, spread %.5f m (%.2f %%), max |error| %.5f m "
              "(%.2f %%)\n",
              alone.tags, alone.edge_mean, alone.edge_std, 100 * alone.edge_std / kSwatTagSize, alone.edge_max_error,
              100 * alone.edge_max_error / kSwatTagSize);
  // What the corner constraints are for: the tags measure at least as well with them as without.
  EXPECT_EQ(alone.tags, with.tags);
  EXPECT_LE(with.edge_std, alone.edge_std);
}

}  // namespace
}  // namespace reconar
