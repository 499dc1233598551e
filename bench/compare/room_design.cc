// room_design PROJECT OUT_DIR: a design of the room a tagged project shows, made from its tags:
// one wall per group of tags facing the same way within 0.2 m of one plane, each a box 5 cm thick
// behind the upright plane fitted to its tags' corners, as long as its tags reach plus half a metre each
// way and from the floor to the ceiling (the world frame's y is up: the tag board's); a floor and a
// ceiling slab, 5 cm thick, at the heights of the lowest and highest dense points (no tag is on
// them), over the tags' extent plus half a metre. Written as OUT_DIR/room_design.glb in millimetres, in a frame of its own (z up,
// the origin 10 m east and 20 m north of the world's), with OUT_DIR/room_control.txt giving every
// tag's centre in that frame, so that `reconar compare PROJECT OUT_DIR/room_design.glb --control
// OUT_DIR/room_control.txt` has to find the units and the frame itself.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/math/point_spread.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_io.h"
#include "core/sfm/tag_layout.h"
#include "core/sfm/tag_squares.h"

namespace reconar {
namespace {

// A box 5 cm thick whose face centre + [a_min, a_max] along + [v_min, v_max] vertical faces
// `normal` (into the room), the rest behind it; in the design's frame and units.
Mesh FacingBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& along, const Eigen::Vector3d& vertical,
               const Eigen::Vector3d& normal, double a_min, double a_max, double v_min, double v_max,
               const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& to_design) {
  Mesh box;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d world = centre + (k & 1 ? a_max : a_min) * along + (k & 2 ? v_max : v_min) * vertical -
                                  (k & 4 ? 0.05 : 0.0) * normal;
    box.positions.push_back(to_design(world).cast<float>());
  }
  // Counter-clockwise from outside in the box's own axes (along, vertical, -normal) when they are
  // right-handed: the face at the plane (k & 4 == 0) then faces the room.
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    box.triangles.push_back({q[0], q[1], q[2]});
    box.triangles.push_back({q[0], q[2], q[3]});
  }
  if (along.cross(vertical).dot(-normal) < 0.0) {
    for (auto& t : box.triangles) std::swap(t[1], t[2]);
  }
  return box;
}

