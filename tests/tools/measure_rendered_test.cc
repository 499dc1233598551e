// `reconar measure` against exact truth: the textured box (tests/core/mvs/pmvs/textured_box_scene.h,
// a box on a ground square under seeded value noise, rendered on the CPU with exact pinhole
// cameras) photographed from a ring of cameras and reconstructed without tags, so values and σ
// are in model units. Points on the box and the ground are picked by their exact pixels in the two
// photos that see them at the widest angle (a triangulated pair, pick σ near zero: the σ is the
// reconstruction's own), and each distance between two of them, brought to the truth's units by
// the ratio of the sparse points' RMS spread in truth and in the model (the normalisation an
// untagged project's σ is relative to; the true points triangulated from the same observations
// with the true cameras), is checked against the true distance: at least 90 % within 2σ. Each point
// picked by one pixel alone, met with the mesh, either lands within 2σ of its triangulated pick or
// is refused as a surface the mesh misses (the dense stage lost the box's top, which every camera
// sees at 65° from its normal: the rays met the ground behind it): never a wrong point with a small σ.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/json_reader.h"
#include "core/geometry/triangulation.h"
#include "core/io/image_write.h"
#include "core/sfm/model_io.h"
#include "tests/core/mvs/pmvs/textured_box_scene.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunReconar;
using testing::TexturedBoxScene;
using testing::TexturedBoxSceneOptions;

std::string ViewName(size_t index) {
  char name[32];
  std::snprintf(name, sizeof(name), "view_%02zu.png", index);
  return name;
}

// RMS distance of the points from their centroid.
double Spread(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centroid += p / static_cast<double>(points.size());
  double squares = 0.0;
  for (const Eigen::Vector3d& p : points) squares += (p - centroid).squaredNorm();
  return std::sqrt(squares / static_cast<double>(points.size()));
}

