// Merging models (core/sfm/model_merge.h) on the synthetic ring split in two halves, the second
// moved by a known similarity: the alignment found, the combined cameras at their true poses, and
// refusals when the shared points disagree or there are none.
#include "core/sfm/model_merge.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/base/prng.h"
#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

using testing::MakeScene;
using testing::Scene;
using testing::SceneOptions;

struct SplitRing {
  Scene scene;
  Reconstruction to;    // images 0-4 at the truth
  Reconstruction from;  // images 5-9, moved by moved_from_truth
  Sim3 moved_from_truth;
};

SplitRing MakeSplitRing() {
  SplitRing ring;
  SceneOptions options;
  options.num_cameras = 10;
  options.seed = 7;
  ring.scene = MakeScene(options);
  MapperModel to = testing::TrueModel(ring.scene), from = testing::TrueModel(ring.scene);
  for (int i = 0; i < 10; ++i) testing::Unregister(i < 5 ? &from : &to, i);
  ring.moved_from_truth.scale = 0.37;
  ring.moved_from_truth.rotation = Eigen::AngleAxisd(0.8, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).matrix();
  ring.moved_from_truth.translation = Eigen::Vector3d(2.0, -1.0, 5.0);
  for (SfmPoint& point : from.rec.points) point.position = ring.moved_from_truth.Apply(point.position);
  for (SfmImage& image : from.rec.images) {
    if (!image.registered) continue;
    const Eigen::Vector3d centre = ring.moved_from_truth.Apply(image.Center());
    image.cam_from_world.rotation = image.cam_from_world.rotation * ring.moved_from_truth.rotation.transpose();
    image.cam_from_world.translation = -(image.cam_from_world.rotation * centre);
  }
  ring.to = std::move(to.rec);
  ring.from = std::move(from.rec);
  return ring;
}

TEST(ModelMergeTest, FindsTheSimilarityFromTheSharedPoints) {
  const SplitRing ring = MakeSplitRing();
  const Result<ModelAlignment> alignment = AlignModels(ring.to, ring.from, ring.scene.pairs, ModelMergeOptions());
  ASSERT_TRUE(alignment.ok()) << alignment.status().ToString();
  EXPECT_GE(alignment->num_shared_points, 100);
  // A wrong match between an image of each half that joins two true points is a shared point the
  // similarity cannot explain (the track builder leaves the match out, both points stay); every
  // other shared point is an inlier.
  int wrong_across = 0;
  for (const MapperPair& pair : ring.scene.pairs) {
    if ((pair.matches.image_a < 5) == (pair.matches.image_b < 5)) continue;
    for (const FeatureMatch& m : pair.matches.matches) {
      const int a = ring.scene.point_of_keypoint[static_cast<size_t>(pair.matches.image_a)][static_cast<size_t>(m.index_a)];
      const int b = ring.scene.point_of_keypoint[static_cast<size_t>(pair.matches.image_b)][static_cast<size_t>(m.index_b)];
      wrong_across += a >= 0 && b >= 0 && a != b ? 1 : 0;
    }
  }
  EXPECT_LE(alignment->num_shared_points - alignment->num_inliers, wrong_across);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3, -2, 1), Eigen::Vector3d(-4, 5, 2)}) {
    EXPECT_LT((alignment->to_from_from.Apply(ring.moved_from_truth.Apply(p)) - p).norm(), 1e-9);
  }
}

TEST(ModelMergeTest, CombinedCamerasAreAtTheirTruePoses) {
  const SplitRing ring = MakeSplitRing();
  const Result<ModelAlignment> alignment = AlignModels(ring.to, ring.from, ring.scene.pairs, ModelMergeOptions());
  ASSERT_TRUE(alignment.ok()) << alignment.status().ToString();
  const Reconstruction combined = CombineRegisteredImages(ring.to, ring.from, alignment->to_from_from);
  ASSERT_EQ(combined.NumRegisteredImages(), 10);
  EXPECT_TRUE(combined.points.empty());
  for (size_t i = 0; i < combined.images.size(); ++i) {
    const Rigid3& pose = combined.images[i].cam_from_world;
    EXPECT_LT((pose.rotation - ring.scene.poses[i].rotation).norm(), 1e-9) << i;
    EXPECT_LT((pose.translation - ring.scene.poses[i].translation).norm(), 1e-8) << i;
    for (int id : combined.images[i].point3d_ids) EXPECT_EQ(id, -1);
  }
}

