// The tag squares (core/sfm/tag_squares.h): which model point holds each tag corner (the majority
// of its keypoints in registered images), and the squares of the common edge fitted to them.
#include "core/sfm/tag_squares.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <vector>

namespace reconar {
namespace {

// Two tags of edges 0.10 and 0.12 (model units), corner k of tag t the point 4 t + k, seen by three
// registered images and one that is not registered.
struct Scene {
  Reconstruction rec;
  std::vector<TagCornerKeypoint> corners;
  std::vector<Rigid3> world_from_tag;
};

Scene MakeScene() {
  Scene scene;
  scene.world_from_tag = {
      Rigid3{Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix(), Eigen::Vector3d(1, 0, 3)},
      Rigid3{Eigen::AngleAxisd(-0.7, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix(), Eigen::Vector3d(-1, 0.5, 4)}};
  const double edges[2] = {0.10, 0.12};
  for (int t = 0; t < 2; ++t) {
    const std::array<Eigen::Vector3d, 4> square = TagSquareCorners(edges[t]);
    for (int k = 0; k < 4; ++k) {
      SfmPoint point;
      point.position = scene.world_from_tag[static_cast<size_t>(t)] * square[static_cast<size_t>(k)];
      scene.rec.points.push_back(point);
    }
  }
  for (int i = 0; i < 4; ++i) {
    SfmImage image;
    image.registered = i < 3;
    image.keypoints.assign(8, Eigen::Vector2d::Zero());
    image.point3d_ids.resize(8);
    for (int p = 0; p < 8; ++p) image.point3d_ids[static_cast<size_t>(p)] = p;
    scene.rec.images.push_back(image);
    for (int t = 0; t < 2; ++t) {
      for (int k = 0; k < 4; ++k) scene.corners.push_back({i, 4 * t + k, 10 + t, k, Eigen::Vector2d::Zero()});
    }
  }
  return scene;
}

TEST(TagSquaresTest, EachCornerIsThePointMostOfItsKeypointsBelongTo) {
  Scene scene = MakeScene();
  // Image 2 and the unregistered image 3 put tag 10's corner 0 on point 5; images 0 and 1 on point 0.
  scene.rec.images[2].point3d_ids[0] = 5;
  scene.rec.images[3].point3d_ids[0] = 5;
  const std::vector<TagCornerPoints> tags = FindTagCornerPoints(scene.rec, scene.corners);
  ASSERT_EQ(tags.size(), 2u);
  EXPECT_EQ(tags[0].tag_id, 10);
  EXPECT_EQ(tags[0].points, (std::array<int, 4>{0, 1, 2, 3}));
  EXPECT_EQ(tags[1].points, (std::array<int, 4>{4, 5, 6, 7}));
  // A deleted point holds nothing.
  scene.rec.points[7].deleted = true;
  EXPECT_EQ(FindTagCornerPoints(scene.rec, scene.corners)[1].points[3], -1);
}

TEST(TagSquaresTest, SquaresOfTheCommonEdgeFitTheirCorners) {
  const Scene scene = MakeScene();
  const TagSquares both = FindTagSquares(scene.rec, scene.corners, {});
  EXPECT_NEAR(both.edge, 0.11, 1e-12);
  ASSERT_EQ(both.squares.size(), 2u);
  for (size_t t = 0; t < 2; ++t) {
    EXPECT_EQ(both.squares[t].tag_id, static_cast<int>(10 + t));
    // The fitted square is centred on the tag and turned as it is, whatever its size.
    EXPECT_LT((both.squares[t].world_from_tag.translation - scene.world_from_tag[t].translation).norm(), 1e-12);
    EXPECT_LT((both.squares[t].world_from_tag.rotation - scene.world_from_tag[t].rotation).norm(), 1e-9);
  }
  const TagSquares one = FindTagSquares(scene.rec, scene.corners, {11});
  ASSERT_EQ(one.squares.size(), 1u);
  EXPECT_EQ(one.squares[0].tag_id, 11);
  EXPECT_NEAR(one.edge, 0.12, 1e-12);
  // A tag two of whose corners are one point is no square.
  Scene merged = MakeScene();
  for (SfmImage& image : merged.rec.images) image.point3d_ids[1] = 0;
  const TagSquares rest = FindTagSquares(merged.rec, merged.corners, {});
  ASSERT_EQ(rest.squares.size(), 1u);
  EXPECT_EQ(rest.squares[0].tag_id, 11);
}

}  // namespace
}  // namespace reconar
