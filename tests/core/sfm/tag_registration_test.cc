// Tag registration (core/sfm/tag_registration.h) on a synthetic scene whose metric truth is known:
// three tags in a world frame, cameras looking at them, the model an arbitrary similarity of the
// world. Also the tag corner correspondences handed to the mapper.
#include "core/sfm/tag_registration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/base/atomic_file.h"
#include "core/math/rigid3.h"

namespace reconar {
namespace {

constexpr double kTagSize = 0.16;

struct Scene {
  std::vector<Rigid3> world_from_tag;  // tag ids 0, 1, 2
  Sim3 model_from_world;
  Reconstruction model;  // cameras in the model frame
  std::vector<std::vector<TagObservation>> observations;
  std::vector<Eigen::Vector3d> camera_centres_world;
};

Eigen::Vector3d TagCorner(const Rigid3& world_from_tag, int k, double size = kTagSize) {
  return world_from_tag * (Eigen::Vector3d(kTagCornerUnits[k][0], kTagCornerUnits[k][1], 0.0) * size / 2.0);
}

// Tag 2 is printed `tag2_scale` times the nominal size.
Scene MakeScene(double tag2_scale = 1.0) {
  Scene scene;
  scene.world_from_tag.push_back(Rigid3::Identity());
  scene.world_from_tag.push_back(
      Rigid3{Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()).toRotationMatrix(), Eigen::Vector3d(0.6, 0.05, -0.1)});
  scene.world_from_tag.push_back(
      Rigid3{Eigen::AngleAxisd(-0.4, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix(),
             Eigen::Vector3d(-0.5, 0.4, 0.05)});
  scene.model_from_world.scale = 3.7;
  scene.model_from_world.rotation =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, -1, 0.4).normalized()).toRotationMatrix();
  scene.model_from_world.translation = Eigen::Vector3d(5, -2, 9);

  SfmCamera camera;
  camera.width = 800;
  camera.height = 600;
  camera.focal = 700;
  camera.cx = 401;
  camera.cy = 297;
  camera.k1 = -0.04;
  camera.k2 = 0.01;
  scene.model.cameras.push_back(camera);
  for (int c = 0; c < 6; ++c) {
    const double angle = -0.6 + 0.24 * c;
    const Eigen::Vector3d centre(2.0 * std::sin(angle), 0.3 * std::cos(3.0 * angle), 2.0 * std::cos(angle));
    scene.camera_centres_world.push_back(centre);
    const Rigid3 cam_from_world = CamFromWorldLookingAt(centre, Eigen::Vector3d(0, 0.1, 0), Eigen::Vector3d::UnitY());
    // cam_from_model: X_cam = R_c X_world + t_c with X_world = R^T (X_model - t) / s, scaled by s.
    const Sim3& m = scene.model_from_world;
    SfmImage image;
    image.name = "view" + std::to_string(c);
    image.camera_id = 0;
    image.registered = true;
    image.cam_from_world.rotation = cam_from_world.rotation * m.rotation.transpose();
    image.cam_from_world.translation =
        m.scale * cam_from_world.translation - image.cam_from_world.rotation * m.translation;
    std::vector<TagObservation> seen;
    for (int id = 0; id < 3; ++id) {
      TagObservation tag;
      tag.tag_id = id;
      for (int k = 0; k < 4; ++k) {
        const double size = id == 2 ? tag2_scale * kTagSize : kTagSize;
        const Eigen::Vector3d model_point = m.Apply(TagCorner(scene.world_from_tag[static_cast<size_t>(id)], k, size));
        tag.corners[static_cast<size_t>(k)] = camera.Project(image.cam_from_world * model_point);
      }
      seen.push_back(tag);
    }
    scene.model.images.push_back(image);
    scene.observations.push_back(seen);
  }
  return scene;
}

