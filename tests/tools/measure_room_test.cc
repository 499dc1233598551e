// `reconar measure` on the swatbotics room (../shared/data/apriltag_swatbotics_mapping: 20 tags
// printed at 0.127 m). The scale from the tags on two walls only (`--scale-tags 0-8,11`); every
// other tag's four edges and two diagonals measured corner to corner against the printed size:
// at least 90 % of them within 2σ of it, with a median σ under 2 mm (an honest σ that is also
// useful). A tag corner picked in two photos lands on the model's corner within 2σ. What the model
// cannot place is an error naming the point and the reason. The JSON is read back as a script would.
// The view measures a tag's edge tapped by its pixels, and draws a design registered by `reconar compare`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/io/image_io.h"
#include "core/geometry/triangulation.h"
#include "core/mesh/glb_io.h"
#include "core/sfm/model_io.h"
#include "core/sfm/tag_layout.h"
#include "core/sfm/tag_observations.h"
#include "tests/support/design_scene.h"
#include "tests/support/ground_truth.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunReconar;

constexpr double kTagSize = 0.127;  // SOURCE.txt

// A copy of the room's shared sparse project (made here when no other test has made it yet),
// mapped again with the scale from `scale_tags`: features, matches and tags are reused.
std::string ProjectWithScaleTags(const std::string& scale_tags) {
  const std::string data = testing::SharedDataPath("apriltag_swatbotics_mapping");
  const std::string shared = testing::SharedProjectDirectory("swatbotics_room_sparse", RECONAR_BINARY);
  const CommandRun made =
      RunReconar("reconstruct " + data + " " + shared + " --tag-size 0.127 --stages sparse --threads 2 --no-preview");
  EXPECT_EQ(made.exit_code, 0) << made.output;
  const fs::path copy = fs::temp_directory_path() / ("reconar_measure_room_" + std::to_string(::getpid()));
  fs::remove_all(copy);
  fs::copy(shared, copy, fs::copy_options::recursive);
  const CommandRun run = RunReconar("sfm " + data + " " + copy.string() + " --tag-size 0.127 --scale-tags " +
                                    scale_tags + " --threads 2 --no-preview");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  return copy.string();
}

