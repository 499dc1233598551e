#include "core/sfm/tag_image_registration.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/math/rotation.h"
#include "core/sfm/image_registration.h"
#include "core/sfm/next_image.h"
#include "core/sfm/tag_registration.h"
#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

constexpr int kImage = 3;             // the image registered by tags
constexpr double kTagEdge = 1.0;      // scene units; the ring has radius 10
constexpr double kCornerNoise = 0.1;  // pixels, libapriltag's corner accuracy

// A ring scene with three tags near the origin facing image kImage, their corners added as
// keypoints and matches (AddTagCorrespondences), and the model at the truth: a point at the true
// corner for every corner track. Image kImage is then unregistered and keeps only `points_kept`
// of its SIFT correspondences, far too few for the ordinary registration; with `two_view`, the
// others stay matches to the registered images on tracks without a point (their points deleted).
struct TagScene {
  testing::Scene scene;
  std::vector<std::array<Eigen::Vector3d, 4>> tags;  // id = index
  std::vector<TagCornerKeypoint> corners;
  MapperModel model;
};

std::array<Eigen::Vector3d, 4> TagCorners(const Eigen::Vector3d& centre, const Eigen::Vector3d& facing) {
  const Eigen::Vector3d z = (facing - centre).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  std::array<Eigen::Vector3d, 4> corners;
  for (int k = 0; k < 4; ++k) {
    corners[static_cast<size_t>(k)] = centre + (kTagCornerUnits[k][0] * x + kTagCornerUnits[k][1] * y) * kTagEdge / 2.0;
  }
  return corners;
}

TagScene MakeTagScene(int points_kept, bool two_view = false) {
  TagScene t;
  testing::SceneOptions o;
  o.num_cameras = 8;
  o.num_points = 1000;
  t.scene = testing::MakeScene(o);
  const Eigen::Vector3d facing = CameraCenterInWorld(t.scene.poses[kImage]);
  for (const Eigen::Vector3d& centre :
       {Eigen::Vector3d(0.5, 0.0, 0.0), Eigen::Vector3d(-1.5, 1.0, 0.5), Eigen::Vector3d(1.0, -1.5, -0.5)}) {
    t.tags.push_back(TagCorners(centre, facing));
  }
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, kCornerNoise);
  std::vector<std::vector<TagObservation>> observations(t.scene.images.size());
  for (size_t i = 0; i < t.scene.images.size(); ++i) {
    const Rigid3& pose = t.scene.poses[i];
    for (size_t id = 0; id < t.tags.size(); ++id) {
      const Eigen::Vector3d centre = (t.tags[id][0] + t.tags[id][2]) / 2.0;
      const Eigen::Vector3d normal = (t.tags[id][1] - t.tags[id][0]).cross(t.tags[id][3] - t.tags[id][0]).normalized();
      if (normal.dot((CameraCenterInWorld(pose) - centre).normalized()) < 0.3) continue;
      TagObservation tag;
      tag.tag_id = static_cast<int>(id);
      bool inside = true;
      for (size_t k = 0; k < 4; ++k) {
        const Eigen::Vector3d cam = pose * t.tags[id][k];
        tag.corners[k] = t.scene.camera.Project(cam) + Eigen::Vector2d(noise(rng), noise(rng));
        inside = inside && cam.z() > 0.0 && tag.corners[k].x() > 0.0 && tag.corners[k].y() > 0.0 &&
                 tag.corners[k].x() < t.scene.camera.width - 1 && tag.corners[k].y() < t.scene.camera.height - 1;
      }
      if (inside) observations[i].push_back(tag);
    }
  }
  for (size_t i = 0; i < t.scene.images.size(); ++i) {
    // No detection scales in the scene: the corners get weights only.
    t.scene.point_of_keypoint[i].resize(t.scene.images[i].keypoints.size() + 4 * observations[i].size(), -1);
  }
  t.corners = AddTagCorrespondences(observations, 1.6, kTagCornerWeight, &t.scene.images, &t.scene.pairs);
  t.model = testing::TrueModel(t.scene);
  // A point at the true corner for each corner track.
  for (const TagCornerKeypoint& c : t.corners) {
    const int track = t.model.tracks.track_of[static_cast<size_t>(c.image_id)][static_cast<size_t>(c.keypoint_id)];
    if (track < 0 || t.model.point_of_track[static_cast<size_t>(track)] >= 0) continue;
    const int id = static_cast<int>(t.model.rec.points.size());
    SfmPoint point;
    point.position = t.tags[static_cast<size_t>(c.tag_id)][static_cast<size_t>(c.corner)];
    t.model.rec.points.push_back(point);
    t.model.track_of_point.push_back(track);
    t.model.point_of_track[static_cast<size_t>(track)] = id;
    for (const TrackElement& e : t.model.tracks.tracks[static_cast<size_t>(track)])
      t.model.AddObservation(id, e.image_id, e.keypoint_id);
  }
  testing::Unregister(&t.model, kImage);
  // Image kImage keeps `points_kept` SIFT keypoints with a track; its tag corners keep theirs.
  std::vector<int>& track_of = t.model.tracks.track_of[kImage];
  const size_t sift = t.scene.images[kImage].keypoints.size() - 4 * observations[kImage].size();
  int kept = 0;
  for (size_t kp = 0; kp < sift; ++kp) {
    if (track_of[kp] < 0 || t.model.point_of_track[static_cast<size_t>(track_of[kp])] < 0) continue;
    if (kept < points_kept) {
      ++kept;
    } else if (two_view) {
      t.model.DeletePoint(t.model.point_of_track[static_cast<size_t>(track_of[kp])]);
    } else {
      track_of[kp] = -1;
    }
  }
  return t;
}

