#include "core/sfm/tag_board.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace reconar {
namespace {

// A tag's axes from its corners (kTagCornerUnits order): x along its edges 0->1 and 3->2, y along
// 0->3 and 1->2, z = x cross y.
Eigen::Matrix3d TagAxes(const std::array<Eigen::Vector3d, 4>& c) {
  const Eigen::Vector3d x = ((c[1] - c[0]) + (c[2] - c[3])).normalized();
  const Eigen::Vector3d along_y = (c[3] - c[0]) + (c[2] - c[1]);
  const Eigen::Vector3d z = x.cross(along_y).normalized();
  Eigen::Matrix3d axes;
  axes << x, z.cross(x), z;
  return axes;
}

Eigen::Vector3d Centre(const std::array<Eigen::Vector3d, 4>& c) { return (c[0] + c[1] + c[2] + c[3]) / 4.0; }

}  // namespace

Result<TagBoardFrame> FitTagBoardFrame(const std::vector<BoardTag>& tags, int world_tag, double tag_size,
                                       const TagBoardOptions& options) {
  if (!(tag_size > 0.0) || !std::isfinite(tag_size)) return InvalidArgument("tag board: the tag size must be positive");
  if (!(options.max_angle_deg > 0.0 && options.max_angle_deg < 90.0))
    return InvalidArgument("tag board: max_angle_deg must be in (0, 90)");
  const auto world = std::find_if(tags.begin(), tags.end(), [&](const BoardTag& t) { return t.id == world_tag; });
  if (world == tags.end()) return InvalidArgument("tag board: the world tag " + std::to_string(world_tag) + " is not given");
  const double min_cos = std::cos(options.max_angle_deg * M_PI / 180.0);
  const Eigen::Matrix3d world_axes = TagAxes(world->corners);
  const Eigen::Vector3d world_centre = Centre(world->corners);

  TagBoardFrame frame;
  std::vector<const BoardTag*> plane = {&*world}, up = {&*world};
  for (const BoardTag& tag : tags) {
    if (tag.id == world_tag) continue;
    const Eigen::Matrix3d axes = TagAxes(tag.corners);
    if (!axes.allFinite()) continue;
    const double offset = std::abs((Centre(tag.corners) - world_centre).dot(world_axes.col(2)));
    if (axes.col(2).dot(world_axes.col(2)) >= min_cos && offset <= tag_size) plane.push_back(&tag);
    if (axes.col(1).dot(world_axes.col(1)) >= min_cos) up.push_back(&tag);
  }

  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const BoardTag* tag : plane) mean += Centre(tag->corners) / static_cast<double>(plane.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const BoardTag* tag : plane)
    for (const Eigen::Vector3d& c : tag->corners) scatter += (c - mean) * (c - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  Eigen::Vector3d normal = eigen.eigenvectors().col(0);  // the smallest eigenvalue's
  if (normal.dot(world_axes.col(2)) < 0.0) normal = -normal;
  Eigen::Vector3d up_sum = Eigen::Vector3d::Zero();
  for (const BoardTag* tag : up) up_sum += TagAxes(tag->corners).col(1);
  const Eigen::Vector3d y = (up_sum - up_sum.dot(normal) * normal).normalized();
  if (!normal.allFinite() || !y.allFinite()) return InvalidArgument("tag board: the world tag's corners are degenerate");

  Eigen::Matrix3d world_tag_from_board;
  world_tag_from_board << y.cross(normal), y, normal;
  const Eigen::Vector3d origin = world_centre - (world_centre - mean).dot(normal) * normal;
  const Rigid3 world_tag_from_board_pose{world_tag_from_board, origin};
  frame.board_from_world_tag = world_tag_from_board_pose.Inverse();
  for (const BoardTag* tag : plane) frame.plane_tags.push_back(tag->id);
  for (const BoardTag* tag : up) frame.up_tags.push_back(tag->id);
  const double cos_turn =
      std::clamp(((world_axes.transpose() * world_tag_from_board).trace() - 1.0) / 2.0, -1.0, 1.0);
  frame.turn_deg = std::acos(cos_turn) * 180.0 / M_PI;
  return frame;
}

}  // namespace reconar