TEST(TagRegistrationTest, RecoversMetresAndTheWorldTagFrame) {
  Scene scene = MakeScene();
  TagRegistrationOptions options;
  options.tag_size_m = kTagSize;
  auto report = RegisterToTags(scene.observations, {}, options, &scene.model);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_TRUE(report->metric) << report->reason;
  EXPECT_EQ(report->world_tag, 0);
  EXPECT_EQ(report->tags_seen, 3);
  ASSERT_EQ(report->tags.size(), 3u);
  EXPECT_NEAR(report->metres_per_model_unit, 1.0 / 3.7, 1e-9);
  for (const RegisteredTag& tag : report->tags) {
    EXPECT_EQ(tag.views, 6);
    EXPECT_FALSE(tag.adjusted);
    EXPECT_LT(tag.rms_reprojection_px, 1e-6);
    for (int k = 0; k < 4; ++k) {
      EXPECT_LT((tag.corners[static_cast<size_t>(k)] - TagCorner(scene.world_from_tag[static_cast<size_t>(tag.id)], k))
                    .norm(),
                1e-7);
      EXPECT_NEAR(tag.edges_m[static_cast<size_t>(k)], kTagSize, 1e-7);
    }
    EXPECT_LT(RotationAngle(tag.world_from_tag.rotation, scene.world_from_tag[static_cast<size_t>(tag.id)].rotation),
              1e-7);
  }
  EXPECT_LT(report->edge_max_abs_error_m, 1e-7);
  // The cameras moved with the model.
  for (size_t c = 0; c < scene.model.images.size(); ++c) {
    EXPECT_LT((scene.model.images[c].Center() - scene.camera_centres_world[c]).norm(), 1e-7);
  }
}

// The world frame comes from the world tag fitted as a rigid square to its corners' observations,
// not from its four corner points alone: here those points (adjusted tracks) are tilted by about 7
// degrees about the tag's x axis while every view sees the true tag. Fitted to those points the
// frame would be 7 degrees off (cameras 0.2 m); fitted to the views it is right to a few hundredths
// of a degree (the square's edge is the adjusted tags' mean, tag 0's, stretched by the tilt).
TEST(TagRegistrationTest, TheWorldTagIsFittedAsASquareToItsViews) {
  Scene scene = MakeScene();
  const Sim3& m = scene.model_from_world;
  std::vector<TagCornerKeypoint> corner_keypoints;
  for (int k = 0; k < 4; ++k) {
    SfmPoint point;
    const double lift = kTagCornerUnits[k][1] * 0.01;  // metres along the tag's z: corners 2, 3 up, 0, 1 down
    point.position = m.Apply(TagCorner(scene.world_from_tag[0], k) + Eigen::Vector3d(0, 0, lift));
    for (size_t c = 0; c < scene.model.images.size(); ++c) point.track.push_back({static_cast<int>(c), k});
    scene.model.points.push_back(point);
  }
  for (size_t c = 0; c < scene.model.images.size(); ++c) {
    SfmImage& image = scene.model.images[c];
    for (int k = 0; k < 4; ++k) {
      image.keypoints.push_back(scene.observations[c][0].corners[static_cast<size_t>(k)]);
      image.point3d_ids.push_back(k);
      corner_keypoints.push_back({static_cast<int>(c), k, 0, k});
    }
  }
  TagRegistrationOptions options;
  options.tag_size_m = kTagSize;
  auto report = RegisterToTags(scene.observations, corner_keypoints, options, &scene.model);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_TRUE(report->metric) << report->reason;
  ASSERT_EQ(report->world_tag, 0);
  EXPECT_TRUE(report->tags[0].adjusted);
  for (size_t c = 0; c < scene.model.images.size(); ++c) {
    const Rigid3 truth =
        CamFromWorldLookingAt(scene.camera_centres_world[c], Eigen::Vector3d(0, 0.1, 0), Eigen::Vector3d::UnitY());
    EXPECT_LT(RotationAngle(scene.model.images[c].cam_from_world.rotation, truth.rotation) * 180.0 / M_PI, 0.1);
    // The scale comes from the adjusted tag alone (tags 1 and 2 were triangulated): tag 0's side
    // edges are stretched by its tilt, by sqrt(1 + (0.02 / 0.16)^2) - 1 = 0.78 %, its mean edge by
    // 0.39 %, so the cameras, about 2.05 m away, sit 8 mm off.
    EXPECT_NEAR((scene.model.images[c].Center() - scene.camera_centres_world[c]).norm(), 0.0080, 0.0005);
  }
}

