#include "tests/support/corridor_walk.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include "core/base/thread_pool.h"
#include "core/io/image_write.h"
#include "tests/support/corridor_rendering.h"
#include "tests/support/numbered_name.h"

namespace reconar::testing {
namespace corridor {

constexpr double kDegree = M_PI / 180.0;

Status CheckWalkOptions(const CorridorWalkOptions& options, const std::string& who) {
  if (options.frames < 1 || options.width < 8 || options.height < 8 || options.supersampling < 1 ||
      options.panel_length_m <= 0.0 || options.length_m <= 0.0 || options.texture_width_px < 8 ||
      !(options.half_width_m > 0.0) || !(options.eye_above_floor_m > 0.0) || !(options.ceiling_above_eye_m > 0.0)) {
    return InvalidArgument(who + ": unusable options");
  }
  return Status::Ok();
}

std::vector<RgbTexture> PanelTextures(const CorridorWalkOptions& options, int count) {
  std::vector<RgbTexture> textures(static_cast<size_t>(count));
  ThreadPool pool(options.threads);
  pool.ParallelFor(0, textures.size(), [&](size_t i, int) {
    textures[i] = DeadLeavesTexture(options.texture_width_px, options.texture_width_px * 3 / 4,
                                    options.texture_contrast, options.seed + static_cast<uint32_t>(i));
  });
  return textures;
}

GroundTruthCamera HandHeldCamera(const CorridorWalkOptions& options, int i, const Eigen::Vector3d& on_path,
                                 double heading) {
  GroundTruthCamera camera;
  camera.width = options.width;
  camera.height = options.height;
  camera.K << options.focal_px, 0.0, 0.5 * options.width, 0.0, options.focal_px, 0.5 * options.height, 0.0, 0.0, 1.0;
  const Eigen::Vector3d right(std::cos(heading), 0.0, -std::sin(heading));
  const Eigen::Vector3d centre =
      on_path + right * (0.12 * std::sin(0.7 * i)) + Eigen::Vector3d(0.0, 0.03 * std::sin(1.9 * i), 0.0);
  const Eigen::Matrix3d world_from_cam =
      (Eigen::AngleAxisd(heading + 3.0 * kDegree * std::sin(0.45 * i), Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(1.5 * kDegree * std::sin(0.8 * i), Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(1.0 * kDegree * std::sin(0.33 * i), Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  camera.cam_from_world_rotation = world_from_cam.transpose();
  camera.cam_from_world_translation = -camera.cam_from_world_rotation * centre;
  return camera;
}

Result<GroundTruthByName> RenderWalkFrames(const std::string& out_dir, const CorridorWalkOptions& options,
                                           const std::vector<GroundTruthCamera>& cameras,
                                           const std::function<Image<uint8_t>(const GroundTruthCamera&)>& render) {
  std::vector<std::string> names(cameras.size());
  std::vector<Status> written(cameras.size());
  ThreadPool pool(options.threads);
  pool.ParallelFor(0, cameras.size(), [&](size_t i, int) {
    names[i] = NumberedName("walk_", static_cast<int>(i), static_cast<int>(cameras.size()), 2, ".png");
    const Image<uint8_t> view = render(cameras[i]);
    written[i] = WritePng(out_dir + "/" + names[i], view.view(), 3);
  });
  GroundTruthByName truth;
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (!written[i].ok()) return written[i];
    truth[names[i]] = cameras[i];
  }
  return truth;
}

}  // namespace corridor

namespace {

// The straight corridor: walls at x = +-half_width_m, floor and ceiling, each papered along z with
// panels panel_length_m long (the first and last stretched beyond), and the end wall at z = length_m.
class Corridor {
 public:
  Corridor(const CorridorWalkOptions& options, std::vector<RgbTexture> textures)
      : options_(options),
        panels_(static_cast<int>(std::ceil(options.length_m / options.panel_length_m))),
        textures_(std::move(textures)) {}

  static int TextureCount(const CorridorWalkOptions& options) {
    return 4 * static_cast<int>(std::ceil(options.length_m / options.panel_length_m)) + 1;
  }

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
  std::vector<RgbTexture> textures_;
};

}  // namespace

Result<GroundTruthByName> RenderCorridorWalk(const std::string& out_dir, const CorridorWalkOptions& options) {
  RECONAR_RETURN_IF_ERROR(corridor::CheckWalkOptions(options, "RenderCorridorWalk"));
  const Corridor scene(options, corridor::PanelTextures(options, Corridor::TextureCount(options)));
  std::vector<GroundTruthCamera> cameras;
  for (int i = 0; i < options.frames; ++i) {
    cameras.push_back(corridor::HandHeldCamera(options, i, Eigen::Vector3d(0.0, 0.0, options.step_m * i), 0.0));
  }
  return corridor::RenderWalkFrames(out_dir, options, cameras, [&](const GroundTruthCamera& camera) {
    return corridor::RenderView(scene, camera, options.supersampling);
  });
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
