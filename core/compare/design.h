#pragma once
// A design (as planned) for `reconar compare`: its elements by name, read from glTF 2.0 (.glb or
// .gltf: one element per node with a mesh, node transforms applied), OBJ (one per group) or PLY
// (the whole file, one element named after it); and the control that places it: the design
// coordinates of some of the project's tags.
//
// Control file, one line per tag or picked point, `#` starts a comment:
//   ID X Y Z                          the tag's centre
//   ID X0 Y0 Z0 X1 Y1 Z1 X2 Y2 Z2 X3 Y3 Z3   its corners, in libapriltag's order (tag_observations.h)
//   point X Y Z WX WY WZ              a point picked in both: its design coordinates, then where it
//                                     is in the project's world frame (`reconar measure` prints it)
// design coordinates in design units.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

struct Design {
  std::vector<NamedMesh> elements;  // each with triangles
};

// kInvalidArgument for a file of another kind; the readers' errors (naming the file) otherwise;
// kCorruptData when no element has a triangle or a triangle's vertex is missing or not finite.
Result<Design> ReadDesign(const std::string& path);

struct ControlTag {
  int id = -1;                                 // -1: a picked point
  std::vector<Eigen::Vector3d> design_points;  // 1: the centre (or the picked point); 4: the corners
  Eigen::Vector3d world_point = Eigen::Vector3d::Zero();  // a picked point's, in the world frame
  int line = 0;
};

// kCorruptData naming the file and line for a malformed line or a tag id given twice; kNotFound for a
// missing file; an empty file (or comments only) is kCorruptData.
Result<std::vector<ControlTag>> ReadControlFile(const std::string& path);
Result<std::vector<ControlTag>> ParseControl(const std::string& text, const std::string& name_for_errors);

}  // namespace reconar