// Drops tag `id` from what image kImage sees.
void HideTag(TagScene* t, int id) {
  std::vector<MapperTag>& tags = t->scene.images[kImage].tags;
  for (size_t i = 0; i < tags.size(); ++i) {
    if (tags[i].tag_id != id) continue;
    for (int k = 0; k < 4; ++k) t->model.tracks.track_of[kImage][static_cast<size_t>(tags[i].first_keypoint + k)] = -1;
    tags.erase(tags.begin() + static_cast<std::ptrdiff_t>(i));
    return;
  }
}

// The pose within max_rotation_deg and max_centre_error (scene units) of the truth.
void ExpectTruePose(const TagScene& t, double max_rotation_deg = 0.2, double max_centre_error = 0.05) {
  const SfmImage& img = t.model.rec.images[kImage];
  ASSERT_TRUE(img.registered);
  EXPECT_LT(RotationAngle(img.cam_from_world.rotation, t.scene.poses[kImage].rotation) * 180.0 / M_PI,
            max_rotation_deg);
  EXPECT_LT((img.Center() - CameraCenterInWorld(t.scene.poses[kImage])).norm(), max_centre_error);
}

MapperOptions Options() {
  MapperOptions options = testing::SingleThreaded();
  return options;
}

TEST(TagImageRegistrationTest, TheSceneSeesThreeTagsInTheImageAndFewPoints) {
  const TagScene t = MakeTagScene(5);
  ASSERT_EQ(t.scene.images[kImage].tags.size(), 3u);
  const std::vector<KnownTag> known = KnownTags(t.model, t.scene.images, kImage, Options());
  ASSERT_EQ(known.size(), 3u);
  for (const KnownTag& tag : known) {
    for (size_t k = 0; k < 4; ++k) {
      EXPECT_GE(tag.points[k], 0);
      EXPECT_LT((tag.corners[k] - t.tags[static_cast<size_t>(tag.tag_id)][k]).norm(), 1e-12);
    }
  }
  EXPECT_EQ(t.model.CountVisiblePoints(kImage), 5 + 12);
}

