#include "tests/support/corridor_walk.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <string>

#include "core/io/image_write.h"

namespace reconar::testing {
namespace {

constexpr double kDegree = M_PI / 180.0;

struct Texture {
  Image<float> rgb;  // 3 channels

  // Bilinear sample at (u, v) in [0, 1]^2.
  Eigen::Vector3f Sample(double u, double v) const {
    const double x = std::clamp(u, 0.0, 1.0) * (rgb.width() - 1);
    const double y = std::clamp(v, 0.0, 1.0) * (rgb.height() - 1);
    const int x0 = std::min(static_cast<int>(x), rgb.width() - 2);
    const int y0 = std::min(static_cast<int>(y), rgb.height() - 2);
    const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
    Eigen::Vector3f out = Eigen::Vector3f::Zero();
    const float weights[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    for (int k = 0; k < 4; ++k) {
      const float* pixel = rgb.row(y0 + k / 2) + 3 * (x0 + k % 2);
      out += weights[k] * Eigen::Vector3f(pixel[0], pixel[1], pixel[2]);
    }
    return out;
  }
};

// A "dead leaves" picture: opaque discs with radii drawn from p(r) ~ r^-3, the scale-invariant
// model of natural images' statistics (Lee, Mumford and Huang, IJCV 2001), here of low contrast:
// a painted wall's colour, each disc within about +-`contrast` grey levels of it. Every seed gives a different picture,
// so no two panels of the corridor look alike.
Texture DeadLeaves(int width, int height, double contrast, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Texture texture;
  texture.rgb = Image<float>(width, height, 3);
  float wall[3];
  for (float& c : wall) c = static_cast<float>(80.0 + 100.0 * unit(random));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) std::copy(wall, wall + 3, texture.rgb.row(y) + 3 * x);
  }
  const double r_min = 2.0, r_max = 0.12 * width;
  const double a = 1.0 / (r_min * r_min), b = 1.0 / (r_max * r_max);
  const int discs = 3 * width * height / 1000;
  for (int i = 0; i < discs; ++i) {
    const double radius = 1.0 / std::sqrt(a - unit(random) * (a - b));
    const double cx = unit(random) * width, cy = unit(random) * height;
    float colour[3];
    const double shade = contrast * (2.0 * unit(random) - 1.0);
    for (int c = 0; c < 3; ++c) colour[c] = static_cast<float>(wall[c] + shade * (0.8 + 0.4 * unit(random)));
    const int x0 = std::max(0, static_cast<int>(cx - radius)), x1 = std::min(width - 1, static_cast<int>(cx + radius));
    const int y0 = std::max(0, static_cast<int>(cy - radius)), y1 = std::min(height - 1, static_cast<int>(cy + radius));
    for (int y = y0; y <= y1; ++y) {
      float* row = texture.rgb.row(y);
      for (int x = x0; x <= x1; ++x) {
        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) > radius * radius) continue;
        for (int c = 0; c < 3; ++c) row[3 * x + c] = colour[c];
      }
    }
  }
  return texture;
}

class Corridor {
 public:
  Corridor(const CorridorWalkOptions& options, std::vector<Texture> textures)
      : options_(options),
        panels_(static_cast<int>(std::ceil(options.length_m / options.panel_length_m))),
        textures_(std::move(textures)) {}

  // The colour seen along the ray from `origin` in direction `direction` (world frame).
  Eigen::Vector3f Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
    const double height = options_.eye_above_floor_m + options_.ceiling_above_eye_m;
    double nearest = std::numeric_limits<double>::infinity();
    Eigen::Vector3f colour(0.0f, 0.0f, 0.0f);
    // Each surface: the plane coordinate along `axis`, then (u, v) of the hit on its panel.
    auto try_plane = [&](int axis, double plane, auto&& texture_at) {
      if (std::abs(direction[axis]) < 1e-12) return;
      const double t = (plane - origin[axis]) / direction[axis];
      if (t <= 0.0 || t >= nearest) return;
      nearest = t;
      colour = texture_at(origin + t * direction);
    };
    auto along = [&](const Eigen::Vector3d& hit, int first, double across) {
      const double panel_coordinate = hit.z() / options_.panel_length_m;
      const int panel = std::clamp(static_cast<int>(std::floor(panel_coordinate)), 0, panels_ - 1);
      const double u = std::clamp(panel_coordinate - panel, 0.0, 1.0);
      return textures_[static_cast<size_t>(4 * panel + first)].Sample(u, across);
    };
    const double w = options_.half_width_m;
    const double up = options_.ceiling_above_eye_m;
    try_plane(0, -w, [&](const Eigen::Vector3d& hit) { return along(hit, 0, (hit.y() + up) / height); });
    try_plane(0, w, [&](const Eigen::Vector3d& hit) { return along(hit, 1, (hit.y() + up) / height); });
    try_plane(1, options_.eye_above_floor_m,
              [&](const Eigen::Vector3d& hit) { return along(hit, 2, (hit.x() + w) / (2 * w)); });
    try_plane(1, -up, [&](const Eigen::Vector3d& hit) { return along(hit, 3, (hit.x() + w) / (2 * w)); });
    try_plane(2, options_.length_m, [&](const Eigen::Vector3d& hit) {
      return textures_[static_cast<size_t>(4 * panels_)].Sample((hit.x() + w) / (2 * w), (hit.y() + up) / height);
    });
    return colour;
  }

 private:
  CorridorWalkOptions options_;
  int panels_;
  std::vector<Texture> textures_;
};

