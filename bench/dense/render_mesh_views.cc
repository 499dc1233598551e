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
#include "render/preview.h"

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

int Run(const Options& options) {
  Result<Mesh> mesh = EndsWith(options.mesh_path, ".glb") ? ReadGlb(options.mesh_path) : ReadPly(options.mesh_path);
  if (!mesh.ok()) return Usage(mesh.status().ToString().c_str());
  std::printf("%s: %zu vertices, %zu triangles\n", options.mesh_path.c_str(), mesh->positions.size(),
              mesh->triangles.size());
  PreviewOptions preview;
  preview.width = options.width;
  preview.height = options.height;
  preview.up = options.up;
  preview.point_size_px = options.point_size;
  preview.directions = PreviewOptions::Ring(options.views, options.elevation_deg);
  auto views = RenderPreviewViews(*mesh, preview);
  if (!views.ok()) return Usage(views.status().ToString().c_str());
  if (!CreateDirectories(options.out_dir).ok()) return Usage(("cannot create " + options.out_dir).c_str());
  for (size_t i = 0; i < views->size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "view_%02zu.png", i);
    if (Status s = WritePng(options.out_dir + "/" + name, (*views)[i].view(), 3); !s.ok()) {
      std::fprintf(stderr, "render_mesh_views: %s\n", s.ToString().c_str());
      return 1;
    }
  }
  if (Status s = WritePng(options.out_dir + "/overview.png", TileImages(*views, 3).view(), 3); !s.ok()) {
    std::fprintf(stderr, "render_mesh_views: %s\n", s.ToString().c_str());
    return 1;
  }
  std::printf("wrote %zu views and overview.png to %s\n", views->size(), options.out_dir.c_str());
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
