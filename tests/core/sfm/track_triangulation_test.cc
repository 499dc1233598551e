#include "core/sfm/track_triangulation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

// The model at the truth with its points removed (every track untriangulated).
MapperModel WithoutPoints(MapperModel model) {
  model.rec.points.clear();
  model.track_of_point.clear();
  std::fill(model.point_of_track.begin(), model.point_of_track.end(), -1);
  for (SfmImage& image : model.rec.images) std::fill(image.point3d_ids.begin(), image.point3d_ids.end(), -1);
  return model;
}

TEST(TrackTriangulationTest, RetriangulateAllRecoversTheTruePoints) {
  const testing::Scene scene = testing::MakeExactScene(6, 400);
  const MapperModel truth = testing::TrueModel(scene);
  MapperModel model = WithoutPoints(truth);
  RetriangulateAll(&model, MapperOptions());
  ASSERT_GE(model.rec.NumPoints(), truth.rec.NumPoints() * 95 / 100);
  for (size_t p = 0; p < model.rec.points.size(); ++p) {
    const SfmPoint& point = model.rec.points[p];
    const int true_point = testing::TruePointOf(scene, point);
    ASSERT_GE(true_point, 0);
    EXPECT_LT((point.position - scene.points[static_cast<size_t>(true_point)]).norm(), 1e-6) << "point " << p;
    // All of the track's views are observations (the keypoints are exact).
    const int t = model.track_of_point[p];
    EXPECT_EQ(point.track.size(), model.tracks.tracks[static_cast<size_t>(t)].size());
    for (const TrackElement& e : point.track) {
      EXPECT_EQ(model.rec.images[static_cast<size_t>(e.image_id)].point3d_ids[static_cast<size_t>(e.keypoint_id)],
                static_cast<int>(p));
    }
  }
}

TEST(TrackTriangulationTest, TrackWithAPlantedOutlierKeepsTheOtherViews) {
  const testing::Scene scene = testing::MakeExactScene(6, 400);
  MapperModel model = WithoutPoints(testing::TrueModel(scene));
  int track = -1;
  for (size_t t = 0; t < model.tracks.tracks.size() && track < 0; ++t) {
    if (model.tracks.tracks[t].size() >= 4) track = static_cast<int>(t);
  }
  ASSERT_GE(track, 0);
  const TrackElement outlier = model.tracks.tracks[static_cast<size_t>(track)][1];
  model.rec.images[static_cast<size_t>(outlier.image_id)].keypoints[static_cast<size_t>(outlier.keypoint_id)] +=
      Eigen::Vector2d(25.0, -10.0);
  ASSERT_TRUE(TriangulateTrack(&model, track, MapperOptions()));
  ASSERT_EQ(model.rec.points.size(), 1u);
  const SfmPoint& point = model.rec.points[0];
  EXPECT_EQ(point.track.size(), model.tracks.tracks[static_cast<size_t>(track)].size() - 1);
  for (const TrackElement& e : point.track) EXPECT_FALSE(e.image_id == outlier.image_id);
  EXPECT_LT((point.position - scene.points[static_cast<size_t>(testing::TruePointOf(scene, point))]).norm(), 1e-6);
  EXPECT_EQ(model.point_of_track[static_cast<size_t>(track)], 0);
  EXPECT_EQ(
      model.rec.images[static_cast<size_t>(outlier.image_id)].point3d_ids[static_cast<size_t>(outlier.keypoint_id)],
      -1);
}

TEST(TrackTriangulationTest, TriangulateImageUsesOnlyRegisteredViews) {
  const testing::Scene scene = testing::MakeExactScene(6, 400);
  MapperModel model = WithoutPoints(testing::TrueModel(scene));
  for (size_t i = 2; i < model.rec.images.size(); ++i) model.rec.images[i].registered = false;
  TriangulateImage(&model, 1, MapperOptions());
  // Every track seen by both images 0 and 1 becomes a point observed exactly there.
  int expected = 0;
  for (const std::vector<TrackElement>& track : model.tracks.tracks) {
    bool in0 = false, in1 = false;
    for (const TrackElement& e : track) {
      in0 = in0 || e.image_id == 0;
      in1 = in1 || e.image_id == 1;
    }
    expected += (in0 && in1) ? 1 : 0;
  }
  ASSERT_GT(expected, 50);
  EXPECT_EQ(model.rec.NumPoints(), expected);
  for (const SfmPoint& point : model.rec.points) {
    ASSERT_EQ(point.track.size(), 2u);
    EXPECT_EQ(point.track[0].image_id, 0);
    EXPECT_EQ(point.track[1].image_id, 1);
    EXPECT_LT((point.position - scene.points[static_cast<size_t>(testing::TruePointOf(scene, point))]).norm(), 1e-6);
  }
}

TEST(TrackTriangulationTest, TooSmallAnAngleMakesNoPoint) {
  const testing::Scene scene = testing::MakeExactScene(6, 400);
  MapperModel model = WithoutPoints(testing::TrueModel(scene));
  MapperOptions options;
  options.min_triangulation_angle_deg = 160.0;  // no two cameras see a point from more than 150 degrees apart
  RetriangulateAll(&model, options);
  EXPECT_EQ(model.rec.NumPoints(), 0);
  for (int p : model.point_of_track) EXPECT_EQ(p, -1);
}

}  // namespace
}  // namespace reconar