// A tag of the wrong size shows in the held-out figures: it is measured at the scale of the
// others, which are exact, while the plain mean is the nominal size by construction.
TEST(TagRegistrationTest, HeldOutEdgesMeasureEachTagAtTheOtherTagsScale) {
  Scene scene = MakeScene(1.03);
  TagRegistrationOptions options;
  options.tag_size_m = kTagSize;
  auto report = RegisterToTags(scene.observations, {}, options, &scene.model);
  ASSERT_TRUE(report.ok() && report->metric);
  ASSERT_EQ(report->tags.size(), 3u);
  EXPECT_NEAR(report->edge_mean_m, kTagSize, 1e-9);
  // Tags 0 and 1 at the scale of {1, 2} or {0, 2}, whose mean edge is 1.015 x nominal.
  const double small = kTagSize / 1.015, large = 1.03 * kTagSize;
  EXPECT_NEAR(report->held_out_edge_max_abs_error_m, large - kTagSize, 1e-7);
  EXPECT_NEAR(report->held_out_edge_mean_m, (2 * small + large) / 3, 1e-7);
  const double mean = (2 * small + large) / 3;
  EXPECT_NEAR(report->held_out_edge_std_m,
              std::sqrt((2 * (small - mean) * (small - mean) + (large - mean) * (large - mean)) / 3), 1e-7);
}

// --scale-tags: tags 0 and 1 (exact) set the scale, tag 2 (printed 3 % large) is registered all the
// same and measured at their scale; a list of tags that were not reconstructed is no scale.
TEST(TagRegistrationTest, ScaleTagsSetTheScaleAndTheOthersCheckIt) {
  Scene scene = MakeScene(1.03);
  TagRegistrationOptions options;
  options.tag_size_m = kTagSize;
  options.scale_tags = {0, 1};
  auto report = RegisterToTags(scene.observations, {}, options, &scene.model);
  ASSERT_TRUE(report.ok() && report->metric);
  EXPECT_EQ(report->scale_tags, (std::vector<int>{0, 1}));
  EXPECT_NEAR(report->metres_per_model_unit, 1.0 / 3.7, 1e-9);
  ASSERT_EQ(report->tags.size(), 3u);
  for (double edge : report->tags[2].edges_m) EXPECT_NEAR(edge, 1.03 * kTagSize, 1e-7);
  // Held out: tags 0 and 1 at each other's scale (exact), tag 2 as measured.
  EXPECT_EQ(report->held_out_edges, 12);
  EXPECT_NEAR(report->held_out_edge_max_abs_error_m, 0.03 * kTagSize, 1e-7);
  EXPECT_NEAR(report->held_out_edge_mean_m, (2 + 1.03) / 3 * kTagSize, 1e-7);

  Scene other = MakeScene();
  options.scale_tags = {5, 6};
  auto none = RegisterToTags(other.observations, {}, options, &other.model);
  ASSERT_TRUE(none.ok()) << none.status().ToString();
  EXPECT_FALSE(none->metric);
  EXPECT_NE(none->reason.find("scale tags"), std::string::npos) << none->reason;
}

