#pragma once
// AprilTag corners seen in the photos of a project, as plain data for structure from motion
// (tracker/photo_tags.h detects them; core/sfm/tag_registration.h uses them). Stored in
// PROJECT/tags/detections.txt:
//   # reconar tag detections v1
//   family tag36h11
//   image NAME TAGS          then TAGS lines: ID x0 y0 x1 y1 x2 y2 x3 y3
// Pixels follow the SfM convention (reconstruction.h: the centre of the top-left pixel is (0, 0));
// corner k is the tag-frame point kTagCornerUnits[k] * size / 2 (tag frame: origin at the tag
// centre, x right, y up, z out of the printed tag toward the viewer; libapriltag's order).
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"

namespace reconar {

inline constexpr double kTagCornerUnits[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
// A tag's six corner-to-corner segments: its four edges (length = size), then its two diagonals.
inline constexpr int kTagSegments[6][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}, {1, 3}};

struct TagObservation {
  int tag_id = -1;
  std::array<Eigen::Vector2d, 4> corners;
};

struct ImageTagObservations {
  std::string image_name;
  std::vector<TagObservation> tags;  // at most one per id
};

struct TagDetectionsFile {
  std::string family;
  std::vector<ImageTagObservations> images;  // every photo of the project, tags or not
};

Status WriteTagDetections(const std::string& path, const TagDetectionsFile& file);  // atomic
// NotFound without the file; CorruptData naming the line otherwise.
Result<TagDetectionsFile> ReadTagDetections(const std::string& path);

}  // namespace reconar
