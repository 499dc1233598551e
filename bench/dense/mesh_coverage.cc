// Coverage of the photos by a project's mesh (issue 16): for each registered image, the fraction of
// its pixels on which the mesh projects (through the image's pose and radial camera, every
// triangle in front of the camera; occlusion does not matter for coverage). Prints one line per
// image and the median and mean over the images, so that two dense methods' meshes of the same
// project can be compared on what the user sees of them.
//
// Usage: mesh_coverage PROJECT_DIR [MESH.ply]   (default PROJECT_DIR/mesh/mesh.ply)
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "core/mesh/mesh_io.h"
#include "core/sfm/model_io.h"

namespace reconar {
namespace {

double Edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double x, double y) {
  return (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
}

// Marks the pixels whose centres lie inside the triangle (either winding).
void FillTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, int width, int height,
                  std::vector<uint8_t>* mask) {
  const double area = Edge(a, b, c.x(), c.y());
  if (area == 0.0 || !std::isfinite(area)) return;
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
  const int x1 = std::min(width - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
  const int y1 = std::min(height - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
  const double sign = area > 0.0 ? 1.0 : -1.0;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double px = x, py = y;
      if (sign * Edge(a, b, px, py) >= 0.0 && sign * Edge(b, c, px, py) >= 0.0 && sign * Edge(c, a, px, py) >= 0.0) {
        (*mask)[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] = 1;
      }
    }
  }
}

int Run(const std::string& project, const std::string& mesh_path) {
  auto model = ReadColmapTextModel(project + "/sparse");
  if (!model.ok()) {
    std::fprintf(stderr, "mesh_coverage: %s\n", model.status().ToString().c_str());
    return 1;
  }
  auto mesh = ReadPly(mesh_path);
  if (!mesh.ok()) {
    std::fprintf(stderr, "mesh_coverage: %s\n", mesh.status().ToString().c_str());
    return 1;
  }
  if (mesh->triangles.empty()) {
    std::fprintf(stderr, "mesh_coverage: %s: no triangles\n", mesh_path.c_str());
    return 1;
  }
  std::vector<double> fractions;
  std::vector<Eigen::Vector2d> pixels(mesh->positions.size());
  std::vector<uint8_t> in_front(mesh->positions.size());
  for (const SfmImage& image : model->images) {
    if (!image.registered) continue;
    const SfmCamera& camera = model->cameras[static_cast<size_t>(image.camera_id)];
    for (size_t v = 0; v < mesh->positions.size(); ++v) {
      const Eigen::Vector3d in_camera = image.cam_from_world * mesh->positions[v].cast<double>();
      in_front[v] = in_camera.z() > 0.0 ? 1 : 0;
      if (in_front[v]) pixels[v] = camera.Project(in_camera);
    }
    std::vector<uint8_t> mask(static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height), 0);
    for (const auto& [i, j, k] : mesh->triangles) {
      if (!in_front[i] || !in_front[j] || !in_front[k]) continue;
      FillTriangle(pixels[i], pixels[j], pixels[k], camera.width, camera.height, &mask);
    }
    size_t covered = 0;
    for (uint8_t m : mask) covered += m;
    const double fraction = static_cast<double>(covered) / static_cast<double>(mask.size());
    fractions.push_back(fraction);
    std::printf("%s %.4f\n", image.name.c_str(), fraction);
  }
  if (fractions.empty()) {
    std::fprintf(stderr, "mesh_coverage: %s/sparse: no registered image\n", project.c_str());
    return 1;
  }
  double mean = 0.0;
  for (double f : fractions) mean += f;
  mean /= static_cast<double>(fractions.size());
  std::vector<double> sorted = fractions;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  std::printf("COVERAGE %s: %zu images, median %.4f, mean %.4f\n", mesh_path.c_str(), fractions.size(),
              sorted[sorted.size() / 2], mean);
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: mesh_coverage PROJECT_DIR [MESH.ply]   (default PROJECT_DIR/mesh/mesh.ply)\n");
    return argc < 2 || argc > 3 ? 2 : 0;
  }
  const std::string project = argv[1];
  return reconar::Run(project, argc == 3 ? argv[2] : project + "/mesh/mesh.ply");
}