// A declared layout sets the world frame: the scene's tags placed in a frame turned and moved
// from the world, the model lands in that frame; from all its tags, or from the one it holds.
TEST(TagRegistrationTest, ALayoutSetsTheFrameFromTheTagsItHolds) {
  const Rigid3 layout_from_world{Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, 1, -0.2).normalized()).toRotationMatrix(),
                                 Eigen::Vector3d(1.5, -0.4, 2.0)};
  for (const std::vector<int>& ids : {std::vector<int>{0, 1, 2}, std::vector<int>{1}}) {
    Scene scene = MakeScene();
    TagRegistrationOptions options;
    options.tag_size_m = kTagSize;
    for (int id : ids) {
      ASSERT_TRUE(options.layout.Add({id, kTagSize, layout_from_world * scene.world_from_tag[static_cast<size_t>(id)]}).ok());
    }
    auto report = RegisterToTags(scene.observations, {}, options, &scene.model);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    ASSERT_TRUE(report->metric) << report->reason;
    EXPECT_EQ(report->layout_tags, ids);
    EXPECT_LT(report->layout_max_m, 1e-7);
    for (const RegisteredTag& tag : report->tags) {
      for (int k = 0; k < 4; ++k) {
        EXPECT_LT((tag.corners[static_cast<size_t>(k)] -
                   layout_from_world * TagCorner(scene.world_from_tag[static_cast<size_t>(tag.id)], k))
                      .norm(),
                  1e-7);
      }
    }
    for (size_t c = 0; c < scene.model.images.size(); ++c) {
      EXPECT_LT((scene.model.images[c].Center() - layout_from_world * scene.camera_centres_world[c]).norm(), 1e-7);
    }
    const std::string json = TagRegistrationJson(*report, "tag36h11", kTagSize);
    EXPECT_NE(json.find("\"frame\": \"layout\""), std::string::npos) << json;
  }
  Scene scene = MakeScene();
  TagRegistrationOptions options;
  options.tag_size_m = kTagSize;
  ASSERT_TRUE(options.layout.Add({7, kTagSize, Rigid3::Identity()}).ok());
  const auto refused = RegisterToTags(scene.observations, {}, options, &scene.model);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("holds none of the reconstructed tags (0, 1, 2)"), std::string::npos)
      << refused.status().message();
}

TEST(TagRegistrationTest, AnyCompleteTagCanBeTheWorldAndOthersAreRefused) {
  Scene scene = MakeScene();
  TagRegistrationOptions options;
  options.tag_size_m = kTagSize;
  options.world_tag = 2;
  auto report = RegisterToTags(scene.observations, {}, options, &scene.model);
  ASSERT_TRUE(report.ok() && report->metric);
  EXPECT_EQ(report->world_tag, 2);
  const RegisteredTag& tag2 = report->tags[2];
  EXPECT_LT(tag2.world_from_tag.translation.norm(), 1e-7);
  EXPECT_LT(RotationAngle(tag2.world_from_tag.rotation, Eigen::Matrix3d::Identity()), 1e-7);

  Scene other = MakeScene();
  options.world_tag = 7;
  EXPECT_EQ(RegisterToTags(other.observations, {}, options, &other.model).status().code(),
            StatusCode::kInvalidArgument);
}

TEST(TagRegistrationTest, WithoutATagInTwoViewsTheModelStaysAsItWas) {
  Scene scene = MakeScene();
  const Eigen::Vector3d centre = scene.model.images[0].Center();
  for (size_t c = 1; c < scene.observations.size(); ++c) scene.observations[c].clear();
  TagRegistrationOptions options;
  options.tag_size_m = kTagSize;
  auto report = RegisterToTags(scene.observations, {}, options, &scene.model);
  ASSERT_TRUE(report.ok());
  EXPECT_FALSE(report->metric);
  EXPECT_NE(report->reason.find("3 tag(s) seen"), std::string::npos) << report->reason;
  EXPECT_LT((scene.model.images[0].Center() - centre).norm(), 1e-12);
  options.tag_size_m = 0.0;
  EXPECT_EQ(RegisterToTags(scene.observations, {}, options, &scene.model).status().code(),
            StatusCode::kInvalidArgument);
}

