#pragma once
// TagLayout and its text file (`tags.layout`): where each tag of a multi-tag target (a board, a
// room, the registered tags of a project) sits, per id its edge length and layout_from_tag
// (Rigid3). The one home of the format: tag registration writes it (FormatTagLayout), the AR
// tracker and calibration read it (ReadTagLayout).
//
// Text format (one tag per line; '#' starts a comment; blank lines ignored; metres and degrees):
//   <id> <size> <x> <y> <z> <qw> <qx> <qy> <qz>   layout_from_tag: translation (x, y, z) and the
//                                                 rotation as a unit quaternion (normalised on read)
//   <id> <size> <cx> <cy> [<angle_deg>]           planar shorthand: tag in the layout's z = 0 plane,
//                                                 centre (cx, cy), rotated by angle_deg about z
// Tag frames follow tracker/tag_pose.h (origin at the tag centre, x right, y up, z toward the
// viewer), so a planar layout's z axis also points toward the viewer. A project's layout frame is
// its world frame (world_from_tag).
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/math/rigid3.h"

namespace reconar {

struct LayoutTag {
  int id = 0;
  double size = 0.0;  // edge of the black square, metres
  Rigid3 layout_from_tag;
};

class TagLayout {
 public:
  // InvalidArgument for a negative id, a non-positive or non-finite size, a non-finite pose or an
  // id already present.
  Status Add(const LayoutTag& tag);
  // nullptr when the id is not in the layout. No allocation (binary search over ids).
  const LayoutTag* Find(int id) const;
  const std::vector<LayoutTag>& tags() const { return tags_; }  // sorted by id
  bool empty() const { return tags_.empty(); }
  // Every tag lies in the layout's z = 0 plane with its z axis along the layout's (1e-9 tolerance).
  bool IsPlanar() const;

 private:
  std::vector<LayoutTag> tags_;
};

// Parses the text format; errors name `name_for_errors`, the line number and the reason
// (InvalidArgument / CorruptData).
Result<TagLayout> ParseTagLayout(const std::string& text, const std::string& name_for_errors);
// NotFound / IoError for the file, then ParseTagLayout.
Result<TagLayout> ReadTagLayout(const std::string& path);
// The text format, in the full 9-field form, one line per tag in the given order, numbers with
// %.17g (read back exactly), after a header comment.
std::string FormatTagLayout(const std::vector<LayoutTag>& tags);

}  // namespace reconar
