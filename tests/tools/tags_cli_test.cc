// `reconar tags`: the printed sheet, rasterised by independent renderers (librsvg for SVG,
// poppler for PDF) at a known resolution, must be detected by libapriltag with the right ids and
// with tag edges of exactly the requested size.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/io/image_io.h"
#include "tests/support/run_command.h"
#include "tracker/tag_detector.h"

namespace reconar {
namespace {

using testing::RunCommand;
using testing::RunReconar;

constexpr double kDpi = 300.0;
constexpr double kPixelsPerMm = kDpi / 25.4;

bool HaveTool(const std::string& tool) { return RunCommand("command -v " + tool + " >/dev/null").exit_code == 0; }

struct SheetMeasurement {
  int width = 0;
  int height = 0;
  std::map<int, double> mean_edge_px;  // per id
  int detections = 0;
};

SheetMeasurement Measure(const std::string& png) {
  SheetMeasurement measurement;
  auto image = ReadImage(png);
  EXPECT_TRUE(image.ok()) << image.status().ToString();
  if (!image.ok()) return measurement;
  const Image<uint8_t> gray = ToGray8(image->rgb);
  measurement.width = gray.width();
  measurement.height = gray.height();
  TagDetectorOptions options;
  options.quad_decimate = 4.0f;  // tags hundreds of pixels wide; edges are refined at full resolution
  auto detector = TagDetector::Create(options);
  EXPECT_TRUE(detector.ok());
  TagDetectionList detections(64);
  EXPECT_TRUE((*detector)->Detect(gray.view(), &detections).ok());
  measurement.detections = detections.size();
  for (const TagDetection& d : detections) {
    double edges = 0.0;
    for (int k = 0; k < 4; ++k) edges += (d.corners[(k + 1) % 4] - d.corners[k]).norm();
    measurement.mean_edge_px[d.id] = edges / 4.0;
  }
  return measurement;
}

void ExpectSheet(const SheetMeasurement& m, double size_mm, int first_id, int last_id) {
  // A4 at 300 dpi is 2480.3 x 3507.9 px; rasterisers round the page up or to nearest.
  EXPECT_NEAR(m.width, 210.0 * kPixelsPerMm, 1.0);
  EXPECT_NEAR(m.height, 297.0 * kPixelsPerMm, 1.0);
  EXPECT_EQ(m.detections, last_id - first_id + 1);
  const double expected_px = size_mm * kPixelsPerMm;
  for (int id = first_id; id <= last_id; ++id) {
    ASSERT_EQ(m.mean_edge_px.count(id), 1u) << "id " << id;
    // Rasterisers snap each edge to the pixel grid: up to half a pixel per side.
    EXPECT_NEAR(m.mean_edge_px.at(id), expected_px, 1.0) << "id " << id;
    std::printf("id %d: edge %.2f px, expected %.2f px (%.3f %%)\n", id, m.mean_edge_px.at(id), expected_px,
                100.0 * (m.mean_edge_px.at(id) / expected_px - 1.0));
  }
}

TEST(TagsCli, SvgRasterisedByLibrsvgHasExactTagSize) {
  if (!HaveTool("rsvg-convert")) GTEST_SKIP() << "rsvg-convert (librsvg2-bin) not installed";
  const std::string dir = testing::MakeTestDirectory("reconar_tags_svg");
  const auto run = RunReconar("tags --ids 0-3 --size 0.06 --out " + dir + "/sheet.svg");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto raster = RunCommand("rsvg-convert --dpi-x 300 --dpi-y 300 -b white -o " + dir + "/sheet.png " + dir +
                                 "/sheet.svg");
  ASSERT_EQ(raster.exit_code, 0) << raster.output;
  ExpectSheet(Measure(dir + "/sheet.png"), 60.0, 0, 3);
}

TEST(TagsCli, PdfRasterisedByPopplerHasExactTagSizeAndPages) {
  if (!HaveTool("pdftoppm")) GTEST_SKIP() << "pdftoppm (poppler-utils) not installed";
  const std::string dir = testing::MakeTestDirectory("reconar_tags_pdf");
  const auto run = RunReconar("tags --ids 10-13 --size 0.06 --out " + dir + "/sheet.pdf");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto raster = RunCommand("pdftoppm -r 300 -png -singlefile " + dir + "/sheet.pdf " + dir + "/sheet");
  ASSERT_EQ(raster.exit_code, 0) << raster.output;
  ExpectSheet(Measure(dir + "/sheet.png"), 60.0, 10, 13);

  // Twelve 60 mm tags do not fit on one A4 page: the PDF gets more pages, each readable.
  const auto many = RunReconar("tags --ids 0-11 --size 0.06 --out " + dir + "/many.pdf");
  ASSERT_EQ(many.exit_code, 0) << many.output;
  const auto info = RunCommand("pdfinfo " + dir + "/many.pdf");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const size_t pages = info.output.find("Pages:");
  ASSERT_NE(pages, std::string::npos) << info.output;
  EXPECT_EQ(std::atoi(info.output.c_str() + pages + 6), 2) << info.output;
}

TEST(TagsCli, BadArgumentsFailWithAClearMessageAndWriteNothing) {
  const std::string dir = testing::MakeTestDirectory("reconar_tags_bad");
  auto run = RunReconar("tags --ids 0-3 --size 0.06 --out " + dir + "/sheet.txt");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("must end in .svg or .pdf"), std::string::npos) << run.output;
  run = RunReconar("tags --ids 0-600 --size 0.06 --out " + dir + "/sheet.svg");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("has ids 0..586, not 587"), std::string::npos) << run.output;
  run = RunReconar("tags --ids 0 --size 0.5 --out " + dir + "/sheet.svg");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("does not fit"), std::string::npos) << run.output;
  run = RunReconar("tags --ids 0 --size 0.05 --family tag99h1 --out " + dir + "/sheet.svg");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("unknown tag family"), std::string::npos) << run.output;
  EXPECT_EQ(RunCommand("ls " + dir + " | wc -l").output, "0\n");
}