// A third of the second model's points moved far off: RANSAC finds the similarity of the rest.
TEST(ModelMergeTest, SharedPointsThatDisagreeAreOutliers) {
  SplitRing ring = MakeSplitRing();
  SplitMix64 rng(11);
  int moved = 0;
  for (size_t p = 0; p < ring.from.points.size(); ++p) {
    if (p % 3 != 0) continue;
    ring.from.points[p].position += Eigen::Vector3d(rng.Uniform(-2, 2), rng.Uniform(-2, 2), rng.Uniform(-2, 2));
    ++moved;
  }
  ASSERT_GT(moved, 0);
  const Result<ModelAlignment> alignment = AlignModels(ring.to, ring.from, ring.scene.pairs, ModelMergeOptions());
  ASSERT_TRUE(alignment.ok()) << alignment.status().ToString();
  EXPECT_LT(alignment->num_inliers, alignment->num_shared_points);
  EXPECT_GE(alignment->num_inliers, alignment->num_shared_points / 2);
  const Eigen::Vector3d p(1, 2, 3);
  EXPECT_LT((alignment->to_from_from.Apply(ring.moved_from_truth.Apply(p)) - p).norm(), 1e-6);
}

// The second model's points shuffled: no similarity explains them, and the models stay apart.
TEST(ModelMergeTest, ModelsWhoseSharedPointsDisagreeAreNotMerged) {
  SplitRing ring = MakeSplitRing();
  SplitMix64 rng(5);
  for (size_t p = ring.from.points.size(); p > 1; --p) {
    std::swap(ring.from.points[p - 1].position, ring.from.points[rng.UniformInt(static_cast<uint32_t>(p))].position);
  }
  const Result<ModelAlignment> alignment = AlignModels(ring.to, ring.from, ring.scene.pairs, ModelMergeOptions());
  ASSERT_FALSE(alignment.ok());
  EXPECT_EQ(alignment.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(alignment.status().message().find("no similarity"), std::string::npos) << alignment.status().message();
}

TEST(ModelMergeTest, ModelsWithoutSharedPointsAreNotMerged) {
  const SplitRing ring = MakeSplitRing();
  const Result<ModelAlignment> alignment = AlignModels(ring.to, ring.from, {}, ModelMergeOptions());
  ASSERT_FALSE(alignment.ok());
  EXPECT_NE(alignment.status().message().find("share 0 points"), std::string::npos) << alignment.status().message();
}

// Without the shared points' alignment: a verified pair between the halves gives the rotation
// and the baseline's direction, and the points each half sees in the pair its length in each
// half's units; the similarity comes out close to the truth (the keypoints carry 0.4 px noise).
TEST(ModelMergeTest, APairBetweenTheModelsGivesTheSimilarity) {
  const SplitRing ring = MakeSplitRing();
  const Result<ModelAlignment> alignment =
      AlignModelsByTwoViewGeometry(ring.to, ring.from, ring.scene.pairs, testing::SingleThreaded(), 5);
  ASSERT_TRUE(alignment.ok()) << alignment.status().ToString();
  EXPECT_LT(alignment->pair_to_image, 5);
  EXPECT_GE(alignment->pair_from_image, 5);
  EXPECT_NEAR(alignment->to_from_from.scale * ring.moved_from_truth.scale, 1.0, 0.01);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3, -2, 1), Eigen::Vector3d(-4, 5, 2)}) {
    EXPECT_LT((alignment->to_from_from.Apply(ring.moved_from_truth.Apply(p)) - p).norm(), 0.05);  // ring radius 10
  }
}

// A half whose points no pair between them sees cannot give the ratio of the units: refused.
TEST(ModelMergeTest, APairWithoutPointsOnOneSideDoesNotJoin) {
  SplitRing ring = MakeSplitRing();
  for (SfmImage& image : ring.from.images) std::fill(image.point3d_ids.begin(), image.point3d_ids.end(), -1);
  const Result<ModelAlignment> alignment =
      AlignModelsByTwoViewGeometry(ring.to, ring.from, ring.scene.pairs, testing::SingleThreaded(), 5);
  ASSERT_FALSE(alignment.ok());
  EXPECT_NE(alignment.status().message().find("fixes the baseline"), std::string::npos) << alignment.status().message();
}

}  // namespace
}  // namespace reconar
