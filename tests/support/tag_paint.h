#pragma once
// Painting AprilTags out of photographs, to test what the program does without them (issue 15:
// markerless localisation in a room whose tags are painted out). Test support only.
//
// Each detected tag is covered whole: libapriltag's quad is the tag's black border square (8 of
// the tag36h11's 10 cells across); the printed tag is one white cell wider on every side. The
// quad is therefore grown to the white border's square through the detection's homography
// (tag coordinates (-1, -1)..(1, 1) scaled by 10/8, exact under perspective), then each edge is
// moved outward by a margin of a few pixels for blur and JPEG ringing, and the quad is filled with
// the mean grey of the original pixels inside it.
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "tracker/tag_detector.h"

namespace reconar::testing {

struct TagPaintOptions {
  double border_scale = 10.0 / 8.0;  // black-border square to the white border (tag36h11)
  double margin_px = 2.0;            // beyond the white border, along each edge's normal
};

// The four corners (pixels, our convention) of the region PaintOutTags fills for `detection`.
std::vector<Eigen::Vector2d> PaintedQuad(const TagDetection& detection, const TagPaintOptions& options = {});

// Fills every detection's PaintedQuad in `rgb` (3 channels, interleaved) with the mean grey
// (Rec.601 luma, as core/io/gray.h) of the original pixels inside it, as R = G = B. All means are
// taken before any tag is painted. Pixels are filled when their centre lies inside the quad;
// quads reaching beyond the image are clipped.
void PaintOutTags(const std::vector<TagDetection>& detections, Image<uint8_t>* rgb,
                  const TagPaintOptions& options = {});

// One photo read upright (core/io/image_io.h), its tags detected at full resolution
// (tracker/photo_tags.h, decimation 1 up to 2048 px), painted out and written as PNG to
// `png_path`. Returns the detections in the original photo. Errors name the file.
Result<std::vector<TagDetection>> PaintOutTagsInPhoto(const std::string& photo_path, const std::string& png_path,
                                                      const TagPaintOptions& options = {});

}  // namespace reconar::testing
