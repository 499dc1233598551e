#include "core/sfm/point_filter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "tests/core/sfm/synthetic_scene.h"

namespace reconar {
namespace {

MapperModel ExactTrueModel() { return testing::TrueModel(testing::MakeExactScene(6, 400)); }

int FirstPointWithTrackLength(const MapperModel& model, size_t min_length, size_t max_length, int after = -1) {
  for (size_t p = static_cast<size_t>(after + 1); p < model.rec.points.size(); ++p) {
    const size_t n = model.rec.points[p].track.size();
    if (n >= min_length && n <= max_length) return static_cast<int>(p);
  }
  return -1;
}

void Shift(MapperModel* model, const TrackElement& e, const Eigen::Vector2d& by) {
  model->rec.images[static_cast<size_t>(e.image_id)].keypoints[static_cast<size_t>(e.keypoint_id)] += by;
}

TEST(PointFilterTest, ExactModelIsKept) {
  MapperModel model = ExactTrueModel();
  const int before = model.rec.NumPoints();
  ASSERT_GT(before, 100);
  FilterPoints(&model, model.AllPoints(), MapperOptions());
  EXPECT_EQ(model.rec.NumPoints(), before);
}

TEST(PointFilterTest, PlantedErrorsRemoveObservationsOrPoints) {
  MapperModel model = ExactTrueModel();
  const MapperModel before = model;
  // a: a long track loses one observation (10 px off); b: a two-view point with one view 10 px
  // off is deleted; c: 3 px off is within the 4 px bound and stays.
  const int a = FirstPointWithTrackLength(model, 3, 100);
  const int b = FirstPointWithTrackLength(model, 2, 2);
  int c = FirstPointWithTrackLength(model, 2, 100);
  while (c == a || c == b) c = FirstPointWithTrackLength(model, 2, 100, c);
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  ASSERT_GE(c, 0);
  const TrackElement planted_a = model.rec.points[static_cast<size_t>(a)].track[1];
  const TrackElement planted_b = model.rec.points[static_cast<size_t>(b)].track[0];
  Shift(&model, planted_a, Eigen::Vector2d(8.0, 6.0));
  Shift(&model, planted_b, Eigen::Vector2d(0.0, -10.0));
  Shift(&model, model.rec.points[static_cast<size_t>(c)].track[0], Eigen::Vector2d(3.0, 0.0));
  FilterPoints(&model, model.AllPoints(), MapperOptions());

  const SfmPoint& pa = model.rec.points[static_cast<size_t>(a)];
  EXPECT_FALSE(pa.deleted);
  EXPECT_EQ(pa.track.size(), before.rec.points[static_cast<size_t>(a)].track.size() - 1);
  for (const TrackElement& e : pa.track) EXPECT_FALSE(e.image_id == planted_a.image_id);
  EXPECT_EQ(
      model.rec.images[static_cast<size_t>(planted_a.image_id)].point3d_ids[static_cast<size_t>(planted_a.keypoint_id)],
      -1);

  const SfmPoint& pb = model.rec.points[static_cast<size_t>(b)];
  EXPECT_TRUE(pb.deleted);
  EXPECT_TRUE(pb.track.empty());
  for (const TrackElement& e : before.rec.points[static_cast<size_t>(b)].track) {
    EXPECT_EQ(model.rec.images[static_cast<size_t>(e.image_id)].point3d_ids[static_cast<size_t>(e.keypoint_id)], -1);
  }
  EXPECT_EQ(model.point_of_track[static_cast<size_t>(model.track_of_point[static_cast<size_t>(b)])], -1);

  // Everything else is as it was.
  EXPECT_EQ(model.rec.NumPoints(), before.rec.NumPoints() - 1);
  for (size_t p = 0; p < model.rec.points.size(); ++p) {
    if (static_cast<int>(p) == a || static_cast<int>(p) == b) continue;
    EXPECT_EQ(model.rec.points[p].track.size(), before.rec.points[p].track.size()) << "point " << p;
  }
}

TEST(PointFilterTest, OnlyTheGivenPointsAreFiltered) {
  MapperModel model = ExactTrueModel();
  const int b = FirstPointWithTrackLength(model, 2, 2);
  ASSERT_GE(b, 0);
  Shift(&model, model.rec.points[static_cast<size_t>(b)].track[0], Eigen::Vector2d(20.0, 0.0));
  std::vector<int> others;
  for (int p : model.AllPoints()) {
    if (p != b) others.push_back(p);
  }
  FilterPoints(&model, others, MapperOptions());
  EXPECT_FALSE(model.rec.points[static_cast<size_t>(b)].deleted);
  FilterPoints(&model, {b}, MapperOptions());
  EXPECT_TRUE(model.rec.points[static_cast<size_t>(b)].deleted);
}

TEST(PointFilterTest, TooLittleParallaxDeletes) {
  MapperModel model = ExactTrueModel();
  MapperOptions options;
  options.min_triangulation_angle_deg = 160.0;  // no two cameras see a point from more than 150 degrees apart
  FilterPoints(&model, model.AllPoints(), options);
  EXPECT_EQ(model.rec.NumPoints(), 0);
  for (const SfmImage& image : model.rec.images) {
    for (int id : image.point3d_ids) EXPECT_EQ(id, -1);
  }
}

}  // namespace
}  // namespace reconar

namespace reconar {
namespace {

// A tag corner is identified by its decoded tag: its observation stays while it is within the
// tag's edge in that image (MapperModel::tag_corner_bounds), far beyond the 4 px of a match.
TEST(PointFilterTest, ATagCornerStaysWithinItsTagsSize) {
  MapperModel model = ExactTrueModel();
  const int near = FirstPointWithTrackLength(model, 3, 100);
  const int far = FirstPointWithTrackLength(model, 3, 100, near);
  const int plain = FirstPointWithTrackLength(model, 3, 100, far);
  ASSERT_GE(plain, 0);
  const TrackElement near_view = model.rec.points[static_cast<size_t>(near)].track[1];
  const TrackElement far_view = model.rec.points[static_cast<size_t>(far)].track[1];
  const TrackElement plain_view = model.rec.points[static_cast<size_t>(plain)].track[1];
  model.tag_corner_bounds.resize(model.rec.images.size());
  for (const TrackElement& e : {near_view, far_view}) {
    model.tag_corner_bounds[static_cast<size_t>(e.image_id)].push_back({e.keypoint_id, 25.0});  // a 25 px tag
    std::sort(model.tag_corner_bounds[static_cast<size_t>(e.image_id)].begin(),
              model.tag_corner_bounds[static_cast<size_t>(e.image_id)].end());
  }
  Shift(&model, near_view, Eigen::Vector2d(12.0, -9.0));  // 15 px: kept
  Shift(&model, far_view, Eigen::Vector2d(24.0, 18.0));   // 30 px: more than the tag, dropped
  Shift(&model, plain_view, Eigen::Vector2d(12.0, -9.0));  // 15 px, not a tag corner: dropped
  const size_t track = model.rec.points[static_cast<size_t>(near)].track.size();
  FilterPoints(&model, model.AllPoints(), MapperOptions());
  EXPECT_EQ(model.rec.points[static_cast<size_t>(near)].track.size(), track);
  for (const TrackElement& e : {far_view, plain_view}) {
    EXPECT_EQ(model.rec.images[static_cast<size_t>(e.image_id)].point3d_ids[static_cast<size_t>(e.keypoint_id)], -1);
  }
}

}  // namespace
}  // namespace reconar
