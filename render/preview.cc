#include "render/preview.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/io/image_write.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/rigid3.h"
#include "platform/egl/egl_context.h"
#include "render/mesh_drawable.h"
#include "render/overlay_renderer.h"

namespace reconar {

std::vector<std::pair<double, double>> PreviewOptions::Ring(int views, double elevation_deg) {
  std::vector<std::pair<double, double>> directions;
  for (int i = 0; i < views; ++i) directions.emplace_back(2.0 * M_PI * i / views, elevation_deg * M_PI / 180.0);
  directions.emplace_back(0.0, 70.0 * M_PI / 180.0);
  return directions;
}

Status PreviewOptions::Check() const {
  if (width < 16 || height < 16 || width > 4096 || height > 4096)
    return InvalidArgument("preview: views must be 16..4096 pixels a side");
  if (directions.empty()) return InvalidArgument("preview: no view direction");
  if (!(up.norm() > 0.0) || !up.allFinite()) return InvalidArgument("preview: the up direction must be non-zero");
  if (!(point_size_px > 0.0f)) return InvalidArgument("preview: the point size must be positive");
  return Status::Ok();
}

Result<std::vector<Image<uint8_t>>> RenderPreviewViews(const Mesh& mesh, const PreviewOptions& options,
                                                       const std::vector<TexturePage>* texture) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (mesh.positions.empty()) return InvalidArgument("preview: the mesh has no vertices");
  Eigen::Vector3d lo, hi;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<float> values;
    values.reserve(mesh.positions.size());
    for (const Eigen::Vector3f& p : mesh.positions) values.push_back(p[axis]);
    const size_t n = values.size();
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n / 100), values.end());
    lo[axis] = values[n / 100];
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n - 1 - n / 100), values.end());
    hi[axis] = values[n - 1 - n / 100];
  }
  const Eigen::Vector3d target = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-9);

  EglContextOptions context_options;
  context_options.kind = EglContextKind::kSurfaceless;
  RECONAR_ASSIGN_OR_RETURN(auto context, EglContext::Create(context_options));
  OverlayRendererOptions renderer_options;
  renderer_options.width = options.width;
  renderer_options.height = options.height;
  renderer_options.samples = options.samples;
  renderer_options.clear_color = {0.12f, 0.12f, 0.14f};
  // f = width: a 53-degree horizontal field.
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
  RECONAR_ASSIGN_OR_RETURN(auto renderer, OverlayRenderer::Create(renderer_options));
  RECONAR_ASSIGN_OR_RETURN(const MeshDrawable drawable, MeshDrawable::Upload(mesh, texture));
  MeshStyle style;
  style.point_size_px = options.point_size_px;
  style.shading = texture == nullptr;

  const Eigen::Vector3d up = options.up.normalized();
  const Eigen::Vector3d side = up.unitOrthogonal();
  const Eigen::Vector3d front = up.cross(side);
  std::vector<Image<uint8_t>> views;
  for (const auto& [azimuth, elevation] : options.directions) {
    const Eigen::Vector3d direction =
        std::cos(elevation) * (std::cos(azimuth) * front + std::sin(azimuth) * side) + std::sin(elevation) * up;
    const Rigid3 cam_from_world = CamFromWorldLookingAt(target + distance * direction, target, up);
    Image<uint8_t> rgb;
    RECONAR_RETURN_IF_ERROR(renderer->BeginFrame());
    RECONAR_RETURN_IF_ERROR(renderer->DrawMesh(drawable, intrinsics, cam_from_world.Matrix(), style));
    RECONAR_RETURN_IF_ERROR(renderer->ReadRgb(&rgb));
    views.push_back(std::move(rgb));
  }
  return views;
}

Image<uint8_t> TileImages(const std::vector<Image<uint8_t>>& views, int columns) {
  if (views.empty() || columns < 1) return Image<uint8_t>();
  const int width = views[0].width(), height = views[0].height();
  const int rows = (static_cast<int>(views.size()) + columns - 1) / columns;
  Image<uint8_t> tiled(std::min(columns, static_cast<int>(views.size())) * width, rows * height, 3);
  std::memset(tiled.row(0), 0, static_cast<size_t>(tiled.width()) * 3 * static_cast<size_t>(tiled.height()));
  for (size_t i = 0; i < views.size(); ++i) {
    const int x0 = static_cast<int>(i % static_cast<size_t>(columns)) * width;
    const int y0 = static_cast<int>(i / static_cast<size_t>(columns)) * height;
    for (int y = 0; y < height; ++y)
      std::memcpy(tiled.row(y0 + y) + 3 * x0, views[i].row(y), 3 * static_cast<size_t>(width));
  }
  return tiled;
}

Status WritePreview(const Mesh& mesh, const std::vector<TexturePage>* texture, const Eigen::Vector3d& up,
                    const std::string& png_path) {
  PreviewOptions preview;
  preview.width = 480;
  preview.height = 360;
  preview.up = up;
  preview.directions = PreviewOptions::Ring(5, 20.0);
  RECONAR_ASSIGN_OR_RETURN(const std::vector<Image<uint8_t>> views, RenderPreviewViews(mesh, preview, texture));
  return WritePng(png_path, TileImages(views, 3).view(), 3);
}

}  // namespace reconar