TEST(MeasureRoom, TheSigmaCoversTheTagsThatDidNotSetTheScale) {
  const std::string project = ProjectWithScaleTags("0-8,11");
  const std::set<int> scale_tags = {0, 1, 2, 3, 4, 5, 6, 7, 8, 11};
  auto tags = ReadJsonFile(project + "/tags.json");
  ASSERT_TRUE(tags.ok()) << tags.status().ToString();
  std::string items;
  std::vector<double> truths;
  const JsonValue& list = *tags->Find("tags");
  for (size_t t = 0; t < list.size(); ++t) {
    const int id = static_cast<int>(*list[t].Find("id")->AsInteger());
    if (scale_tags.count(id)) continue;
    for (int s = 0; s < 6; ++s) {
      items += " --distance tag:" + std::to_string(id) + ":c" + std::to_string(kTagSegments[s][0]) + " tag:" +
               std::to_string(id) + ":c" + std::to_string(kTagSegments[s][1]);
      truths.push_back(s < 4 ? kTagSize : kTagSize * std::sqrt(2.0));
    }
  }
  ASSERT_GE(truths.size(), 48u) << "most of the 10 other tags registered";
  const CommandRun run = RunReconar("measure " + project + items + " --json", testing::StderrMode::kSeparate);
  ASSERT_EQ(run.exit_code, 0) << run.output << run.error;
  auto json = ParseJson(run.output, "measure --json");
  ASSERT_TRUE(json.ok()) << json.status().ToString();
  EXPECT_TRUE(json->Find("metric")->bool_value());
  const JsonValue& measured = *json->Find("items");
  ASSERT_EQ(measured.size(), truths.size());
  int within = 0;
  std::vector<double> sigmas;
  for (size_t k = 0; k < measured.size(); ++k) {
    EXPECT_EQ(measured[k].Find("kind")->string(), "distance");
    EXPECT_EQ(measured[k].Find("unit")->string(), "m");
    EXPECT_EQ(measured[k].Find("points")->size(), 2u);
    const double value = measured[k].Find("value")->number(), sigma = measured[k].Find("sigma")->number();
    within += std::abs(value - truths[k]) <= 2.0 * sigma ? 1 : 0;
    sigmas.push_back(sigma);
  }
  std::sort(sigmas.begin(), sigmas.end());
  const double share = static_cast<double>(within) / static_cast<double>(truths.size());
  const double median_sigma = sigmas[sigmas.size() / 2];
  std::printf("%d of %zu check segments within 2 sigma (%.1f %%), median sigma %.2f mm\n", within, truths.size(),
              100 * share, 1000 * median_sigma);
  EXPECT_GE(share, 0.90);
  EXPECT_LE(median_sigma, 0.002);

  // A check tag's corner picked in the two registered photos that see it at the widest angle.
  auto detections = ReadTagDetections(project + "/tags/detections.txt");
  ASSERT_TRUE(detections.ok()) << detections.status().ToString();
  auto model = ReadColmapTextModel(project + "/sparse");
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  Eigen::Vector3d corner = Eigen::Vector3d::Zero();
  for (size_t t = 0; t < list.size(); ++t) {
    if (*list[t].Find("id")->AsInteger() != 15) continue;
    const JsonValue& c = (*list[t].Find("corners"))[0];
    corner = Eigen::Vector3d(c[0].number(), c[1].number(), c[2].number());
  }
  std::vector<std::string> picks;
  std::vector<Eigen::Vector3d> centres;
  for (const ImageTagObservations& image : detections->images) {
    const auto registered = std::find_if(model->images.begin(), model->images.end(),
                                         [&](const SfmImage& m) { return m.name == image.image_name && m.registered; });
    if (registered == model->images.end()) continue;
    for (const TagObservation& tag : image.tags) {
      if (tag.tag_id != 15) continue;
      std::ostringstream pick;
      pick.precision(10);
      pick << image.image_name << "@" << tag.corners[0].x() << "," << tag.corners[0].y();
      picks.push_back(pick.str());
      centres.push_back(registered->Center());
    }
  }
  ASSERT_GE(picks.size(), 2u);
  size_t first = 0, second = 1;
  for (size_t a = 0; a < picks.size(); ++a) {
    for (size_t b = a + 1; b < picks.size(); ++b) {
      if (TriangulationAngle(centres[a], centres[b], corner) > TriangulationAngle(centres[first], centres[second], corner)) {
        first = a;
        second = b;
      }
    }
  }
  const std::string pair = picks[first] + "+" + picks[second];
  std::printf("the widest pair: %.1f degrees\n", TriangulationAngle(centres[first], centres[second], corner) * 180 / M_PI);
  const CommandRun picked = RunReconar("measure " + project + " --distance " + pair + " tag:15:c0 --pick-sigma 0.2 --json",
                                       testing::StderrMode::kSeparate);
  ASSERT_EQ(picked.exit_code, 0) << picked.output << picked.error;
  auto picked_json = ParseJson(picked.output, "measure --json");
  ASSERT_TRUE(picked_json.ok()) << picked_json.status().ToString();
  const JsonValue& gap = (*picked_json->Find("items"))[0];
  std::printf("tag 15 corner 0 picked in %s: %.2f mm from the model's corner, sigma %.2f mm\n", pair.c_str(),
              1000 * gap.Find("value")->number(), 1000 * gap.Find("sigma")->number());
  EXPECT_LE(gap.Find("value")->number(), 2.0 * gap.Find("sigma")->number());
  EXPECT_LT(gap.Find("sigma")->number(), 0.01) << "a wide pair places the corner within a centimetre";

  // Points the model cannot place: exit 1 or 2 with the point and the reason; nothing on stdout.
  const struct {
    std::string item, message;
  } bad[] = {
      {"--distance tag:99 tag:0", "no registered photo shows tag 99"},
      {"--distance NOT_A_PHOTO.JPG@10,10 tag:0", "the project has no photo NOT_A_PHOTO.JPG"},
      {"--distance " + picks.front().substr(0, picks.front().find('@')) + "@5000,10 tag:0", "the pixel is outside"},
      {"--distance " + picks.front() + " tag:0", "mesh.ply is missing"},
      {"--distance tag:0", "distance takes 2 points, got 1"},
      {"--distance tag:0 tag:1:c9", "a corner is c0, c1, c2 or c3"},
  };
  for (const auto& [item, message] : bad) {
    const CommandRun refused = RunReconar("measure " + project + " " + item, testing::StderrMode::kSeparate);
    EXPECT_TRUE(refused.exit_code == 1 || refused.exit_code == 2) << item << ": " << refused.exit_code;
    EXPECT_NE(refused.error.find(message), std::string::npos) << item << ": " << refused.error;
    EXPECT_TRUE(refused.output.empty()) << item << ": " << refused.output;
  }
  fs::remove_all(project);
}