TEST(TagImageRegistrationTest, TwoKnownTagsRegisterAnImageWithoutOtherPoints) {
  TagScene t = MakeTagScene(0);
  HideTag(&t, 2);
  const MapperOptions options = Options();
  // Without its tags the image would not even be a candidate (8 corners < 30 points).
  const std::vector<NextImageCandidate> candidates = NextImageCandidates(&t.model, t.scene.images, options);
  ASSERT_EQ(candidates.size(), 1u);
  EXPECT_EQ(candidates[0].image, kImage);
  EXPECT_TRUE(NextImageCandidates(&t.model, {}, options).empty());
  bool focal_changed = true;
  ASSERT_TRUE(RegisterImage(&t.model, t.scene.images, kImage, options, &focal_changed)) << t.model.failure[kImage];
  EXPECT_FALSE(focal_changed);
  ExpectTruePose(t);
  EXPECT_TRUE(t.model.failure[kImage].empty());
  int observed = 0;
  for (int id : t.model.rec.images[kImage].point3d_ids) observed += id >= 0 ? 1 : 0;
  EXPECT_EQ(observed, 8);  // the corners' points
}

TEST(TagImageRegistrationTest, OneTagNeedsSomeOtherPoints) {
  const MapperOptions options = Options();
  TagScene alone = MakeTagScene(0);
  HideTag(&alone, 1);
  HideTag(&alone, 2);
  bool focal_changed = false;
  EXPECT_TRUE(NextImageCandidates(&alone.model, alone.scene.images, options).empty());
  EXPECT_FALSE(RegisterImage(&alone.model, alone.scene.images, kImage, options, &focal_changed));
  EXPECT_NE(alone.model.failure[kImage].find("by tags: sees 1 tag(s) the model holds and 0 other points"),
            std::string::npos)
      << alone.model.failure[kImage];
  EXPECT_FALSE(alone.model.rec.images[kImage].registered);

  TagScene with_points = MakeTagScene(options.registration_min_tag_point_inliers + 2);
  HideTag(&with_points, 1);
  HideTag(&with_points, 2);
  ASSERT_TRUE(RegisterImage(&with_points.model, with_points.scene.images, kImage, options, &focal_changed))
      << with_points.model.failure[kImage];
  ExpectTruePose(with_points);
}

// Moves tag 1's corner points in the model by `offset`.
void MoveTag1(TagScene* t, const Eigen::Vector3d& offset) {
  for (const KnownTag& tag : KnownTags(t->model, t->scene.images, kImage, Options())) {
    if (tag.tag_id != 1) continue;
    for (int point : tag.points) t->model.rec.points[static_cast<size_t>(point)].position += offset;
  }
}

void ExpectRefused(TagScene* t, const std::string& why) {
  bool focal_changed = false;
  EXPECT_FALSE(RegisterImage(&t->model, t->scene.images, kImage, Options(), &focal_changed));
  EXPECT_FALSE(t->model.rec.images[kImage].registered);
  EXPECT_NE(t->model.failure[kImage].find("no pose fits them all"), std::string::npos) << t->model.failure[kImage];
  EXPECT_NE(t->model.failure[kImage].find(why), std::string::npos) << t->model.failure[kImage];
  for (int id : t->model.rec.images[kImage].point3d_ids) EXPECT_EQ(id, -1);
}

// Two small tags facing the camera, one of them 0.4 units (40 % of its edge) off in the model,
// admit a wrong pose (about 2 units off) that fits all eight corners within 2 px, 1.2 px rms:
// the image's matches to the registered images refuse it, being off their epipolar lines.
TEST(TagImageRegistrationTest, AWronglyPlacedTagIsRefusedByTheTwoViewMatches) {
  TagScene t = MakeTagScene(0, /*two_view=*/true);
  HideTag(&t, 2);
  bool focal_changed = false;
  {
    TagScene right = t;  // the same scene with the tag in place registers
    ASSERT_TRUE(RegisterImage(&right.model, right.scene.images, kImage, Options(), &focal_changed))
        << right.model.failure[kImage];
    ExpectTruePose(right);
  }
  MoveTag1(&t, Eigen::Vector3d(0.3, 0.0, 0.27));
  ExpectRefused(&t, "two-view matches on their epipolar lines");
}

