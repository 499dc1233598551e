// ProjectMeasurer on a project written here with exact truth: a 3.2 m wall (the mesh) with two
// 0.2 m tags on it, seen by 6 cameras whose observations carry 0.3 px of noise. Distances
// between tags, between pixels picked in the photos (met with the wall, or triangulated from two
// photos) and world points come out as the scene has them, with a σ; points the model cannot
// place are errors that say why; without tags the values and σ are in model units.
#include "core/measure/measurement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "core/base/atomic_file.h"
#include "core/features/sift/sift_io.h"
#include "core/mesh/mesh_file.h"
#include "core/sfm/model_io.h"
#include "core/sfm/tag_observations.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

constexpr double kTagSize = 0.2;
const Eigen::Vector3d kTagCentres[2] = {{0.0, 0.0, 0.0}, {1.0, 0.5, 0.0}};

Eigen::Vector3d TagCorner(int tag, int corner) {
  return kTagCentres[tag] + 0.5 * kTagSize * Eigen::Vector3d(kTagCornerUnits[corner][0], kTagCornerUnits[corner][1], 0.0);
}

class MeasureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() / ("reconar_measure_" + std::to_string(::getpid()))).string();
    fs::remove_all(dir_);
    const Project project(dir_);
    fs::create_directories(project.SparseDir());
    fs::create_directories(project.FeaturesDir());
    fs::create_directories(project.MeshDir());
    fs::create_directories(dir_ + "/tags");

    Reconstruction model;
    SfmCamera camera;
    camera.focal = 1000.0;
    camera.cx = 639.5;
    camera.cy = 479.5;
    camera.width = 1280;
    camera.height = 960;
    model.cameras.push_back(camera);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> on_wall(-1.5, 1.5);
    std::normal_distribution<double> noise(0.0, 0.3);
    std::vector<Eigen::Vector3d> points;
    for (int p = 0; p < 300; ++p) points.emplace_back(on_wall(random), on_wall(random), 0.0);
    for (int tag = 0; tag < 2; ++tag) {
      for (int corner = 0; corner < 4; ++corner) points.push_back(TagCorner(tag, corner));
    }
    model.points.resize(points.size());
    TagDetectionsFile detections;
    detections.family = "tag36h11";
    for (int i = 0; i < 6; ++i) {
      SfmImage image;
      image.name = "IMG_" + std::to_string(i) + ".JPG";
      image.camera_id = 0;
      image.registered = true;
      const Eigen::Vector3d centre(-1.2 + 0.5 * i, 0.3 * (i % 2), 3.0 + 0.2 * (i % 3));
      image.cam_from_world = CamFromWorldLookingAt(centre, Eigen::Vector3d(0.3, 0.2, 0.0), Eigen::Vector3d(0, 1, 0));
      FeatureFile features;
      features.image_width = camera.width;
      features.image_height = camera.height;
      ImageTagObservations tags{image.name, {}};
      for (size_t p = 0; p < points.size(); ++p) {
        const Eigen::Vector2d pixel = camera.Project(image.cam_from_world.rotation * points[p] +
                                                     image.cam_from_world.translation);
        const bool tag_corner = p >= 300;
        if (!tag_corner) {
          if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > 1279 || pixel.y() > 959) continue;
          const Eigen::Vector2d seen = pixel + Eigen::Vector2d(noise(random), noise(random));
          SiftKeypoint keypoint;
          keypoint.x = static_cast<float>(seen.x());
          keypoint.y = static_cast<float>(seen.y());
          keypoint.scale = 1.0f;
          features.features.keypoints.push_back(keypoint);
          image.keypoints.push_back(seen);
        } else {
          const int tag = static_cast<int>(p - 300) / 4, corner = static_cast<int>(p - 300) % 4;
          if (corner == 0) tags.tags.push_back({tag, {}});
          tags.tags.back().corners[static_cast<size_t>(corner)] = pixel + 0.1 * Eigen::Vector2d(noise(random), noise(random));
        }
        image.point3d_ids.push_back(static_cast<int>(p));
        model.points[p].track.push_back({i, static_cast<int>(image.keypoints.size()) - (tag_corner ? 0 : 1)});
        if (tag_corner) image.keypoints.push_back(tags.tags.back().corners[static_cast<size_t>((p - 300) % 4)]);
      }
      features.features.descriptors.assign(128 * features.features.keypoints.size(), 0);
      ASSERT_TRUE(WriteFeatureFile(project.FeaturePath(image.name), features).ok());
      detections.images.push_back(tags);
      model.images.push_back(image);
    }
    for (size_t p = 0; p < points.size(); ++p) model.points[p].position = points[p];
    ASSERT_TRUE(WriteColmapTextModel(model, project.SparseDir()).ok());
    ASSERT_TRUE(WriteFileAtomically(project.SparseDir() + "/report.json",
                                    "{\"distortion_refined\": false, \"principal_point_refined\": false}\n").ok());
    ASSERT_TRUE(WriteTagDetections(project.TagDetectionsPath(), detections).ok());
    ASSERT_TRUE(WriteFileAtomically(project.TagsJsonPath(),
                                    "{\"metric\": true, \"tag_size_m\": 0.2, \"world_tag\": 0, \"scale_tags\": [0, 1],"
                                    " \"tags\": [{\"id\": 0}, {\"id\": 1}]}\n").ok());
    Mesh wall;
    wall.positions = {{-1.6f, -1.6f, 0}, {1.6f, -1.6f, 0}, {1.6f, 1.6f, 0}, {-1.6f, 1.6f, 0}};
    wall.triangles = {{0, 1, 2}, {0, 2, 3}};
    ASSERT_TRUE(WriteMeshFile(project.MeshDir() + "/mesh.ply", wall).ok());
    Mesh dense;  // the dense points the wall was made from: every 2 cm
    for (int x = -80; x <= 80; ++x) {
      for (int y = -80; y <= 80; ++y) dense.positions.emplace_back(0.02f * x, 0.02f * y, 0.0f);
    }
    fs::create_directories(dir_ + "/dense");
    ASSERT_TRUE(WriteMeshFile(project.DensePointsPath(), dense).ok());
    ASSERT_TRUE(WriteFileAtomically(project.MeshDir() + "/report.json", "{\"median_spacing\": 0.02}\n").ok());
    model_ = model;
  }
  void TearDown() override { fs::remove_all(dir_); }

  // "IMG_i.JPG@u,v" of a world point.
  std::string Pick(int image, const Eigen::Vector3d& point) const {
    const SfmImage& view = model_.images[static_cast<size_t>(image)];
    const Eigen::Vector2d pixel =
        model_.cameras[0].Project(view.cam_from_world.rotation * point + view.cam_from_world.translation);
    char text[128];
    std::snprintf(text, sizeof(text), "%s@%.9f,%.9f", view.name.c_str(), pixel.x(), pixel.y());
    return text;
  }

  MeasureItem Distance(const std::string& a, const std::string& b) {
    MeasureItem item;
    for (const std::string& text : {a, b}) {
      Result<MeasurePoint> point = ParseMeasurePoint(text);
      EXPECT_TRUE(point.ok()) << text << ": " << point.status().ToString();
      if (point.ok()) item.points.push_back(*point);
    }
    return item;
  }

  std::string dir_;
  Reconstruction model_;
};

