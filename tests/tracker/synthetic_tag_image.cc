#include "tests/tracker/synthetic_tag_image.h"

#include <algorithm>
#include <cmath>
#include <vector>


#include <Eigen/Geometry>
#include <Eigen/LU>

#include "tracker/tag_pose.h"

namespace reconar {
namespace testing {
namespace {

// Pixel-edge coordinates (pixel (i, j) covers [i, i+1] x [j, j+1]) from tag-plane point (X, Y, 1).
Eigen::Matrix3d PixelFromTagPlane(const SyntheticTag& tag, const CameraIntrinsics& camera) {
  Eigen::Matrix3d K;
  K << camera.fx, 0.0, camera.cx + 0.5, 0.0, camera.fy, camera.cy + 0.5, 0.0, 0.0, 1.0;
  Eigen::Matrix3d M;
  M.col(0) = tag.cam_from_tag.rotation.col(0);
  M.col(1) = tag.cam_from_tag.rotation.col(1);
  M.col(2) = tag.cam_from_tag.translation;
  return K * M;
}

void GaussianBlur(double sigma, Image<uint8_t>* image) {
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0.0;
  for (int i = -radius; i <= radius; ++i) sum += kernel[i + radius] = std::exp(-0.5 * i * i / (sigma * sigma));
  for (double& k : kernel) k /= sum;
  const int w = image->width(), h = image->height();
  std::vector<double> tmp(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double acc = 0.0;
      for (int i = -radius; i <= radius; ++i) acc += kernel[i + radius] * image->row(y)[std::clamp(x + i, 0, w - 1)];
      tmp[static_cast<size_t>(y) * w + x] = acc;
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double acc = 0.0;
      for (int i = -radius; i <= radius; ++i) acc += kernel[i + radius] * tmp[static_cast<size_t>(std::clamp(y + i, 0, h - 1)) * w + x];
      image->row(y)[x] = static_cast<uint8_t>(std::lround(std::clamp(acc, 0.0, 255.0)));
    }
  }
}

}  // namespace

std::array<Eigen::Vector2d, 4> ProjectedCorners(const SyntheticTag& tag, const CameraIntrinsics& camera) {
  const std::array<Eigen::Vector3d, 4> corners = TagCornersInTagFrame(tag.size);
  std::array<Eigen::Vector2d, 4> out;
  for (int k = 0; k < 4; ++k) out[k] = camera.Project(tag.cam_from_tag * corners[k]);
  return out;
}

bool DrawTag(const SyntheticTag& tag, const CameraIntrinsics& camera, int supersampling, Image<uint8_t>* image) {
  const Result<TagBitmap> bitmap = RenderTagBitmap(tag.family, tag.id);
  if (!bitmap.ok() || !(tag.cam_from_tag.translation.z() > 0.0)) return false;
  const Image<uint8_t>& bits = bitmap->pixels;
  const int total = bits.width();
  const double module = tag.size / bitmap->width_at_border;
  const Eigen::Matrix3d H = PixelFromTagPlane(tag, camera);
  const Eigen::Matrix3d H_inv = H.inverse();
  // Bounding box of the whole bitmap (white border included).
  const double half_total = 0.5 * total * module;
  double x_lo = 1e30, y_lo = 1e30, x_hi = -1e30, y_hi = -1e30;
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(-half_total, -half_total), Eigen::Vector2d(half_total, -half_total),
                                   Eigen::Vector2d(half_total, half_total), Eigen::Vector2d(-half_total, half_total)}) {
    const Eigen::Vector2d p = (H * c.homogeneous()).hnormalized();
    x_lo = std::min(x_lo, p.x()); x_hi = std::max(x_hi, p.x());
    y_lo = std::min(y_lo, p.y()); y_hi = std::max(y_hi, p.y());
  }
  const int x0 = std::max(0, static_cast<int>(std::floor(x_lo)) - 1);
  const int y0 = std::max(0, static_cast<int>(std::floor(y_lo)) - 1);
  const int x1 = std::min(image->width(), static_cast<int>(std::ceil(x_hi)) + 1);
  const int y1 = std::min(image->height(), static_cast<int>(std::ceil(y_hi)) + 1);
  const int s = supersampling;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      double acc = 0.0;
      int inside = 0;
      for (int sy = 0; sy < s; ++sy) {
        for (int sx = 0; sx < s; ++sx) {
          const Eigen::Vector3d q = H_inv * Eigen::Vector3d(x + (sx + 0.5) / s, y + (sy + 0.5) / s, 1.0);
          const Eigen::Vector2d plane = q.hnormalized();
          // Bitmap columns run along +x, rows along -y (tag frame y points up).
          const double u = (plane.x() + half_total) / module;
          const double v = (half_total - plane.y()) / module;
          if (q.z() <= 0.0 || u < 0.0 || v < 0.0 || u >= total || v >= total) {
            acc += image->row(y)[x];
            continue;
          }
          acc += bits.row(static_cast<int>(v))[static_cast<int>(u)];
          ++inside;
        }
      }
      if (inside > 0) image->row(y)[x] = static_cast<uint8_t>(std::lround(acc / (s * s)));
    }
  }
  return true;
}

Image<uint8_t> RenderTags(const SyntheticTag* tags, int count, const CameraIntrinsics& camera,
                          const SyntheticRenderOptions& options) {
  Image<uint8_t> image(camera.width, camera.height, 1);
  std::fill(image.data(), image.data() + image.size_bytes(), options.background);
  for (int i = 0; i < count; ++i) DrawTag(tags[i], camera, options.supersampling, &image);
  if (options.blur_sigma > 0.0) GaussianBlur(options.blur_sigma, &image);
  return image;
}

SyntheticTag TiltedTag(int id, const Eigen::Vector3d& translation, double angle_deg) {
  SyntheticTag tag;
  tag.id = id;
  tag.size = 0.1;
  // The tag faces the camera: tag z toward the viewer = camera -z; tilted a little.
  const Eigen::Matrix3d facing = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  tag.cam_from_tag.rotation = Eigen::AngleAxisd(angle_deg * M_PI / 180.0, Eigen::Vector3d(0.3, 1.0, 0.2).normalized())
                                  .toRotationMatrix() * facing;
  tag.cam_from_tag.translation = translation;
  return tag;
}

CameraIntrinsics TestCamera() {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = camera.fy = 600.0;
  camera.cx = 320.0;
  camera.cy = 240.0;
  return camera;
}

}  // namespace testing
}  // namespace reconar
