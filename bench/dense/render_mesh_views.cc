// Renders a mesh or point cloud (.ply or .glb) offscreen from a few viewpoints around it, so that a
// reconstruction can be looked at without a display: a ring of views around the chosen up axis at
// 25 degrees elevation, one view from 70 degrees, each written as PNG, plus overview.png with all of
// them tiled 3 across. The framing fits the 1st..99th percentile box of the vertices. Surfaceless EGL (Mesa llvmpipe here); headlight Lambert shading or the
// vertex colours (render/mesh_drawable.h).
//
// Usage: render_mesh_views MESH OUT_DIR [--views N=6] [--size WxH=640x480] [--up +x|-x|+y|-y|+z|-z]
//                          [--point-size PX=2] [--elevation DEG=25]
// --up defaults to -y, the "up" of a model whose first camera looked level (SfM frames, camera y down).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/io/image_write.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_io.h"
#include "platform/egl/egl_context.h"
#include "render/overlay_renderer.h"

namespace reconar {
namespace {

struct Options {
  std::string mesh_path;
  std::string out_dir;
  int views = 6;
  int width = 640;
  int height = 480;
  Eigen::Vector3d up = -Eigen::Vector3d::UnitY();
  float point_size = 2.0f;
  double elevation_deg = 25.0;
};

int Usage(const char* message) {
  std::fprintf(stderr,
               "render_mesh_views: %s\n"
               "usage: render_mesh_views MESH(.ply|.glb) OUT_DIR [--views N] [--size WxH] [--up +x|-x|+y|-y|+z|-z]\n"
               "                         [--point-size PX] [--elevation DEG]\n",
               message);
  return 2;
}

bool ParseUp(const std::string& text, Eigen::Vector3d* up) {
  if (text.size() != 2 || (text[0] != '+' && text[0] != '-')) return false;
  const int axis = text[1] == 'x' ? 0 : text[1] == 'y' ? 1 : text[1] == 'z' ? 2 : -1;
  if (axis < 0) return false;
  *up = Eigen::Vector3d::Unit(axis) * (text[0] == '+' ? 1.0 : -1.0);
  return true;
}

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// cam_from_world of a camera at `center` looking at `target`, image up along `up`.
Rigid3 LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - center).normalized();
  Eigen::Vector3d x = z.cross(up);
  if (x.norm() < 1e-9) x = z.unitOrthogonal();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Rigid3 cam_from_world;
  cam_from_world.rotation.row(0) = x.transpose();
  cam_from_world.rotation.row(1) = y.transpose();
  cam_from_world.rotation.row(2) = z.transpose();
  cam_from_world.translation = -cam_from_world.rotation * center;
  return cam_from_world;
}

