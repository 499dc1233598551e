#include "core/texture/face_views.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/base/image_sampling.h"
#include "core/io/gray.h"
#include "core/mvs/undistort.h"

namespace reconar {
namespace {

// Mean over a (2 radius + 1)^2 box, edges clamped; any channel count.
Image<uint8_t> BoxSmooth(const Image<uint8_t>& image, int radius) {
  const int width = image.width(), height = image.height(), channels = image.channels();
  Image<uint8_t> rows(width, height, channels), out(width, height, channels);
  const float norm = 1.0f / static_cast<float>(2 * radius + 1);
  for (int y = 0; y < height; ++y) {
    const uint8_t* in = image.row(y);
    uint8_t* o = rows.row(y);
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        int sum = 0;
        for (int k = -radius; k <= radius; ++k) sum += in[channels * std::clamp(x + k, 0, width - 1) + c];
        o[channels * x + c] = static_cast<uint8_t>(std::lround(static_cast<float>(sum) * norm));
      }
    }
  }
  for (int y = 0; y < height; ++y) {
    uint8_t* o = out.row(y);
    for (int x = 0; x < width * channels; ++x) {
      int sum = 0;
      for (int k = -radius; k <= radius; ++k) sum += rows.row(std::clamp(y + k, 0, height - 1))[x];
      o[x] = static_cast<uint8_t>(std::lround(static_cast<float>(sum) * norm));
    }
  }
  return out;
}

// Sobel gradient magnitude of the gray image, then its mean over 5 x 5.
void SmoothedGradient(const Image<uint8_t>& gray, std::vector<float>* gradient) {
  const int width = gray.width(), height = gray.height();
  std::vector<float> magnitude(static_cast<size_t>(width) * height);
  auto at = [&](int x, int y) {
    return static_cast<float>(gray.row(std::clamp(y, 0, height - 1))[std::clamp(x, 0, width - 1)]);
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float gx = (at(x + 1, y - 1) + 2 * at(x + 1, y) + at(x + 1, y + 1)) -
                       (at(x - 1, y - 1) + 2 * at(x - 1, y) + at(x - 1, y + 1));
      const float gy = (at(x - 1, y + 1) + 2 * at(x, y + 1) + at(x + 1, y + 1)) -
                       (at(x - 1, y - 1) + 2 * at(x, y - 1) + at(x + 1, y - 1));
      magnitude[static_cast<size_t>(y) * width + x] = 0.125f * std::sqrt(gx * gx + gy * gy);
    }
  }
  constexpr int kRadius = 2;
  std::vector<float> rows(magnitude.size());
  gradient->assign(magnitude.size(), 0.0f);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float sum = 0.0f;
      for (int k = -kRadius; k <= kRadius; ++k) sum += magnitude[static_cast<size_t>(y) * width + std::clamp(x + k, 0, width - 1)];
      rows[static_cast<size_t>(y) * width + x] = sum;
    }
  }
  const float norm = 1.0f / static_cast<float>((2 * kRadius + 1) * (2 * kRadius + 1));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float sum = 0.0f;
      for (int k = -kRadius; k <= kRadius; ++k) sum += rows[static_cast<size_t>(std::clamp(y + k, 0, height - 1)) * width + x];
      (*gradient)[static_cast<size_t>(y) * width + x] = sum * norm;
    }
  }
}

// Draws a triangle (reduced-image coordinates, camera depths) into the depth buffer, keeping the
// nearest; depth is 1 / (1/z interpolated), exact for a plane.
void DrawDepth(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, double za, double zb,
               double zc, int width, int height, float* depth) {
  const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
  if (!(std::abs(area) > 1e-12)) return;
  const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))));
  const int x1 = std::min(width - 1, static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
  const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))));
  const int y1 = std::min(height - 1, static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
  const double inverse_area = 1.0 / area;
  const double ia = 1.0 / za, ib = 1.0 / zb, ic = 1.0 / zc;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double wa = ((b.x() - x) * (c.y() - y) - (b.y() - y) * (c.x() - x)) * inverse_area;
      const double wb = ((c.x() - x) * (a.y() - y) - (c.y() - y) * (a.x() - x)) * inverse_area;
      const double wc = 1.0 - wa - wb;
      if (wa < 0.0 || wb < 0.0 || wc < 0.0) continue;
      const float z = static_cast<float>(1.0 / (wa * ia + wb * ib + wc * ic));
      float& stored = depth[static_cast<size_t>(y) * width + x];
      if (z < stored) stored = z;
    }
  }
}

}  // namespace

FaceGeometry::FaceGeometry(const Mesh& mesh) {
  centroids.resize(mesh.triangles.size());
  normals.resize(mesh.triangles.size());
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                          c = mesh.positions[t[2]].cast<double>();
    centroids[f] = (a + b + c) / 3.0;
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double length = n.norm();
    normals[f] = length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
  }
}

PhotoProjector::PhotoProjector(const TexturePhoto& photo)
    : photo_(photo),
      center_(CameraCenterInWorld(photo.cam_from_world)),
      max_radius2_(photo.camera.MaxValidRadiusSquared(photo.camera.width, photo.camera.height)) {}