TEST(MeasureRendered, TheSigmaCoversExactDistancesOnTheTexturedBox) {
  TexturedBoxSceneOptions options;
  options.num_cameras = 16;
  options.width = 640;
  options.height = 480;
  options.focal = 500.0;
  const TexturedBoxScene scene(options);
  const fs::path root = fs::temp_directory_path() / ("reconar_measure_rendered_" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root / "images");
  for (size_t i = 0; i < scene.views().size(); ++i) {
    const DenseView& view = scene.views()[i];
    ASSERT_TRUE(WritePng((root / "images" / ViewName(i)).string(), view.rgb.view(), 3).ok());
  }
  const std::string project = (root / "project").string();
  const CommandRun made = RunReconar("reconstruct " + (root / "images").string() + " " + project +
                                     " --threads 2 --no-preview --formats ply");
  ASSERT_EQ(made.exit_code, 0) << made.output;
  auto model = ReadColmapTextModel(project + "/sparse");
  ASSERT_TRUE(model.ok()) << model.status().ToString();

  // Which view each registered image is, and the model's scale against the truth.
  std::vector<int> view_of_image(model->images.size(), -1);
  int registered = 0;
  for (size_t m = 0; m < model->images.size(); ++m) {
    for (size_t i = 0; i < scene.views().size(); ++i) {
      if (model->images[m].registered && model->images[m].name == ViewName(i)) view_of_image[m] = static_cast<int>(i);
    }
    registered += view_of_image[m] >= 0 ? 1 : 0;
  }
  ASSERT_GE(registered, 14) << "of 16 views";
  std::vector<Eigen::Vector3d> model_points, true_points;
  for (const SfmPoint& point : model->points) {
    if (point.deleted || point.track.size() < 2) continue;
    std::vector<TriangulationView> views;
    for (const TrackElement& e : point.track) {
      const int v = view_of_image[static_cast<size_t>(e.image_id)];
      if (v < 0) continue;
      const DenseView& view = scene.views()[static_cast<size_t>(v)];
      const Eigen::Vector2d& pixel = model->images[static_cast<size_t>(e.image_id)].keypoints[static_cast<size_t>(e.keypoint_id)];
      views.push_back({view.cam_from_world, Eigen::Vector2d((pixel.x() - view.cx) / view.fx, (pixel.y() - view.cy) / view.fy),
                       view.fx});
    }
    Eigen::Vector3d truth;
    if (views.size() < 2 || !TriangulateMultiView(views, &truth)) continue;
    model_points.push_back(point.position);
    true_points.push_back(truth);
  }
  ASSERT_GE(model_points.size(), 500u);
  const double truth_per_model_unit = Spread(true_points) / Spread(model_points);

  // Points on the box's top and sides and on the ground, each picked in the two registered views
  // that see it at the widest angle.
  const std::vector<Eigen::Vector3d> targets = {
      {0.25, 0.25, 0.6},  {-0.25, 0.25, 0.6}, {-0.25, -0.25, 0.6}, {0.25, -0.25, 0.6}, {0.5, 0.1, 0.3},
      {-0.5, -0.2, 0.35}, {0.1, 0.5, 0.2},    {-0.2, -0.5, 0.4},   {1.2, 0.3, 0.0},   {-1.0, -1.0, 0.0},
      {0.5, 1.5, 0.0},    {-1.5, 0.8, 0.0}};
  std::vector<std::string> picks;
  std::vector<Eigen::Vector3d> picked;
  for (const Eigen::Vector3d& x : targets) {
    std::vector<size_t> seeing;
    for (size_t m = 0; m < model->images.size(); ++m) {
      if (view_of_image[m] < 0) continue;
      const DenseView& view = scene.views()[static_cast<size_t>(view_of_image[m])];
      const Eigen::Vector2d pixel = view.Project(x);
      if (scene.Sees(view, x) && pixel.x() > 10 && pixel.y() > 10 && pixel.x() < options.width - 10 &&
          pixel.y() < options.height - 10) {
        seeing.push_back(m);
      }
    }
    double widest = 0.0;
    std::string pick;
    for (size_t a = 0; a < seeing.size(); ++a) {
      for (size_t b = a + 1; b < seeing.size(); ++b) {
        const DenseView& va = scene.views()[static_cast<size_t>(view_of_image[seeing[a]])];
        const DenseView& vb = scene.views()[static_cast<size_t>(view_of_image[seeing[b]])];
        const double angle = TriangulationAngle(va.Center(), vb.Center(), x);
        if (angle <= widest) continue;
        widest = angle;
        std::ostringstream text;
        text.precision(10);
        text << model->images[seeing[a]].name << "@" << va.Project(x).x() << "," << va.Project(x).y() << "+"
             << model->images[seeing[b]].name << "@" << vb.Project(x).x() << "," << vb.Project(x).y();
        pick = text.str();
      }
    }
    if (pick.empty()) continue;
    picks.push_back(pick);
    picked.push_back(x);
  }
  ASSERT_GE(picks.size(), 10u) << "of 12 scene points seen twice";
  std::string items;
  std::vector<double> truths;
  for (size_t a = 0; a < picks.size(); ++a) {
    for (size_t b = a + 1; b < picks.size(); ++b) {
      items += " --distance " + picks[a] + " " + picks[b];
      truths.push_back((picked[a] - picked[b]).norm());
    }
  }
  const CommandRun run = RunReconar("measure " + project + items + " --pick-sigma 0.01 --json", testing::StderrMode::kSeparate);
  ASSERT_EQ(run.exit_code, 0) << run.output << run.error;
  auto json = ParseJson(run.output, "measure --json");
  ASSERT_TRUE(json.ok()) << json.status().ToString();
  EXPECT_FALSE(json->Find("metric")->bool_value());
  const JsonValue& measured = *json->Find("items");
  ASSERT_EQ(measured.size(), truths.size());
  int within = 0;
  std::vector<double> relative_sigmas, relative_errors;
  for (size_t k = 0; k < measured.size(); ++k) {
    const double value = truth_per_model_unit * measured[k].Find("value")->number();
    const double sigma = truth_per_model_unit * measured[k].Find("sigma")->number();
    within += std::abs(value - truths[k]) <= 2.0 * sigma ? 1 : 0;
    relative_sigmas.push_back(sigma / truths[k]);
    relative_errors.push_back(std::abs(value - truths[k]) / truths[k]);
  }
  std::sort(relative_sigmas.begin(), relative_sigmas.end());
  std::sort(relative_errors.begin(), relative_errors.end());
  const double share = static_cast<double>(within) / static_cast<double>(truths.size());
  std::printf("%d views registered; %zu distances between %zu picked scene points: %d within 2 sigma (%.1f %%), "
              "median sigma %.3f %% of the distance, median |error| %.3f %%\n",
              registered, truths.size(), picks.size(), within, 100 * share, 100 * relative_sigmas[relative_sigmas.size() / 2],
              100 * relative_errors[relative_errors.size() / 2]);
  EXPECT_GE(share, 0.90);

  int agree = 0, refused = 0;
  for (const std::string& pair : picks) {
    const std::string single = pair.substr(0, pair.find('+'));
    const CommandRun hit = RunReconar("measure " + project + " --distance " + single + " " + pair + " --pick-sigma 0.01 --json",
                                      testing::StderrMode::kSeparate);
    if (hit.exit_code != 0) {
      EXPECT_NE(hit.error.find("its surface there is missing"), std::string::npos) << hit.error;
      ++refused;
      continue;
    }
    auto gap = ParseJson(hit.output, "measure --json");
    ASSERT_TRUE(gap.ok()) << gap.status().ToString();
    const JsonValue& item = (*gap->Find("items"))[0];
    EXPECT_LE(item.Find("value")->number(), 2.0 * item.Find("sigma")->number()) << single;
    agree += item.Find("value")->number() <= 2.0 * item.Find("sigma")->number() ? 1 : 0;
  }
  std::printf("one pixel met with the mesh: %d of %zu within 2 sigma of the triangulated pick, %d refused\n", agree,
              picks.size(), refused);
  EXPECT_GE(agree, 6) << "the box's sides and the ground";
  fs::remove_all(root);
}

}  // namespace
}  // namespace reconar
