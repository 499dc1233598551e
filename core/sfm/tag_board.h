#pragma once
// The world frame from the tag board as a whole: the world tag's origin, the plane of the tags
// that share its wall and the "up" that the tags printed the same way share. One 12.7 cm tag's
// normal is known to about half a degree; the room's odd and even photos, reconstructed apart,
// put their world tags' frames 0.6 degrees apart, 0.2 with the plane of the four tags on the
// world tag's wall (2.9 m across) and the up of all twenty.
#include <array>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/math/rigid3.h"

namespace reconar {

struct BoardTag {
  int id = -1;
  std::array<Eigen::Vector3d, 4> corners;  // in the world tag's frame, kTagCornerUnits order
};

struct TagBoardOptions {
  // A tag joins the world tag's plane when its normal is within this angle of the world tag's
  // and its centre within one tag edge of the world tag's plane (the same wall, not a pillar
  // face in front of it); it joins the up when its y axis is within this angle of the world tag's.
  double max_angle_deg = 10.0;
};

struct TagBoardFrame {
  Rigid3 board_from_world_tag;   // the correction taking the world tag's frame to the board's
  std::vector<int> plane_tags;   // the tags whose corners fit the plane (the world tag first)
  std::vector<int> up_tags;      // the tags whose y axes set the up (the world tag first)
  double turn_deg = 0.0;         // the angle between the two frames
};

// `tags` in the world tag's frame (the world tag itself the square of edge `tag_size` centred on
// the origin in z = 0, but any fit of it will do): the frame whose z is the normal of the plane
// fitted to the corners of every tag on the world tag's wall, whose y is the mean y axis of the
// tags sharing the world tag's up, projected on that plane, and whose origin is the world tag's
// centre projected on it. With no other tag on the wall or up, the world tag's own frame.
// InvalidArgument when the world tag is not in `tags` or the options are bad.
Result<TagBoardFrame> FitTagBoardFrame(const std::vector<BoardTag>& tags, int world_tag, double tag_size,
                                       const TagBoardOptions& options = {});

}  // namespace reconar