bool PhotoProjector::Project(const Eigen::Vector3d& world_point, Eigen::Vector2d* pixel, double* depth) const {
  const Eigen::Vector3d cam = photo_.cam_from_world * world_point;
  if (!(cam.z() > 0.0)) return false;
  const Eigen::Vector2d normalised = cam.head<2>() / cam.z();
  if (!(normalised.squaredNorm() <= max_radius2_)) return false;
  *pixel = photo_.camera.PixelFromNormalised(normalised);
  *depth = cam.z();
  return std::isfinite(pixel->x()) && std::isfinite(pixel->y());
}

int ReducedLevel(int width, int height, int raster_long_side) {
  int level = 0;
  while ((std::max(width, height) >> level) > raster_long_side && level < 8) ++level;
  return level;
}

void FindFaceCandidates(const Mesh& mesh, const FaceGeometry& geometry, int photo_index,
                        const PhotoProjector& projector, const Image<uint8_t>& rgb, const TextureOptions& options,
                        CandidateScratch* scratch, std::vector<FaceCandidate>* candidates, ReducedPhoto* reduced) {
  const int level = ReducedLevel(rgb.width(), rgb.height(), options.raster_long_side);
  Image<uint8_t> small = AreaAverageDown(rgb, level);
  reduced->level = level;
  const Image<uint8_t> smoothed = BoxSmooth(small, 1);
  SmoothedGradient(ToGray8(small), &scratch->gradient);
  const int width = small.width(), height = small.height();
  reduced->rgb = std::move(small);

  const size_t num_vertices = mesh.positions.size();
  scratch->pixels.resize(num_vertices);
  scratch->depths.resize(num_vertices);
  scratch->projected.assign(num_vertices, 0);
  for (size_t v = 0; v < num_vertices; ++v) {
    Eigen::Vector2d pixel;
    double depth;
    if (projector.Project(mesh.positions[v].cast<double>(), &pixel, &depth)) {
      scratch->pixels[v] = reduced->FromFull(pixel);
      scratch->depths[v] = depth;
      scratch->projected[v] = 1;
    }
  }
  scratch->depth.assign(static_cast<size_t>(width) * height, std::numeric_limits<float>::infinity());
  for (const auto& t : mesh.triangles) {
    if (!scratch->projected[t[0]] || !scratch->projected[t[1]] || !scratch->projected[t[2]]) continue;
    DrawDepth(scratch->pixels[t[0]], scratch->pixels[t[1]], scratch->pixels[t[2]], scratch->depths[t[0]],
              scratch->depths[t[1]], scratch->depths[t[2]], width, height, scratch->depth.data());
  }

  const double full_scale = static_cast<double>(1 << level);
  const Eigen::Vector3d center = projector.center();
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    if (!scratch->projected[t[0]] || !scratch->projected[t[1]] || !scratch->projected[t[2]]) continue;
    const Eigen::Vector3d to_camera = center - geometry.centroids[f];
    if (!(geometry.normals[f].dot(to_camera) > options.min_view_cosine * to_camera.norm())) continue;
    const Eigen::Vector3d& centroid = geometry.centroids[f];
    const std::array<Eigen::Vector3d, 4> samples = {
        centroid, 0.5 * (centroid + mesh.positions[t[0]].cast<double>()),
        0.5 * (centroid + mesh.positions[t[1]].cast<double>()), 0.5 * (centroid + mesh.positions[t[2]].cast<double>())};
    bool seen = true;
    float gradient = 0.0f;
    std::array<float, 3> colour = {0.0f, 0.0f, 0.0f};
    for (const Eigen::Vector3d& sample : samples) {
      Eigen::Vector2d pixel;
      double depth;
      if (!projector.Project(sample, &pixel, &depth)) {
        seen = false;
        break;
      }
      const Eigen::Vector2d at = reduced->FromFull(pixel);
      const int x = static_cast<int>(std::lround(at.x())), y = static_cast<int>(std::lround(at.y()));
      float rgb_sample[3];
      if (x < 0 || y < 0 || x >= width || y >= height ||
          !(depth <= scratch->depth[static_cast<size_t>(y) * width + x] * (1.0 + options.depth_tolerance)) ||
          !SampleBilinear(smoothed, at.x(), at.y(), rgb_sample)) {
        seen = false;
        break;
      }
      gradient += scratch->gradient[static_cast<size_t>(y) * width + x];
      for (int c = 0; c < 3; ++c) colour[static_cast<size_t>(c)] += rgb_sample[c];
    }
    if (!seen) continue;
    // Projected area in full-resolution pixels.
    const Eigen::Vector2d a = scratch->pixels[t[0]], b = scratch->pixels[t[1]], c = scratch->pixels[t[2]];
    const double area = 0.5 * std::abs((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x())) *
                        full_scale * full_scale;
    FaceCandidate candidate;
    candidate.face = static_cast<int>(f);
    candidate.photo = photo_index;
    candidate.area = static_cast<float>(area);
    candidate.sharpness = gradient / static_cast<float>(samples.size());
    candidate.quality = candidate.area;
    for (int k = 0; k < 3; ++k) candidate.colour[static_cast<size_t>(k)] = colour[static_cast<size_t>(k)] / samples.size();
    candidates->push_back(candidate);
  }
}

}  // namespace reconar
