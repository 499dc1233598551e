#include "tests/support/mesh_raster.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace reconar::testing {

TriangleRaster RasterizeTriangles(const Mesh& mesh, const PinholeView& view, double near_m) {
  TriangleRaster raster;
  raster.triangle = Image<int32_t>(view.width, view.height, 1);
  raster.depth = Image<float>(view.width, view.height, 1);
  std::fill(raster.triangle.data(), raster.triangle.data() + view.width * view.height, -1);
  std::fill(raster.depth.data(), raster.depth.data() + view.width * view.height, 0.0f);
  // The z-buffer holds 1/z, which is affine in the image (perspective-correct interpolation).
  Image<double> inverse_depth(view.width, view.height, 1);
  std::fill(inverse_depth.data(), inverse_depth.data() + view.width * view.height, 0.0);

  std::vector<Eigen::Vector3d> projected(mesh.positions.size());  // pixel x, pixel y, 1 / z
  std::vector<bool> usable(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Eigen::Vector3d cam = view.cam_from_world * mesh.positions[i].cast<double>();
    usable[i] = cam.z() >= near_m;
    projected[i] =
        Eigen::Vector3d(view.fx * cam.x() / cam.z() + view.cx, view.fy * cam.y() / cam.z() + view.cy, 1.0 / cam.z());
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& corners = mesh.triangles[t];
    if (!usable[corners[0]] || !usable[corners[1]] || !usable[corners[2]]) continue;
    const Eigen::Vector3d& a = projected[corners[0]];
    const Eigen::Vector3d& b = projected[corners[1]];
    const Eigen::Vector3d& c = projected[corners[2]];
    // Twice the signed area, and each corner's weight at p as the area opposite it.
    const auto edge = [](const Eigen::Vector3d& from, const Eigen::Vector3d& to, double px, double py) {
      return (to.x() - from.x()) * (py - from.y()) - (to.y() - from.y()) * (px - from.x());
    };
    const double area = edge(a, b, c.x(), c.y());
    if (std::abs(area) < 1e-12) continue;
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))));
    const int x1 = std::min(view.width - 1, static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))));
    const int y1 = std::min(view.height - 1, static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double wa = edge(b, c, x, y) / area, wb = edge(c, a, x, y) / area, wc = edge(a, b, x, y) / area;
        // A pixel on an edge two triangles share belongs to both (the z-buffer picks one): the
        // weights there are 0 up to rounding, which differs between the two triangles' sums and
        // with fused multiply-adds (aarch64), and a strict test left a crack of background.
        constexpr double kOnEdge = -1e-9;
        if (wa < kOnEdge || wb < kOnEdge || wc < kOnEdge) continue;
        const double inverse_z = wa * a.z() + wb * b.z() + wc * c.z();
        double& nearest = inverse_depth.row(y)[x];
        if (inverse_z <= nearest) continue;
        nearest = inverse_z;
        raster.triangle.row(y)[x] = static_cast<int32_t>(t);
        raster.depth.row(y)[x] = static_cast<float>(1.0 / inverse_z);
      }
    }
  }
  return raster;
}

}  // namespace reconar::testing