// Tap-to-measure in the view: 16 of the room's photos round tag 4, reconstructed whole (mesh and
// dense points); the view of one photo with --measure on tag 4's bottom edge (its corners as
// detected) draws the line and its label into the PNG and gives 0.127 m within 2σ in the JSON.
// Then a design registered to the project by `reconar compare` is drawn over the same frame.
TEST(MeasureRoom, TheViewMeasuresATagEdgeAndShowsTheDesign) {
  const std::string data = testing::SharedDataPath("apriltag_swatbotics_mapping");
  const fs::path root = fs::temp_directory_path() / ("reconar_measure_view_" + std::to_string(::getpid()));
  fs::remove_all(root);
  std::vector<std::string> names;
  for (int i = 1377; i <= 1384; ++i) names.push_back("IMG_" + std::to_string(i) + ".JPG");
  for (int i = 1412; i <= 1419; ++i) names.push_back("IMG_" + std::to_string(i) + ".JPG");
  const std::string photos = testing::LinkFiles((root / "photos").string(), data, names);
  const std::string project = (root / "project").string();
  const CommandRun made =
      RunReconar("reconstruct " + photos + " " + project + " --tag-size 0.127 --threads 2 --no-preview");
  ASSERT_EQ(made.exit_code, 0) << made.output;

  auto detections = ReadTagDetections(project + "/tags/detections.txt");
  ASSERT_TRUE(detections.ok()) << detections.status().ToString();
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero(), centre = Eigen::Vector2d::Zero();
  for (const ImageTagObservations& image : detections->images) {
    if (image.image_name != "IMG_1415.JPG") continue;
    for (const TagObservation& tag : image.tags) {
      if (tag.tag_id != 4) continue;
      a = tag.corners[0];
      b = tag.corners[1];
      for (const Eigen::Vector2d& corner : tag.corners) centre += corner / 4.0;
    }
  }
  ASSERT_GT((b - a).norm(), 10.0) << "tag 4 in IMG_1415.JPG";
  const std::string frames = testing::LinkFiles((root / "frame").string(), data, {"IMG_1415.JPG"});
  std::ostringstream pixels;
  pixels.precision(10);
  pixels << a.x() << "," << a.y() << " " << b.x() << "," << b.y();
  const CommandRun view = RunReconar("view --project " + project + " --frames " + frames + " --out " +
                                         (root / "out").string() + " --measure \"" + pixels.str() + "\" --json",
                                     testing::StderrMode::kSeparate);
  ASSERT_EQ(view.exit_code, 0) << view.output << view.error;
  auto line = ParseJson(view.output.substr(0, view.output.find('\n')), "view --json");
  ASSERT_TRUE(line.ok()) << line.status().ToString() << view.output;
  const JsonValue* measure = line->Find("measure");
  ASSERT_NE(measure, nullptr) << view.output;
  ASSERT_EQ(measure->Find("error"), nullptr) << view.output;
  const double value = measure->Find("value")->number(), sigma = measure->Find("sigma")->number();
  std::printf("tag 4's edge tapped in IMG_1415.JPG: %.2f mm, sigma %.2f mm, %.2f ms\n", 1000 * value, 1000 * sigma,
              measure->Find("ms")->number());
  EXPECT_EQ(measure->Find("unit")->string(), "m");
  EXPECT_LE(std::abs(value - kTagSize), 2.0 * sigma);
  EXPECT_LT(sigma, 0.015) << "a σ that still says something about a 127 mm edge";
  EXPECT_LT(measure->Find("ms")->number(), 33.0) << "within a frame at 30 Hz";

  // The line is drawn into the PNG: its middle is the line's yellow.
  auto png = ReadImage((root / "out" / "IMG_1415.png").string());
  ASSERT_TRUE(png.ok()) << png.status().ToString();
  const Eigen::Vector2d middle = 0.5 * (a + b);
  const uint8_t* pixel = png->rgb.row(static_cast<int>(std::lround(middle.y()))) + 3 * std::lround(middle.x());
  EXPECT_EQ(pixel[0], 255);
  EXPECT_EQ(pixel[1], 255);
  EXPECT_EQ(pixel[2], 0);

  // A malformed --measure.
  const CommandRun bad = RunReconar("view --project " + project + " --frames " + frames + " --out " +
                                    (root / "out").string() + " --measure 1,2,3", testing::StderrMode::kSeparate);
  EXPECT_EQ(bad.exit_code, 2) << bad.error;
  EXPECT_NE(bad.error.find("expected \"X1,Y1 X2,Y2\""), std::string::npos) << bad.error;

  // A design of the room's tags as plates standing 2.5 cm off the wall, in millimetres in a frame
  // of its own, placed by the tags' centres (`reconar compare`), drawn by the view over the same
  // frame: tag 4's middle turns toward the design's cyan, and nothing changes on the as-built layer.
  auto layout = ReadTagLayout(project + "/tags.layout");
  ASSERT_TRUE(layout.ok()) << layout.status().ToString();
  const Eigen::Vector3d design_origin(10.0, 20.0, 0.0);
  std::vector<NamedMesh> plates;
  std::ostringstream control;
  control.precision(12);
  for (const LayoutTag& tag : layout->tags()) {
    const double half = tag.size / 2;
    Mesh plate = testing::BoxMesh({-half, -half, 0.02}, {half, half, 0.03});
    for (Eigen::Vector3f& v : plate.positions) {
      v = (1000.0 * (tag.layout_from_tag * v.cast<double>() + design_origin)).cast<float>();
    }
    plates.push_back({"plate_" + std::to_string(tag.id), plate});
    const Eigen::Vector3d centre_mm = 1000.0 * (tag.layout_from_tag.translation + design_origin);
    control << tag.id << " " << centre_mm.x() << " " << centre_mm.y() << " " << centre_mm.z() << "\n";
  }
  const std::string design = (root / "plates.glb").string(), control_path = (root / "plates.txt").string();
  ASSERT_TRUE(WriteGlbScene(design, plates).ok());
  ASSERT_TRUE(WriteFileAtomically(control_path, control.str()).ok());
  const CommandRun not_yet = RunReconar("view --project " + project + " --frames " + frames + " --out " +
                                            (root / "design").string() + " --design " + design,
                                        testing::StderrMode::kSeparate);
  EXPECT_NE(not_yet.exit_code, 0);
  EXPECT_NE(not_yet.error.find("reconar compare"), std::string::npos) << not_yet.error;
  const CommandRun compared = RunReconar("compare " + project + " " + design + " --control " + control_path);
  ASSERT_EQ(compared.exit_code, 0) << compared.output;
  EXPECT_NE(compared.output.find("units mm"), std::string::npos) << compared.output;
  const auto tint = [&](const std::string& layer) {  // (G + B) / 2 - R about tag 4's middle
    const fs::path out = root / layer;
    const CommandRun drawn = RunReconar("view --project " + project + " --frames " + frames + " --out " + out.string() +
                                            " --design " + design + " --layer " + layer,
                                        testing::StderrMode::kSeparate);
    EXPECT_EQ(drawn.exit_code, 0) << drawn.error;
    auto picture = ReadImage((out / "IMG_1415.png").string());
    if (!picture.ok()) return -1000.0;
    double sum = 0.0;
    int count = 0;
    for (int dy = -3; dy <= 3; ++dy) {
      for (int dx = -3; dx <= 3; ++dx) {
        const uint8_t* p = picture->rgb.row(static_cast<int>(std::lround(centre.y())) + dy) +
                           3 * (std::lround(centre.x()) + dx);
        sum += 0.5 * (p[1] + p[2]) - p[0];
        ++count;
      }
    }
    return sum / count;
  };
  const double as_built = tint("as-built"), with_design = tint("design");
  std::printf("tag 4's middle: (G + B) / 2 - R %.1f as built, %.1f with the design over it\n", as_built, with_design);
  EXPECT_GT(with_design, as_built + 40.0);
  fs::remove_all(root);
}

}  // namespace
}  // namespace reconar