TEST_F(MeasureTest, DistancesBetweenTagsPixelsAndWorldPointsAreTheScenesWithASigma) {
  Result<ProjectMeasurer> measurer = ProjectMeasurer::Open(Project(dir_));
  ASSERT_TRUE(measurer.ok()) << measurer.status().ToString();
  EXPECT_TRUE(measurer->setup().metric);
  EXPECT_EQ(measurer->setup().scale_tags, (std::vector<int>{0, 1}));
  EXPECT_NEAR(measurer->setup().sigma0_px, 0.3, 0.05);

  Result<MeasuredItem> centres = measurer->Measure(Distance("tag:0", "tag:1"));
  ASSERT_TRUE(centres.ok()) << centres.status().ToString();
  EXPECT_NEAR(centres->value, std::sqrt(1.25), 1e-9);  // the model's positions are the truth here
  EXPECT_GT(centres->sigma, 0.0);
  EXPECT_LT(centres->sigma, 0.01);
  EXPECT_EQ(centres->unit, "m");

  // A wall point picked in one photo (met with the wall), in another, and in both (triangulated).
  const Eigen::Vector3d a(0.7, -0.4, 0.0), b(-0.5, 0.9, 0.0);
  for (const std::string& pick_a : {Pick(1, a), Pick(4, a), Pick(1, a) + "+" + Pick(4, a)}) {
    Result<MeasuredItem> item = measurer->Measure(Distance(pick_a, Pick(2, b)));
    ASSERT_TRUE(item.ok()) << pick_a << ": " << item.status().ToString();
    EXPECT_NEAR(item->value, (a - b).norm(), 1e-6) << pick_a;
    EXPECT_LT((item->points[0] - a).norm(), 1e-6) << pick_a;
    EXPECT_GT(item->sigma, 0.0) << pick_a;
    EXPECT_LT(item->sigma, 0.01) << pick_a;
  }
  Result<MeasuredItem> to_world = measurer->Measure(Distance("xyz:0.7,-0.4,0", Pick(3, b)));
  ASSERT_TRUE(to_world.ok()) << to_world.status().ToString();
  EXPECT_NEAR(to_world->value, (a - b).norm(), 1e-6);
  EXPECT_GT(to_world->sigma, 0.0);

  // Area of tag 1 (a polygon of its corners), height of a world point over the wall's plane.
  MeasureItem area;
  area.kind = MeasureKind::kArea;
  for (const char* corner : {"tag:1:c0", "tag:1:c1", "tag:1:c2", "tag:1:c3"}) area.points.push_back(*ParseMeasurePoint(corner));
  Result<MeasuredItem> square = measurer->Measure(area);
  ASSERT_TRUE(square.ok()) << square.status().ToString();
  EXPECT_NEAR(square->value, kTagSize * kTagSize, 1e-9);
  EXPECT_EQ(square->unit, "m2");
  MeasureItem height;
  height.kind = MeasureKind::kHeight;
  for (const char* point : {"xyz:0.2,0.1,0.35", "tag:0:c0", "tag:0:c1", "tag:1:c2"}) height.points.push_back(*ParseMeasurePoint(point));
  Result<MeasuredItem> above = measurer->Measure(height);
  ASSERT_TRUE(above.ok()) << above.status().ToString();
  EXPECT_NEAR(above->value, 0.35, 1e-9);
  height.points[3] = *ParseMeasurePoint("tag:0:c0");  // a plane through two points only
  Result<MeasuredItem> no_plane = measurer->Measure(height);
  EXPECT_EQ(no_plane.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(no_plane.status().message().find("on one line"), std::string::npos) << no_plane.status().message();

  // The view's tap: a ray from above the wall.
  Result<MeasurePoint> tapped = measurer->PointOnSurface(Eigen::Vector3d(0.7, -0.4, 2.0), Eigen::Vector3d(0, 0, -1));
  ASSERT_TRUE(tapped.ok()) << tapped.status().ToString();
  MeasureItem tap;
  tap.points = {*tapped, *ParseMeasurePoint("xyz:-0.5,0.9,0")};
  Result<MeasuredItem> tap_distance = measurer->Measure(tap);
  ASSERT_TRUE(tap_distance.ok()) << tap_distance.status().ToString();
  EXPECT_NEAR(tap_distance->value, (a - b).norm(), 1e-6);
  EXPECT_FALSE(measurer->PointOnSurface(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0, 0, 1)).ok());
  // The view's measure: two pixels of a frame from a camera of the project's kind, repeated.
  const Rigid3 frame_pose = CamFromWorldLookingAt(Eigen::Vector3d(0.1, 0.2, 2.5), Eigen::Vector3d(0.1, 0.2, 0.0),
                                                  Eigen::Vector3d(0, 1, 0));
  const RadialCamera& lens = model_.cameras[0];
  const auto pixel_of = [&](const Eigen::Vector3d& p) { return lens.Project(frame_pose.rotation * p + frame_pose.translation); };
  for (int frame = 0; frame < 3; ++frame) {
    Result<MeasuredItem> on_screen = measurer->MeasureBetweenPixels(frame_pose, lens, pixel_of(a), pixel_of(b));
    ASSERT_TRUE(on_screen.ok()) << on_screen.status().ToString();
    EXPECT_NEAR(on_screen->value, (a - b).norm(), 1e-6);
    EXPECT_GT(on_screen->sigma, 0.0);
  }
  // From behind the wall: its back face is not a surface a photo saw.
  EXPECT_FALSE(measurer->PointOnSurface(Eigen::Vector3d(0.7, -0.4, -2.0), Eigen::Vector3d(0, 0, 1)).ok());
}