int Run(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: room_design PROJECT OUT_DIR\n");
    return 2;
  }
  const std::string project = argv[1], out = argv[2];
  std::error_code made;
  std::filesystem::create_directories(out, made);
  Result<TagLayout> layout = ReadTagLayout(project + "/tags.layout");
  if (!layout.ok()) {
    std::fprintf(stderr, "%s\n", layout.status().ToString().c_str());
    return 1;
  }
  // Walls: tags facing the same way (within 20 degrees) within 0.2 m of the first one's plane.
  struct Wall {
    std::vector<const LayoutTag*> tags;
    Eigen::Vector3d normal;
  };
  std::vector<Wall> walls;
  for (const LayoutTag& tag : layout->tags()) {
    const Eigen::Vector3d normal = tag.layout_from_tag.rotation.col(2);
    bool placed = false;
    for (Wall& wall : walls) {
      const LayoutTag& first = *wall.tags.front();
      if (normal.dot(wall.normal) > std::cos(20.0 * M_PI / 180.0) &&
          std::abs((tag.layout_from_tag.translation - first.layout_from_tag.translation).dot(wall.normal)) < 0.2) {
        wall.tags.push_back(&tag);
        placed = true;
        break;
      }
    }
    if (!placed) walls.push_back({{&tag}, normal});
  }
  // The design frame: z up (the world's y), x the world's x, origin (10, 20, 0) m; millimetres.
  Eigen::Matrix3d design_from_world_rotation;
  design_from_world_rotation << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  const Eigen::Vector3d design_origin(10.0, 20.0, 0.0);
  const auto to_design_mm = [&](const Eigen::Vector3d& world) {
    return Eigen::Vector3d(1000.0 * (design_from_world_rotation * world + design_origin));
  };
  std::vector<NamedMesh> elements;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitY();  // the tag board's y
  // No tag is on the floor or the ceiling, and the photos, taken at the tags' height, barely show
  // them: they are put at the lowest and the highest dense point (the floor is no higher than
  // anything standing on it).
  Result<Mesh> dense = ReadPly(project + "/dense/points.ply");
  if (!dense.ok()) {
    std::fprintf(stderr, "%s\n", dense.status().ToString().c_str());
    return 1;
  }
  std::vector<double> heights;
  for (const Eigen::Vector3f& p : dense->positions) heights.push_back(up.dot(p.cast<double>()));
  std::sort(heights.begin(), heights.end());
  const double floor_height = heights.front(), ceiling_height = heights.back();
  Eigen::AlignedBox3d room;  // the tags' extent
  for (const LayoutTag& tag : layout->tags()) room.extend(tag.layout_from_tag.translation);
  for (const Wall& wall : walls) {
    std::vector<Eigen::Vector3d> corners;
    for (const LayoutTag* tag : wall.tags) {
      for (const Eigen::Vector3d& c : TagSquareCorners(tag->size)) corners.push_back(tag->layout_from_tag * c);
    }
    const PointSpread spread = SpreadOfPoints(corners);
    const Eigen::Vector3d& centre = spread.mean;
    // Walls stand upright: the normal of the tags' plane laid horizontal (a row of tags at one
    // height leaves the plane free to tilt about it).
    Eigen::Vector3d normal = spread.ThinnestAxis();
    normal = (normal - normal.dot(up) * up).normalized();
    if (normal.dot(wall.normal) < 0.0) normal = -normal;  // into the room
    const Eigen::Vector3d along = up.cross(normal).normalized();
    const Eigen::Vector3d vertical = normal.cross(along);
    double a_min = 1e9, a_max = -1e9, v_min = 1e9, v_max = -1e9;
    for (const Eigen::Vector3d& c : corners) {
      a_min = std::min(a_min, (c - centre).dot(along));
      a_max = std::max(a_max, (c - centre).dot(along));
      v_min = std::min(v_min, (c - centre).dot(vertical));
      v_max = std::max(v_max, (c - centre).dot(vertical));
    }
    a_min -= 0.5, a_max += 0.5;
    v_min = floor_height - (centre.dot(up)), v_max = ceiling_height - centre.dot(up);
    const Mesh box = FacingBox(centre, along, vertical, normal, a_min, a_max, v_min, v_max, to_design_mm);
    std::string name = "wall";
    for (const LayoutTag* tag : wall.tags) name += "_" + std::to_string(tag->id);
    // The flatness the tags show: their corners' distances from the wall's (upright) plane.
    double squares = 0.0, largest = 0.0;
    for (const Eigen::Vector3d& c : corners) {
      const double off = (c - centre).dot(normal);
      squares += off * off;
      largest = std::max(largest, std::abs(off));
    }
    std::printf("%s: %zu tags, normal (%.3f %.3f %.3f), %.2f x %.2f m; tag corners off its plane: RMS %.1f mm, "
                "largest %.1f mm\n",
                name.c_str(), wall.tags.size(), normal.x(), normal.y(), normal.z(), a_max - a_min, v_max - v_min,
                1000.0 * std::sqrt(squares / static_cast<double>(corners.size())), 1000.0 * largest);
    elements.push_back({name, box});
  }
  // Floor and ceiling: slabs over the tags' extent in x and z, half a metre beyond it.
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), z = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d middle = room.center();
  const double half_x = room.sizes().x() / 2 + 0.5, half_z = room.sizes().z() / 2 + 0.5;
  const Eigen::Vector3d floor_centre = middle + (floor_height - middle.dot(up)) * up;
  const Eigen::Vector3d ceiling_centre = middle + (ceiling_height - middle.dot(up)) * up;
  elements.push_back({"floor", FacingBox(floor_centre, x, -z, up, -half_x, half_x, -half_z, half_z, to_design_mm)});
  elements.push_back({"ceiling", FacingBox(ceiling_centre, x, z, -up, -half_x, half_x, -half_z, half_z, to_design_mm)});
  std::printf("floor at %.3f m, ceiling at %.3f m (the lowest and highest dense points), %.2f x %.2f m\n",
              floor_height, ceiling_height, 2 * half_x, 2 * half_z);
  if (Status written = WriteGlbScene(out + "/room_design.glb", elements); !written.ok()) {
    std::fprintf(stderr, "%s\n", written.ToString().c_str());
    return 1;
  }
  std::ofstream control(out + "/room_control.txt");
  control << "# tag centres in the room design's frame (millimetres, z up)\n";
  for (const LayoutTag& tag : layout->tags()) {
    const Eigen::Vector3d p = to_design_mm(tag.layout_from_tag.translation);
    control << tag.id << " " << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  std::printf("%zu walls written to %s/room_design.glb, control %s/room_control.txt\n", elements.size(), out.c_str(),
              out.c_str());
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