int Run(const Options& options) {
  Result<Mesh> mesh = EndsWith(options.mesh_path, ".glb") ? ReadGlb(options.mesh_path) : ReadPly(options.mesh_path);
  if (!mesh.ok()) return Usage(mesh.status().ToString().c_str());
  if (mesh->positions.empty()) return Usage("the mesh has no vertices");
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const Eigen::Vector3f& p : mesh->positions) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  std::printf("%s: %zu vertices, %zu triangles, box (%.4g %.4g %.4g) .. (%.4g %.4g %.4g)\n", options.mesh_path.c_str(),
              mesh->positions.size(), mesh->triangles.size(), lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
  // Framing: the 1st..99th percentile box per axis, so that a few stray points (dense outliers)
  // do not shrink the object to a dot.
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<float> values;
    values.reserve(mesh->positions.size());
    for (const Eigen::Vector3f& p : mesh->positions) values.push_back(p[axis]);
    const size_t n = values.size();
    std::nth_element(values.begin(), values.begin() + n / 100, values.end());
    lo[axis] = values[n / 100];
    std::nth_element(values.begin(), values.begin() + (n - 1 - n / 100), values.end());
    hi[axis] = values[n - 1 - n / 100];
  }
  const Eigen::Vector3d target = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-9);

  EglContextOptions context_options;
  context_options.kind = EglContextKind::kSurfaceless;
  auto context = EglContext::Create(context_options);
  if (!context.ok()) return Usage(context.status().ToString().c_str());
  OverlayRendererOptions renderer_options;
  renderer_options.width = options.width;
  renderer_options.height = options.height;
  renderer_options.samples = 4;
  renderer_options.clear_color = {0.12f, 0.12f, 0.14f};
  // The bounding sphere fills 90 % of the shorter image side: f = width gives a 53-degree horizontal field.
  CameraIntrinsics intrinsics;
  intrinsics.width = options.width;
  intrinsics.height = options.height;
  intrinsics.fx = intrinsics.fy = options.width;
  intrinsics.cx = 0.5 * (options.width - 1);
  intrinsics.cy = 0.5 * (options.height - 1);
  const double half_angle = std::atan(0.45 * std::min(options.width, options.height) / intrinsics.fx);
  const double distance = radius / std::sin(half_angle);
  renderer_options.depth.near_m = std::max(1e-6, 0.05 * (distance - radius));
  renderer_options.depth.far_m = 2.0 * (distance + radius);
  auto renderer = OverlayRenderer::Create(renderer_options);
  if (!renderer.ok()) return Usage(renderer.status().ToString().c_str());
  auto drawable = MeshDrawable::Upload(*mesh);
  if (!drawable.ok()) return Usage(drawable.status().ToString().c_str());
  MeshStyle style;
  style.point_size_px = options.point_size;

  const Eigen::Vector3d up = options.up;
  const Eigen::Vector3d side = up.unitOrthogonal();
  const Eigen::Vector3d front = up.cross(side);
  std::vector<std::pair<double, double>> directions;  // (azimuth, elevation) in radians
  for (int i = 0; i < options.views; ++i) {
    directions.emplace_back(2.0 * M_PI * i / options.views, options.elevation_deg * M_PI / 180.0);
  }
  directions.emplace_back(0.0, 70.0 * M_PI / 180.0);

  if (!CreateDirectories(options.out_dir).ok()) return Usage(("cannot create " + options.out_dir).c_str());
  const int columns = 3;
  const int rows = (static_cast<int>(directions.size()) + columns - 1) / columns;
  Image<uint8_t> overview(columns * options.width, rows * options.height, 3);
  Image<uint8_t> rgb;
  for (size_t i = 0; i < directions.size(); ++i) {
    const auto [azimuth, elevation] = directions[i];
    const Eigen::Vector3d direction = std::cos(elevation) * (std::cos(azimuth) * front + std::sin(azimuth) * side) +
                                      std::sin(elevation) * up;
    const Rigid3 cam_from_world = LookAt(target + distance * direction, target, up);
    Status status = (*renderer)->BeginFrame();
    if (status.ok()) status = (*renderer)->DrawMesh(*drawable, intrinsics, cam_from_world.Matrix(), style);
    if (status.ok()) status = (*renderer)->ReadRgb(&rgb);
    char name[32];
    std::snprintf(name, sizeof(name), "view_%02zu.png", i);
    if (status.ok()) status = WritePng(options.out_dir + "/" + name, rgb.view(), 3);
    if (!status.ok()) {
      std::fprintf(stderr, "render_mesh_views: %s\n", status.ToString().c_str());
      return 1;
    }
    const int x0 = static_cast<int>(i % columns) * options.width;
    const int y0 = static_cast<int>(i / columns) * options.height;
    for (int y = 0; y < options.height; ++y) {
      std::memcpy(overview.row(y0 + y) + 3 * x0, rgb.row(y), 3 * static_cast<size_t>(options.width));
    }
  }
  const Status status = WritePng(options.out_dir + "/overview.png", overview.view(), 3);
  if (!status.ok()) {
    std::fprintf(stderr, "render_mesh_views: %s\n", status.ToString().c_str());
    return 1;
  }
  std::printf("wrote %zu views and overview.png to %s\n", directions.size(), options.out_dir.c_str());
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) {
  reconar::Options options;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--help" || arg == "-h") {
      reconar::Usage("renders MESH from a ring of viewpoints into OUT_DIR");
      return 0;
    } else if (arg == "--views" && has_value) {
      options.views = std::atoi(argv[++i]);
    } else if (arg == "--size" && has_value) {
      if (std::sscanf(argv[++i], "%dx%d", &options.width, &options.height) != 2) return reconar::Usage("bad --size");
    } else if (arg == "--up" && has_value) {
      if (!reconar::ParseUp(argv[++i], &options.up)) return reconar::Usage("bad --up");
    } else if (arg == "--point-size" && has_value) {
      options.point_size = static_cast<float>(std::atof(argv[++i]));
    } else if (arg == "--elevation" && has_value) {
      options.elevation_deg = std::atof(argv[++i]);
    } else if (arg.rfind("--", 0) == 0) {
      return reconar::Usage(("unknown or incomplete option " + arg).c_str());
    } else {
      positional.push_back(arg);
    }
  }
  if (positional.size() != 2) return reconar::Usage("expected MESH and OUT_DIR");
  if (options.views < 1 || options.views > 64 || options.width < 16 || options.height < 16 ||
      options.width > 4096 || options.height > 4096 || !(options.point_size > 0.0f)) {
    return reconar::Usage("--views must be 1..64, --size 16..4096 per side, --point-size positive");
  }
  options.mesh_path = positional[0];
  options.out_dir = positional[1];
  return reconar::Run(options);
}