// Without other evidence, a tag misplaced by more than its edge cannot fit with the other.
TEST(TagImageRegistrationTest, AGrosslyWrongTagIsRefusedByTheCorners) {
  TagScene t = MakeTagScene(0);
  HideTag(&t, 2);
  MoveTag1(&t, Eigen::Vector3d(0.9, 0.0, 0.8));
  ExpectRefused(&t, "corners rms");
}

TEST(TagImageRegistrationTest, ATagWithoutPointsIsPlacedByItsPoseInOneRegisteredView) {
  TagScene t = MakeTagScene(0);
  HideTag(&t, 2);
  // Tag 1's corner tracks lose their points: the model holds the tag only through the views that
  // see it (the largest one gives its pose, scaled by tag 0's edge in the model).
  for (const KnownTag& tag : KnownTags(t.model, t.scene.images, kImage, Options())) {
    if (tag.tag_id != 1) continue;
    for (int point : tag.points) t.model.DeletePoint(point);
  }
  const std::vector<KnownTag> known = KnownTags(t.model, t.scene.images, kImage, Options());
  ASSERT_EQ(known.size(), 2u);
  EXPECT_EQ(known[1].tag_id, 1);
  constexpr double kPlacedCornerError = 0.05;  // scene units
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(known[1].points[k], -1);
    EXPECT_LT((known[1].corners[k] - t.tags[1][k]).norm(), kPlacedCornerError);
  }
  bool focal_changed = false;
  ASSERT_TRUE(RegisterImage(&t.model, t.scene.images, kImage, Options(), &focal_changed)) << t.model.failure[kImage];
  // Half of the pose's 8 corners are placed only within kPlacedCornerError, seen from about 10
  // units (the ring's radius): the pose can turn by up to twice that error's angle, about 0.57
  // degrees, and its centre move by that angle times the distance, about 0.1 units. (The exact
  // errors differ between x86-64 and aarch64, whose floating-point contraction differs.)
  const double angle = std::atan(kPlacedCornerError / 10.0);
  ExpectTruePose(t, 2.0 * angle * 180.0 / M_PI, 2.0 * angle * 10.0);
}

TEST(TagImageRegistrationTest, ThreeCornersGiveTheFourth) {
  TagScene t = MakeTagScene(0);
  HideTag(&t, 2);
  const std::vector<KnownTag> before = KnownTags(t.model, t.scene.images, kImage, Options());
  t.model.DeletePoint(before[0].points[2]);
  const std::vector<KnownTag> known = KnownTags(t.model, t.scene.images, kImage, Options());
  ASSERT_EQ(known.size(), 2u);
  EXPECT_EQ(known[0].points[2], -1);
  EXPECT_LT((known[0].corners[2] - t.tags[0][2]).norm(), 1e-9);
}

TEST(TagImageRegistrationTest, TagsWhoseCornersAreNoKeypointsAreIgnored) {
  TagScene t = MakeTagScene(0);
  const int size = static_cast<int>(t.scene.images[kImage].keypoints.size());
  for (const int first : {-3, size - 3, size, 2147483646}) t.scene.images[kImage].tags.push_back({7, first});
  EXPECT_EQ(KnownTags(t.model, t.scene.images, kImage, Options()).size(), 3u);
  EXPECT_TRUE(KnownTags(t.model, t.scene.images, -1, Options()).empty());
  EXPECT_TRUE(KnownTags(t.model, t.scene.images, static_cast<int>(t.scene.images.size()), Options()).empty());
  bool focal_changed = false;
  ASSERT_TRUE(RegisterImage(&t.model, t.scene.images, kImage, Options(), &focal_changed)) << t.model.failure[kImage];
  ExpectTruePose(t);
}

}  // namespace
}  // namespace reconar