TEST(TagRegistrationTest, CornersBecomeKeypointsAndMatchesOfEveryPairSharingATag) {
  std::vector<MapperImage> images(3);
  for (MapperImage& image : images) {
    image.keypoints.assign(5, Eigen::Vector2d::Zero());
    image.keypoint_scales.assign(5, 2.0f);
  }
  const auto tag = [](int id) {
    TagObservation t;
    t.tag_id = id;
    for (size_t k = 0; k < 4; ++k) t.corners[k] = Eigen::Vector2d(10.0 * id + k, 1.0);
    return t;
  };
  // Image 2 shows id 1 twice: both are dropped. Pair (0, 1) exists, stored as (1, 0).
  std::vector<std::vector<TagObservation>> observations = {{tag(1), tag(2)}, {tag(2)}, {tag(1), tag(1)}};
  std::vector<MapperPair> pairs(1);
  pairs[0].matches.image_a = 1;
  pairs[0].matches.image_b = 0;
  pairs[0].matches.matches = {{0, 0}, {1, 1}};
  const std::vector<TagCornerKeypoint> corners = AddTagCorrespondences(observations, 1.6, 2.0, &images, &pairs);
  EXPECT_EQ(corners.size(), 12u);
  EXPECT_EQ(images[0].keypoints.size(), 13u);
  EXPECT_EQ(images[1].keypoints.size(), 9u);
  EXPECT_EQ(images[2].keypoints.size(), 5u);
  EXPECT_EQ(images[0].keypoint_scales.size(), 13u);
  ASSERT_EQ(images[0].keypoint_weights.size(), 13u);
  EXPECT_EQ(images[0].keypoint_weights[4], 0.0f);
  EXPECT_EQ(images[0].keypoint_weights[5], 2.0f);
  EXPECT_EQ(images[0].keypoints[9], Eigen::Vector2d(20, 1));  // tag 2, corner 0
  ASSERT_EQ(pairs.size(), 1u);                                // no new pair: image 2 keeps no tag
  ASSERT_EQ(pairs[0].matches.matches.size(), 6u);
  // Tag 2 is keypoints 9..12 of image 0 and 5..8 of image 1; the pair is (1, 0).
  EXPECT_EQ(pairs[0].matches.matches[2].index_a, 5);
  EXPECT_EQ(pairs[0].matches.matches[2].index_b, 9);
  EXPECT_EQ(pairs[0].matches.matches[5].index_a, 8);
  EXPECT_EQ(pairs[0].matches.matches[5].index_b, 12);
}

TEST(TagRegistrationTest, DetectionsFileRoundTripsAndNamesBadLines) {
  const std::string dir = ::testing::TempDir();
  TagDetectionsFile file;
  file.family = "tag36h11";
  ImageTagObservations image;
  image.image_name = "a.jpg";
  TagObservation tag;
  tag.tag_id = 7;
  for (size_t k = 0; k < 4; ++k) tag.corners[k] = Eigen::Vector2d(0.1 + k, 1.0 / 3.0 + k);
  image.tags.push_back(tag);
  file.images.push_back(image);
  file.images.push_back({"b.jpg", {}});
  const std::string path = dir + "/reconar_tag_detections.txt";
  ASSERT_TRUE(WriteTagDetections(path, file).ok());
  auto read = ReadTagDetections(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->family, "tag36h11");
  ASSERT_EQ(read->images.size(), 2u);
  ASSERT_EQ(read->images[0].tags.size(), 1u);
  EXPECT_EQ(read->images[0].tags[0].tag_id, 7);
  EXPECT_EQ(read->images[0].tags[0].corners[3], tag.corners[3]);
  EXPECT_TRUE(read->images[1].tags.empty());
  ASSERT_TRUE(WriteFileAtomically(path, "# reconar tag detections v1\nimage a.jpg 1\n7 1 2 3\n").ok());
  const Status bad = ReadTagDetections(path).status();
  EXPECT_EQ(bad.code(), StatusCode::kCorruptData);
  EXPECT_NE(bad.message().find("line 3"), std::string::npos) << bad.ToString();
}

}  // namespace
}  // namespace reconar
