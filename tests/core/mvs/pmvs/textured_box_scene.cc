#include "tests/core/mvs/pmvs/textured_box_scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

namespace reconar::testing {
namespace {

uint64_t Hash(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdull;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ull;
  return x ^ (x >> 33);
}

// Value noise in [0, 1]: random values on the integer lattice, bilinearly interpolated.
double ValueNoise(uint64_t seed, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int64_t ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  auto lattice = [&](int64_t i, int64_t j) {
    const uint64_t h = Hash(seed ^ Hash(static_cast<uint64_t>(i) * 0x9E3779B97F4A7C15ull ^ static_cast<uint64_t>(j)));
    return static_cast<double>(h >> 11) * 0x1.0p-53;
  };
  const double ax = x - fx, ay = y - fy;
  const double top = lattice(ix, iy) + ax * (lattice(ix + 1, iy) - lattice(ix, iy));
  const double bottom = lattice(ix, iy + 1) + ax * (lattice(ix + 1, iy + 1) - lattice(ix, iy + 1));
  return top + ay * (bottom - top);
}

}  // namespace

TexturedBoxScene::TexturedBoxScene(const TexturedBoxSceneOptions& options) : options_(options) {
  const double h = options.box_half_size, z = options.box_height, g = options.ground_half_size;
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
  faces_.push_back({Eigen::Vector3d(-g, -g, 0.0), ex, ey, ez, 2 * g, 2 * g});  // ground
  faces_.push_back({Eigen::Vector3d(-h, -h, z), ex, ey, ez, 2 * h, 2 * h});    // top
  faces_.push_back({Eigen::Vector3d(h, -h, 0.0), ey, ez, ex, 2 * h, z});       // +x
  faces_.push_back({Eigen::Vector3d(-h, -h, 0.0), ey, ez, -ex, 2 * h, z});     // -x
  faces_.push_back({Eigen::Vector3d(-h, h, 0.0), ex, ez, ey, 2 * h, z});       // +y
  faces_.push_back({Eigen::Vector3d(-h, -h, 0.0), ex, ez, -ey, 2 * h, z});     // -y

  for (int c = 0; c < options.num_cameras; ++c) {
    const double angle = 2.0 * M_PI * (c + 0.125) / options.num_cameras;
    const Eigen::Vector3d center(options.ring_radius * std::cos(angle), options.ring_radius * std::sin(angle),
                                 options.ring_height);
    const Eigen::Vector3d forward = (options.target - center).normalized();
    const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d down = forward.cross(right);
    DenseView view;
    view.name = "synthetic_" + std::to_string(c);
    view.image_id = c;
    view.fx = view.fy = options.focal;
    view.cx = 0.5 * (options.width - 1);
    view.cy = 0.5 * (options.height - 1);
    Eigen::Matrix3d rotation;  // rows: camera axes in world coordinates
    rotation.row(0) = right.transpose();
    rotation.row(1) = down.transpose();
    rotation.row(2) = forward.transpose();
    view.cam_from_world.rotation = rotation;
    view.cam_from_world.translation = -rotation * center;
    view.gray = Image<uint8_t>(options.width, options.height, 1);
    view.rgb = Image<uint8_t>(options.width, options.height, 3);
    for (int y = 0; y < options.height; ++y) {
      for (int x = 0; x < options.width; ++x) {
        const Eigen::Vector3d direction =
            (rotation.transpose() * Eigen::Vector3d((x - view.cx) / view.fx, (y - view.cy) / view.fy, 1.0)).normalized();
        const SceneHit hit = Intersect(center, direction);
        double value = 0.5;  // background grey
        if (hit.hit) {
          const Face& f = faces_[hit.face];
          const Eigen::Vector3d local = hit.point - f.origin;
          value =
              InBlankPanel(hit.face, hit.point) ? kBlankPanelValue : Texture(hit.face, local.dot(f.u), local.dot(f.v));
        }
        const uint8_t g8 = static_cast<uint8_t>(std::clamp(std::lround(value * 255.0), 0L, 255L));
        view.gray.row(y)[x] = g8;
        uint8_t* rgb = view.rgb.row(y) + 3 * x;
        rgb[0] = rgb[1] = rgb[2] = g8;
      }
    }
    views_.push_back(std::move(view));
  }
}

std::vector<const DenseView*> TexturedBoxScene::view_pointers() const {
  std::vector<const DenseView*> out;
  for (const DenseView& v : views_) out.push_back(&v);
  return out;
}

double TexturedBoxScene::Texture(int face, double a, double b) const {
  const uint64_t seed = Hash(options_.seed * 131 + static_cast<uint64_t>(face));
  const double fine = ValueNoise(seed, a / options_.texel, b / options_.texel);
  const double coarse = ValueNoise(Hash(seed), a / (4.0 * options_.texel), b / (4.0 * options_.texel));
  return 0.1 + 0.8 * (0.6 * fine + 0.4 * coarse);
}

bool TexturedBoxScene::InBlankPanel(int face, const Eigen::Vector3d& x) const {
  const double inset = options_.blank_panel_inset;
  if (!(inset > 0.0) || face < 2 || face >= static_cast<int>(faces_.size())) return false;  // the box's sides
  const Face& f = faces_[static_cast<size_t>(face)];
  const double a = (x - f.origin).dot(f.u), b = (x - f.origin).dot(f.v);
  return a > inset && a < f.extent_u - inset && b > inset && b < f.extent_v - inset;
}

SceneHit TexturedBoxScene::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
  SceneHit best;
  for (int i = 0; i < static_cast<int>(faces_.size()); ++i) {
    const Face& f = faces_[i];
    const double denominator = direction.dot(f.normal);
    if (std::abs(denominator) < 1e-12) continue;
    const double s = (f.origin - origin).dot(f.normal) / denominator;
    if (!(s > 1e-9) || (best.hit && s >= best.distance)) continue;
    const Eigen::Vector3d p = origin + s * direction;
    const double a = (p - f.origin).dot(f.u), b = (p - f.origin).dot(f.v);
    if (a < 0.0 || b < 0.0 || a > f.extent_u || b > f.extent_v) continue;
    best = {true, s, i, p};
  }
  return best;
}

double TexturedBoxScene::DistanceToSurface(const Eigen::Vector3d& x, Eigen::Vector3d* normal) const {
  double best = std::numeric_limits<double>::infinity();
  for (const Face& f : faces_) {
    const Eigen::Vector3d d = x - f.origin;
    const double a = std::clamp(d.dot(f.u), 0.0, f.extent_u), b = std::clamp(d.dot(f.v), 0.0, f.extent_v);
    const double distance = (x - (f.origin + a * f.u + b * f.v)).norm();
    if (distance < best) {
      best = distance;
      if (normal) *normal = f.normal;
    }
  }
  return best;
}

bool TexturedBoxScene::Sees(const DenseView& view, const Eigen::Vector3d& x) const {
  const Eigen::Vector3d center = view.Center();
  const Eigen::Vector3d to_point = x - center;
  const double distance = to_point.norm();
  const SceneHit hit = Intersect(center, to_point / distance);
  return hit.hit && hit.distance > distance - 1e-6 * distance - 1e-9;
}

}  // namespace reconar::testing