// Frame i of the walk: forward by step_m, with a sway, a bob and small turns.
GroundTruthCamera WalkCamera(const CorridorWalkOptions& options, int i) {
  GroundTruthCamera camera;
  camera.width = options.width;
  camera.height = options.height;
  camera.K << options.focal_px, 0.0, 0.5 * options.width, 0.0, options.focal_px, 0.5 * options.height, 0.0, 0.0, 1.0;
  const Eigen::Vector3d centre(0.12 * std::sin(0.7 * i), 0.03 * std::sin(1.9 * i), options.step_m * i);
  const Eigen::Matrix3d world_from_cam =
      (Eigen::AngleAxisd(3.0 * kDegree * std::sin(0.45 * i), Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(1.5 * kDegree * std::sin(0.8 * i), Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(1.0 * kDegree * std::sin(0.33 * i), Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  camera.cam_from_world_rotation = world_from_cam.transpose();
  camera.cam_from_world_translation = -camera.cam_from_world_rotation * centre;
  return camera;
}

Image<uint8_t> RenderView(const Corridor& corridor, const GroundTruthCamera& camera, int supersampling) {
  Image<uint8_t> image(camera.width, camera.height, 3);
  const Eigen::Matrix3d world_from_cam = camera.cam_from_world_rotation.transpose();
  const Eigen::Vector3d centre = camera.Centre();
  const double focal = camera.K(0, 0), cx = camera.K(0, 2), cy = camera.K(1, 2);
  const float norm = 1.0f / static_cast<float>(supersampling * supersampling);
  for (int y = 0; y < camera.height; ++y) {
    uint8_t* row = image.row(y);
    for (int x = 0; x < camera.width; ++x) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      for (int sy = 0; sy < supersampling; ++sy) {
        for (int sx = 0; sx < supersampling; ++sx) {
          // Pixel centres at integer coordinates; samples spread evenly over the pixel's square.
          const double px = x - 0.5 + (sx + 0.5) / supersampling;
          const double py = y - 0.5 + (sy + 0.5) / supersampling;
          sum += corridor.Trace(centre, world_from_cam * Eigen::Vector3d((px - cx) / focal, (py - cy) / focal, 1.0));
        }
      }
      for (int c = 0; c < 3; ++c) row[3 * x + c] = static_cast<uint8_t>(std::clamp(sum[c] * norm + 0.5f, 0.0f, 255.0f));
    }
  }
  return image;
}

}  // namespace

Result<GroundTruthByName> RenderCorridorWalk(const std::string& out_dir, const CorridorWalkOptions& options) {
  if (options.frames < 1 || options.width < 8 || options.height < 8 || options.supersampling < 1 ||
      options.panel_length_m <= 0.0 || options.length_m <= 0.0 || options.texture_width_px < 8) {
    return InvalidArgument("RenderCorridorWalk: unusable options");
  }
  const int panels = static_cast<int>(std::ceil(options.length_m / options.panel_length_m));
  std::vector<Texture> textures;
  for (int i = 0; i < 4 * panels + 1; ++i) {
    textures.push_back(DeadLeaves(options.texture_width_px, options.texture_width_px * 3 / 4, options.texture_contrast,
                                  options.seed + static_cast<uint32_t>(i)));
  }
  const Corridor corridor(options, std::move(textures));
  GroundTruthByName truth;
  // Zero-padded to the last frame's digits, so that a plain string sort keeps the walk's order too.
  const int digits = std::max(2, static_cast<int>(std::to_string(options.frames - 1).size()));
  for (int i = 0; i < options.frames; ++i) {
    const std::string number = std::to_string(i);
    const std::string name = "walk_" + std::string(static_cast<size_t>(digits) - number.size(), '0') + number + ".png";
    const GroundTruthCamera camera = WalkCamera(options, i);
    const Image<uint8_t> view = RenderView(corridor, camera, options.supersampling);
    const Status written = WritePng(out_dir + "/" + name, view.view(), 3);
    if (!written.ok()) return written;
    truth[name] = camera;
  }
  return truth;
}

Result<CorridorVideo> RenderCorridorVideo(const std::string& out_dir) {
  CorridorVideo video;
  video.walk.frames = 90;
  video.walk.step_m = 0.05;
  std::error_code error;
  std::filesystem::create_directories(out_dir, error);
  if (error) return IoError(out_dir + ": cannot create the directory: " + error.message());
  RECONAR_ASSIGN_OR_RETURN(video.truth, RenderCorridorWalk(out_dir, video.walk));
  for (const auto& [name, camera] : video.truth) video.names.push_back(name);
  std::sort(video.names.begin(), video.names.end());
  return video;
}

}  // namespace reconar::testing