// `reconar tags PHOTO --json` on a swatbotics photo lists the ids the dataset's groundtruth.txt
// gives for it (a human-made list: "IMG_1369.JPG 11 13 19"), with the photo's size and the
// corners inside it, in the program's pixel convention (centre of the top-left pixel at (0, 0)).
TEST(TagsCli, JsonListsTheTagsInAPhoto) {
  const std::string data = std::string(RECONAR_SHARED_DATA_DIR) + "/apriltag_swatbotics_mapping";
  std::set<int> expected;
  std::ifstream truth(data + "/groundtruth.txt");
  for (std::string line; std::getline(truth, line);) {
    std::istringstream fields(line);
    std::string name;
    fields >> name;
    if (name != "IMG_1369.JPG") continue;
    for (int id = 0; fields >> id;) expected.insert(id);
  }
  ASSERT_EQ(expected, (std::set<int>{11, 13, 19})) << "groundtruth.txt";
  const auto run = RunReconar("tags " + data + "/IMG_1369.JPG --json", testing::StderrMode::kSeparate);
  ASSERT_EQ(run.exit_code, 0) << run.error;
  ASSERT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  auto json = ParseJson(run.output, "tags --json");
  ASSERT_TRUE(json.ok()) << json.status().ToString();
  EXPECT_EQ(json->Find("image")->string(), "IMG_1369.JPG");
  EXPECT_EQ(json->Find("width")->number(), 816.0);
  EXPECT_EQ(json->Find("height")->number(), 612.0);
  const JsonValue& tags = *json->Find("tags");
  std::set<int> found;
  for (size_t i = 0; i < tags.size(); ++i) {
    found.insert(static_cast<int>(tags[i].Find("id")->number()));
    EXPECT_EQ(tags[i].Find("family")->string(), "tag36h11");
    EXPECT_LE(tags[i].Find("hamming")->number(), 1.0);
    EXPECT_GT(tags[i].Find("decision_margin")->number(), 0.0);
    const JsonValue& corners = *tags[i].Find("corners");
    ASSERT_EQ(corners.size(), 4u);
    for (size_t k = 0; k < 4; ++k) {
      EXPECT_GE(corners[k][0].number(), -0.5);
      EXPECT_LE(corners[k][0].number(), 815.5);
      EXPECT_GE(corners[k][1].number(), -0.5);
      EXPECT_LE(corners[k][1].number(), 611.5);
    }
  }
  EXPECT_EQ(found, expected);
  EXPECT_EQ(tags.size(), expected.size());

  // Without --json: one line per photo; a photo and sheet options together are a usage error.
  const auto text = RunReconar("tags " + data + "/IMG_1369.JPG", testing::StderrMode::kSeparate);
  EXPECT_EQ(text.exit_code, 0) << text.error;
  EXPECT_EQ(text.output.rfind("IMG_1369.JPG 816x612: 3 tag(s)", 0), 0u) << text.output;
  EXPECT_EQ(RunReconar("tags " + data + "/IMG_1369.JPG --ids 0").exit_code, 2);
}

}  // namespace
}  // namespace reconar
