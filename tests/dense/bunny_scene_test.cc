// The rendered bunny scene against its own cameras, read back through the COLMAP text reader:
// the silhouette in each view must be bounded by the projected bunny vertices exactly as GL's
// pixel-centre rasterisation rule implies in our (0, 0)-at-the-top-left-pixel-centre convention,
// and the supersampled colour image must sit on the same pixels as the one-sample depth image.
#include "tests/dense/bunny_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/io/image_io.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"
#include "tests/render/gl_test_context.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace testing {
namespace {

const std::string kBunnyPath = std::string(RECONAR_SHARED_DATA_DIR) + "/stanford_bunny/reconstruction/bun_zipper.ply";

class BunnySceneTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto mesh = ReadPly(kBunnyPath);
    ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
    bunny_ = new Mesh(std::move(mesh).value());
  }
  static void TearDownTestSuite() {
    delete bunny_;
    bunny_ = nullptr;
  }
  void SetUp() override {
    ASSERT_NE(SharedSurfacelessContext(), nullptr);
    ASSERT_NE(bunny_, nullptr);
  }
  static Mesh* bunny_;
};
Mesh* BunnySceneTest::bunny_ = nullptr;

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

TEST_F(BunnySceneTest, CamerasLookAtTheBunnyFromTwoRings) {
  BunnySceneOptions options;
  const Reconstruction model = MakeBunnyCameras(*bunny_, options);
  ASSERT_EQ(model.images.size(), 40u);
  const Eigen::Vector3d target = BoundingBoxCenter(*bunny_);
  for (const SfmImage& image : model.images) {
    EXPECT_NEAR((image.Center() - target).norm(), options.distance_m, 1e-12);
    const Eigen::Vector2d pixel = model.cameras[0].Project(image.cam_from_world * target);
    EXPECT_NEAR(pixel.x(), 319.5, 1e-9);
    EXPECT_NEAR(pixel.y(), 239.5, 1e-9);
    // Image "up" (-y of the camera) points to the world's +y: the bunny stands upright.
    EXPECT_LT(image.cam_from_world.rotation.row(1).dot(Eigen::Vector3d::UnitY()), -0.5);
  }
}

// The leftmost bunny pixel column c_min (a pixel is drawn when its centre is inside a triangle)
// satisfies c_min >= u_min for the smallest projected vertex abscissa u_min, and c_min - u_min
// is spread over [0, 1) (a bit more where the extreme vertex is a thin tip). Likewise on the
// other three sides. A half-pixel error in the convention either makes some margins negative or
// moves their median to ~1.
TEST_F(BunnySceneTest, SilhouetteIsBoundedByProjectedVerticesAtPixelCentres) {
  const std::string dir = MakeTestDirectory("reconar_bunny_scene");
  BunnyProjectOptions options;
  auto report = WriteBunnyProject(*bunny_, options, dir);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->views, 40);
  // The bunny is ~57 % of the frame's height and about as wide, so its bounding rectangle is ~0.25
  // of the frame; its silhouette fills about half of that.
  EXPECT_GT(report->mean_foreground_fraction, 0.08);
  EXPECT_LT(report->mean_foreground_fraction, 0.25);
  std::printf("foreground %.3f of the image; vertices seen by >= 2 views %.3f, >= 3 views %.3f; footprint %.3f mm\n",
              report->mean_foreground_fraction, report->visibility.seen_by_2_fraction,
              report->visibility.seen_by_3_fraction, 1e3 * report->pixel_footprint_at_center_m);

  // The cameras as the dense stage will see them: through the COLMAP text reader.
  auto model = ReadColmapTextModel(dir + "/sparse");
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  ASSERT_EQ(model->images.size(), 40u);
  ASSERT_EQ(model->cameras.size(), 1u);
  EXPECT_EQ(model->points.size(), 0u);
  auto list = Project(dir).ReadImageList();
  ASSERT_TRUE(list.ok()) << list.status().ToString();
  ASSERT_EQ(list->size(), 40u);

  auto renderer = BunnyRenderer::Create(*bunny_, options.scene);
  ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();
  const SfmCamera& camera = model->cameras[0];
  std::vector<double> margins;
  Image<float> depth;
  for (size_t i = 0; i < model->images.size(); ++i) {
    const SfmImage& image = model->images[i];
    EXPECT_EQ(image.name, (*list)[i].name);
    ASSERT_TRUE((*renderer)->RenderDepth(camera, image.cam_from_world, &depth).ok());
    int c_min = depth.width(), c_max = -1, r_min = depth.height(), r_max = -1;
    for (int y = 0; y < depth.height(); ++y) {
      for (int x = 0; x < depth.width(); ++x) {
        if (depth.row(y)[x] <= 0.0f) continue;
        c_min = std::min(c_min, x);
        c_max = std::max(c_max, x);
        r_min = std::min(r_min, y);
        r_max = std::max(r_max, y);
      }
    }
    double u_min = INFINITY, u_max = -INFINITY, v_min = INFINITY, v_max = -INFINITY;
    for (const Eigen::Vector3f& p : bunny_->positions) {
      const Eigen::Vector2d pixel = camera.Project(image.cam_from_world * (p.cast<double>()));
      u_min = std::min(u_min, pixel.x());
      u_max = std::max(u_max, pixel.x());
      v_min = std::min(v_min, pixel.y());
      v_max = std::max(v_max, pixel.y());
    }
    ASSERT_GT(u_min, 0.0);  // the whole bunny in view
    ASSERT_LT(u_max, camera.width - 1.0);
    ASSERT_GT(v_min, 0.0);
    ASSERT_LT(v_max, camera.height - 1.0);
    for (double margin : {c_min - u_min, u_max - c_max, r_min - v_min, v_max - r_max}) {
      EXPECT_GT(margin, -1e-3) << image.name;
      EXPECT_LT(margin, 2.5) << image.name;
      margins.push_back(margin);
    }
  }
  const double median = Median(margins);
  std::printf("silhouette margins: median %.3f px over %zu extremes\n", median, margins.size());
  EXPECT_GT(median, 0.2);
  EXPECT_LT(median, 0.8);

  std::printf("renders in %s/images\n", dir.c_str());
}

