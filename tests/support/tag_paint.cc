#include "tests/support/tag_paint.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "core/io/image_io.h"
#include "core/io/image_write.h"
#include "tracker/photo_tags.h"

namespace reconar::testing {
namespace {

// Crossing-number test of the point against the closed polygon `quad`.
bool Inside(const std::vector<Eigen::Vector2d>& quad, double x, double y) {
  bool inside = false;
  for (size_t i = 0, j = quad.size() - 1; i < quad.size(); j = i++) {
    const Eigen::Vector2d& a = quad[i];
    const Eigen::Vector2d& b = quad[j];
    if ((a.y() > y) != (b.y() > y) && x < (b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()) + a.x()) inside = !inside;
  }
  return inside;
}

struct PixelBox {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  // inclusive, clipped to the image
};

PixelBox BoxOf(const std::vector<Eigen::Vector2d>& quad, int width, int height) {
  double min_x = quad[0].x(), max_x = quad[0].x(), min_y = quad[0].y(), max_y = quad[0].y();
  for (const Eigen::Vector2d& p : quad) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) return PixelBox();
    min_x = std::min(min_x, p.x());
    max_x = std::max(max_x, p.x());
    min_y = std::min(min_y, p.y());
    max_y = std::max(max_y, p.y());
  }
  PixelBox box;
  box.x0 = static_cast<int>(std::max(0.0, std::floor(min_x)));
  box.y0 = static_cast<int>(std::max(0.0, std::floor(min_y)));
  box.x1 = static_cast<int>(std::min(static_cast<double>(width - 1), std::ceil(max_x)));
  box.y1 = static_cast<int>(std::min(static_cast<double>(height - 1), std::ceil(max_y)));
  return box;
}

double Luma(const uint8_t* rgb) { return 0.299 * rgb[0] + 0.587 * rgb[1] + 0.114 * rgb[2]; }

}  // namespace

std::vector<Eigen::Vector2d> PaintedQuad(const TagDetection& detection, const TagPaintOptions& options) {
  // Tag coordinates of the black square's corners in cyclic order; grown by border_scale.
  constexpr double kUnit[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  std::vector<Eigen::Vector2d> quad(4);
  bool through_homography = true;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d h = detection.homography * Eigen::Vector3d(options.border_scale * kUnit[k][0],
                                                                     options.border_scale * kUnit[k][1], 1.0);
    through_homography = through_homography && h.z() > 0.0;
    quad[static_cast<size_t>(k)] = h.head<2>() / h.z();
  }
  if (!through_homography) {  // a degenerate homography: grow the corners about the centre instead
    for (int k = 0; k < 4; ++k) {
      quad[static_cast<size_t>(k)] =
          detection.center + options.border_scale * (detection.corners[k] - detection.center);
    }
  }
  // Each edge moved outward by margin_px along its normal; the corners where the moved edges meet.
  Eigen::Vector2d normals[4];
  for (size_t k = 0; k < 4; ++k) {
    const Eigen::Vector2d edge = quad[(k + 1) % 4] - quad[k];
    Eigen::Vector2d normal(edge.y(), -edge.x());
    if (normal.dot(quad[k] - detection.center) < 0.0) normal = -normal;
    const double length = normal.norm();
    normals[k] = length > 0.0 ? Eigen::Vector2d(normal / length) : Eigen::Vector2d::Zero();
  }
  std::vector<Eigen::Vector2d> grown(4);
  for (size_t k = 0; k < 4; ++k) {
    // Corner k joins edge k - 1 (with normal a) and edge k (with normal b): x . a = p . a + m,
    // x . b = p . b + m.
    const Eigen::Vector2d& a = normals[(k + 3) % 4];
    const Eigen::Vector2d& b = normals[k];
    Eigen::Matrix2d lines;
    lines << a.transpose(), b.transpose();
    const Eigen::Vector2d offsets(quad[k].dot(a) + options.margin_px, quad[k].dot(b) + options.margin_px);
    const double det = lines.determinant();
    grown[k] = std::abs(det) > 1e-6 ? Eigen::Vector2d(lines.inverse() * offsets)
                                    : Eigen::Vector2d(quad[k] + options.margin_px * (a + b).normalized());
  }
  quad = grown;
  return quad;
}

void PaintOutTags(const std::vector<TagDetection>& detections, Image<uint8_t>* rgb, const TagPaintOptions& options) {
  const int width = rgb->width();
  const int height = rgb->height();
  std::vector<std::vector<Eigen::Vector2d>> quads;
  std::vector<uint8_t> greys;
  for (const TagDetection& detection : detections) {
    quads.push_back(PaintedQuad(detection, options));
    const PixelBox box = BoxOf(quads.back(), width, height);
    double sum = 0.0;
    int count = 0;
    for (int y = box.y0; y <= box.y1; ++y) {
      for (int x = box.x0; x <= box.x1; ++x) {
        if (!Inside(quads.back(), x, y)) continue;
        sum += Luma(rgb->row(y) + 3 * x);
        ++count;
      }
    }
    greys.push_back(count > 0 ? static_cast<uint8_t>(std::lround(sum / count)) : 128);
  }
  for (size_t t = 0; t < quads.size(); ++t) {
    const PixelBox box = BoxOf(quads[t], width, height);
    for (int y = box.y0; y <= box.y1; ++y) {
      for (int x = box.x0; x <= box.x1; ++x) {
        if (!Inside(quads[t], x, y)) continue;
        uint8_t* pixel = rgb->row(y) + 3 * x;
        pixel[0] = pixel[1] = pixel[2] = greys[t];
      }
    }
  }
}

Result<std::vector<TagDetection>> PaintOutTagsInPhoto(const std::string& photo_path, const std::string& png_path,
                                                      const TagPaintOptions& options) {
  PhotoTagOptions tag_options;
  tag_options.num_threads = 1;
  tag_options.show_progress = false;
  RECONAR_ASSIGN_OR_RETURN(std::vector<PhotoDetections> found, DetectAllTagsInPhotos({photo_path}, tag_options));
  RECONAR_ASSIGN_OR_RETURN(DecodedImage decoded, ReadImage(photo_path));
  if (decoded.rgb.channels() != 3) return InvalidArgument(photo_path + ": not an RGB image");
  PaintOutTags(found[0].detections, &decoded.rgb, options);
  RECONAR_RETURN_IF_ERROR(WritePng(png_path, decoded.rgb.view(), 3));
  return found[0].detections;
}

}  // namespace reconar::testing