TEST_F(MeasureTest, APointTheModelCannotPlaceIsAnErrorThatSaysWhy) {
  Result<ProjectMeasurer> measurer = ProjectMeasurer::Open(Project(dir_));
  ASSERT_TRUE(measurer.ok()) << measurer.status().ToString();
  const auto message = [&](const std::string& a, const std::string& b) {
    Result<MeasuredItem> item = measurer->Measure(Distance(a, b));
    return item.ok() ? std::string("ok") : item.status().message();
  };
  EXPECT_NE(message("tag:7", "tag:0").find("no registered photo shows tag 7 (tags seen: 0,1)"), std::string::npos);
  EXPECT_NE(message("NOPE.JPG@10,10", "tag:0").find("no photo NOPE.JPG"), std::string::npos);
  EXPECT_NE(message("IMG_0.JPG@2000,10", "tag:0").find("outside IMG_0.JPG (1280 x 960)"), std::string::npos);
  EXPECT_NE(message(Pick(0, Eigen::Vector3d(0.3, 1.75, 0.0)), "tag:0").find("meets no surface"), std::string::npos)
      << Pick(0, Eigen::Vector3d(0.3, 1.75, 0.0));
  EXPECT_NE(message(Pick(1, Eigen::Vector3d(0.7, -0.4, 0)) + "+" + Pick(4, Eigen::Vector3d(0.2, 0.4, 0)), "tag:0")
                .find("not of one point"),
            std::string::npos);
  MeasureItem one;
  one.points = {*ParseMeasurePoint("tag:0")};
  EXPECT_EQ(measurer->Measure(one).status().code(), StatusCode::kInvalidArgument);

  for (const char* bad : {"tag:", "tag:x", "tag:1:c4", "xyz:1,2", "xyz:1,2,3,4", "IMG@1", "@1,2", "IMG@1,2+", "plain"}) {
    EXPECT_EQ(ParseMeasurePoint(bad).status().code(), StatusCode::kInvalidArgument) << bad;
  }
  Result<MeasurePoint> pair = ParseMeasurePoint("a b@1.5,2+c@3,4e0");
  ASSERT_TRUE(pair.ok()) << pair.status().ToString();
  ASSERT_EQ(pair->pixels.size(), 2u);
  EXPECT_EQ(pair->pixels[0].image, "a b");
  EXPECT_EQ(pair->pixels[1].pixel, Eigen::Vector2d(3, 4));

  // Without the mesh a single pixel cannot be placed, a pixel pair still can.
  fs::remove(Project(dir_).MeshDir() + "/mesh.ply");
  Result<ProjectMeasurer> no_mesh = ProjectMeasurer::Open(Project(dir_));
  ASSERT_TRUE(no_mesh.ok());
  const Eigen::Vector3d a(0.7, -0.4, 0.0);
  Result<MeasuredItem> single = no_mesh->Measure(Distance(Pick(1, a), "tag:0"));
  ASSERT_FALSE(single.ok());
  EXPECT_EQ(single.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(single.status().message().find("mesh.ply"), std::string::npos) << single.status().message();
  EXPECT_TRUE(no_mesh->Measure(Distance(Pick(1, a) + "+" + Pick(4, a), "tag:0")).ok());
}

TEST_F(MeasureTest, WithoutTagsTheValuesAndSigmaAreInModelUnits) {
  fs::remove(Project(dir_).TagsJsonPath());
  Result<ProjectMeasurer> measurer = ProjectMeasurer::Open(Project(dir_));
  ASSERT_TRUE(measurer.ok()) << measurer.status().ToString();
  EXPECT_FALSE(measurer->setup().metric);
  Result<MeasuredItem> item = measurer->Measure(Distance("tag:0:c0", "tag:0:c1"));
  ASSERT_TRUE(item.ok()) << item.status().ToString();
  EXPECT_NEAR(item->value, kTagSize, 1e-9);
  EXPECT_GT(item->sigma, 0.0);  // relative to the model's size
  EXPECT_LT(item->sigma, 0.01);
  EXPECT_EQ(item->unit, "model units");
  const std::string json = MeasurementsJson(measurer->setup(), {*item});
  EXPECT_NE(json.find("\"metric\": false"), std::string::npos) << json;

  fs::remove_all(Project(dir_).SparseDir());
  Result<ProjectMeasurer> none = ProjectMeasurer::Open(Project(dir_));
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("no sparse model"), std::string::npos) << none.status().message();
}

}  // namespace
}  // namespace reconar