// The supersampled colour image sits on the same pixels as the one-sample depth image: the
// coverage-weighted centroid of RenderColor's samples (RenderCoverage) and the centroid of the
// depth image's bunny pixels both estimate the silhouette's area centroid, to ~0.01 px; a sample
// grid off by half a fine pixel would move the first by 0.25 px. And no bunny pixel is black.
TEST_F(BunnySceneTest, SupersampledColourSitsOnTheDepthSilhouette) {
  BunnySceneOptions options;
  ASSERT_EQ(options.supersampling, 2);
  const Reconstruction model = MakeBunnyCameras(*bunny_, options);
  auto renderer = BunnyRenderer::Create(*bunny_, options);
  ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();
  Image<uint8_t> rgb;
  Image<float> depth;
  Image<float> coverage;
  for (int index : {0, 7, 23, 31}) {
    const Rigid3& pose = model.images[index].cam_from_world;
    ASSERT_TRUE((*renderer)->RenderColor(model.cameras[0], pose, &rgb).ok());
    ASSERT_TRUE((*renderer)->RenderDepth(model.cameras[0], pose, &depth).ok());
    ASSERT_TRUE((*renderer)->RenderCoverage(model.cameras[0], pose, &coverage).ok());
    Eigen::Vector2d coverage_sum = Eigen::Vector2d::Zero(), depth_sum = Eigen::Vector2d::Zero();
    double coverage_weight = 0.0, depth_weight = 0.0;
    int black_on_bunny = 0;
    for (int y = 0; y < depth.height(); ++y) {
      for (int x = 0; x < depth.width(); ++x) {
        const uint8_t* p = rgb.row(y) + 3 * x;
        const float c = coverage.row(y)[x];
        coverage_sum += c * Eigen::Vector2d(x, y);
        coverage_weight += c;
        if (depth.row(y)[x] > 0.0f) {
          depth_sum += Eigen::Vector2d(x, y);
          depth_weight += 1.0;
          black_on_bunny += (p[0] | p[1] | p[2]) == 0 ? 1 : 0;
        }
      }
    }
    ASSERT_GT(depth_weight, 1000.0);
    EXPECT_EQ(black_on_bunny, 0);
    EXPECT_NEAR(coverage_weight, depth_weight, 0.01 * depth_weight);
    const Eigen::Vector2d offset = coverage_sum / coverage_weight - depth_sum / depth_weight;
    EXPECT_LT(offset.norm(), 0.05) << "view " << index << " offset " << offset.transpose();
  }
}

}  // namespace
}  // namespace testing
}  // namespace reconar
