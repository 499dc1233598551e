// The world frame from the tag board (core/sfm/tag_board.h): the plane of the tags on the world
// tag's wall, the up the upright tags share, the world tag's centre as the origin.
#include "core/sfm/tag_board.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/sfm/tag_squares.h"

namespace reconar {
namespace {

constexpr double kEdge = 0.127;
constexpr double kDegree = M_PI / 180.0;

// A tag at `board_from_tag` in the board frame, its corners in the world tag's frame.
BoardTag Place(int id, const Rigid3& world_tag_from_board, const Rigid3& board_from_tag) {
  BoardTag tag{id, {}};
  const std::array<Eigen::Vector3d, 4> square = TagSquareCorners(kEdge);
  for (size_t k = 0; k < 4; ++k) tag.corners[k] = world_tag_from_board * (board_from_tag * square[k]);
  return tag;
}

Rigid3 At(double x, double y, double z, const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity()) {
  return Rigid3{rotation, Eigen::Vector3d(x, y, z)};
}

bool Contains(const std::vector<int>& ids, int id) { return std::find(ids.begin(), ids.end(), id) != ids.end(); }

// The world tag, stuck on the wall 1.5 degrees off it (the room's tag 0 is, by both halves of its
// photos): the frame is close to the wall's (the world tag's own corners are among the five
// tags' that fit it), its origin the world tag's centre.
TEST(TagBoardTest, TheWallsTagsSetThePlaneAndTheirUpTheAxes) {
  const Eigen::Matrix3d tilt =
      (Eigen::AngleAxisd(1.5 * kDegree, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.7 * kDegree, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  const Rigid3 board_from_world_tag = At(0, 0, 0, tilt);
  const Rigid3 world_tag_from_board = board_from_world_tag.Inverse();
  const Eigen::Matrix3d facing_left = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d turned = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const std::vector<BoardTag> tags = {
      Place(0, world_tag_from_board, board_from_world_tag),
      Place(1, world_tag_from_board, At(0.7, -0.6, 0.0)),
      Place(2, world_tag_from_board, At(1.8, -0.3, 0.0)),
      Place(3, world_tag_from_board, At(-1.0, 0.0, 0.0)),
      Place(4, world_tag_from_board, At(1.0, 0.4, 0.0, turned)),       // on the wall, turned: not up
      Place(5, world_tag_from_board, At(0.5, 0.0, 0.6)),               // a pillar in front: not the plane
      Place(6, world_tag_from_board, At(2.3, -0.5, 1.5, facing_left)),  // the next wall: the up only
  };
  const Result<TagBoardFrame> frame = FitTagBoardFrame(tags, 0, kEdge);
  ASSERT_TRUE(frame.ok()) << frame.status().message();
  EXPECT_EQ(frame->plane_tags, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_TRUE(Contains(frame->up_tags, 5) && Contains(frame->up_tags, 6));
  EXPECT_FALSE(Contains(frame->up_tags, 4));
  const Eigen::Matrix3d error = frame->board_from_world_tag.rotation * board_from_world_tag.rotation.transpose();
  const double tilt_deg = Eigen::AngleAxisd(tilt).angle() / kDegree;
  EXPECT_LT(Eigen::AngleAxisd(error).angle() / kDegree, 0.2 * tilt_deg);
  EXPECT_NEAR(frame->turn_deg, tilt_deg, 0.2 * tilt_deg);
  EXPECT_LT(frame->board_from_world_tag.translation.norm(), 1e-4);
  // In the fitted frame the wall's tags lie within a millimetre of z = 0.
  for (const BoardTag& tag : tags) {
    if (tag.id < 1 || tag.id > 3) continue;
    for (const Eigen::Vector3d& corner : tag.corners) EXPECT_NEAR((frame->board_from_world_tag * corner).z(), 0.0, 1e-3);
  }
}

// Noisy corners: the plane of several tags is steadier than the world tag's own normal.
TEST(TagBoardTest, ManyTagsGiveASteadierFrameThanOne) {
  std::srand(3);
  const auto noise = [] { return 0.001 * (2.0 * std::rand() / RAND_MAX - 1.0); };  // +-1 mm per corner
  double own_sum = 0.0, board_sum = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<BoardTag> tags;
    for (int id = 0; id < 6; ++id) {
      BoardTag tag = Place(id, Rigid3::Identity(), At(0.5 * id - 1.2, 0.3 * (id % 3), 0.0));
      for (Eigen::Vector3d& corner : tag.corners) corner += Eigen::Vector3d(noise(), noise(), noise());
      tags.push_back(tag);
    }
    // The world tag as the frame would take it: its own fit, here its corners as they came.
    const Result<TagBoardFrame> alone = FitTagBoardFrame({tags[0]}, 0, kEdge);
    const Result<TagBoardFrame> board = FitTagBoardFrame(tags, 0, kEdge);
    ASSERT_TRUE(alone.ok() && board.ok());
    EXPECT_EQ(alone->plane_tags, std::vector<int>{0});
    own_sum += Eigen::AngleAxisd(alone->board_from_world_tag.rotation).angle();
    board_sum += Eigen::AngleAxisd(board->board_from_world_tag.rotation).angle();
  }
  EXPECT_LT(board_sum, 0.3 * own_sum) << "mean turn from the true frame: board " << board_sum / 50 / kDegree
                                      << " deg, the world tag alone " << own_sum / 50 / kDegree << " deg";
}

TEST(TagBoardTest, AWorldTagAloneKeepsItsFrameAndAMissingOneIsAnError) {
  const std::vector<BoardTag> tags = {Place(7, Rigid3::Identity(), At(0, 0, 0))};
  const Result<TagBoardFrame> frame = FitTagBoardFrame(tags, 7, kEdge);
  ASSERT_TRUE(frame.ok());
  EXPECT_LT(Eigen::AngleAxisd(frame->board_from_world_tag.rotation).angle(), 1e-12);
  EXPECT_NEAR(frame->turn_deg, 0.0, 1e-6);
  EXPECT_FALSE(FitTagBoardFrame(tags, 3, kEdge).ok());
  EXPECT_FALSE(FitTagBoardFrame(tags, 7, -1.0).ok());
}

}  // namespace
}  // namespace reconar
