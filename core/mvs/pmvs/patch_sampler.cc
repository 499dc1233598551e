#include "core/mvs/pmvs/patch_sampler.h"

#include <algorithm>
#include <cmath>

namespace reconar {

PatchSampler::PatchSampler(const std::vector<PmvsView>& views, int patch_size, double min_texture_std)
    : views_(views),
      kernel_(ActiveNccKernel()),
      patch_size_(patch_size),
      count_(patch_size * patch_size),
      min_texture_std_(static_cast<float>(min_texture_std)) {}

bool PatchSampler::SetPatch(const Eigen::Vector3d& center, const Eigen::Vector3d& normal, int reference) {
  reference_ = reference;
  const PmvsView& view = views_[reference];
  const Eigen::Vector3d h = view.ProjectHomogeneous(center);
  if (!(h.z() > 0.0)) return false;
  const double u = h.x() / h.z(), v = h.y() / h.z();
  // Intersect the rays through (u + 1, v) and (u, v + 1) with the plane.
  const Eigen::Vector3d to_center = center - view.center;
  const double plane_distance = to_center.dot(normal);
  const Eigen::Vector3d ray_x = view.RayDirection(u + 1.0, v);
  const Eigen::Vector3d ray_y = view.RayDirection(u, v + 1.0);
  const double dx = ray_x.dot(normal), dy = ray_y.dot(normal);
  // Grazing planes (the caller keeps the viewing angle below iota < 90 degrees) are refused.
  if (std::abs(dx) < 1e-12 || std::abs(dy) < 1e-12) return false;
  axis_x_ = view.center + ray_x * (plane_distance / dx) - center;
  axis_y_ = view.center + ray_y * (plane_distance / dy) - center;
  const double half = 0.5 * (patch_size_ - 1);
  origin_ = center - half * (axis_x_ + axis_y_);
  if (!Sample(view, reference_samples_.data())) return false;
  return NormalizeNccReference(reference_samples_.data(), count_, PaddedNccCount(count_), min_texture_std_);
}

bool PatchSampler::Sample(const PmvsView& view, float* out) const {
  const Eigen::Vector3d h0 = view.ProjectHomogeneous(origin_);
  const Eigen::Vector3d hx = view.projection.leftCols<3>() * axis_x_;
  const Eigen::Vector3d hy = view.projection.leftCols<3>() * axis_y_;
  const int width = view.width, height = view.height;
  // The grid is a convex quad in front of the camera when its corners are (depth is affine over
  // it), and its projection lies in the convex hull of the projected corners, so checking the
  // corners (with slack for the float rounding below) keeps every sample inside.
  const double last = patch_size_ - 1;
  const double max_u = width - 1 - 1e-2, max_v = height - 1 - 1e-2;
  for (int corner = 0; corner < 4; ++corner) {
    const Eigen::Vector3d h = h0 + ((corner & 1) ? last : 0.0) * hx + ((corner & 2) ? last : 0.0) * hy;
    if (!(h.z() > 0.0)) return false;
    const double u = h.x() / h.z(), v = h.y() / h.z();
    if (!(u >= 0.0 && v >= 0.0 && u <= max_u && v <= max_v)) return false;
  }
  // Projections in float, written so that the compiler vectorises them.
  alignas(32) std::array<float, kMaxSamples> us, vs;
  const float h0x = static_cast<float>(h0.x()), h0y = static_cast<float>(h0.y()), h0z = static_cast<float>(h0.z());
  const float hxx = static_cast<float>(hx.x()), hxy = static_cast<float>(hx.y()), hxz = static_cast<float>(hx.z());
  const float hyx = static_cast<float>(hy.x()), hyy = static_cast<float>(hy.y()), hyz = static_cast<float>(hy.z());
  for (int j = 0, k = 0; j < patch_size_; ++j) {
    const float rx = h0x + j * hyx, ry = h0y + j * hyy, rz = h0z + j * hyz;
    for (int i = 0; i < patch_size_; ++i, ++k) {
      const float inv_z = 1.0f / (rz + i * hxz);
      us[k] = (rx + i * hxx) * inv_z;
      vs[k] = (ry + i * hxy) * inv_z;
    }
  }
  const float* pixels = view.gray.data();
  for (int k = 0; k < count_; ++k) {
    const float u = us[k], v = vs[k];
    const int x0 = std::clamp(static_cast<int>(u), 0, width - 2);
    const int y0 = std::clamp(static_cast<int>(v), 0, height - 2);
    const float ax = u - x0, ay = v - y0;
    const float* p = pixels + static_cast<ptrdiff_t>(y0) * width + x0;
    const float top = p[0] + ax * (p[1] - p[0]);
    const float bottom = p[width] + ax * (p[width + 1] - p[width]);
    out[k] = top + ay * (bottom - top);
  }
  return true;
}

float PatchSampler::Ncc(int image) {
  if (!Sample(views_[image], samples_.data())) return -1.0f;
  return reconar::Ncc(kernel_, reference_samples_.data(), samples_.data(), count_);
}

Eigen::Vector3f PatchSampler::MeanReferenceColor() const {
  const PmvsView& view = views_[reference_];
  const Image<uint8_t>& rgb = view.source->rgb;
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  int n = 0;
  for (int j = 0; j < patch_size_; ++j) {
    for (int i = 0; i < patch_size_; ++i) {
      const Eigen::Vector2d p = view.Project(origin_ + i * axis_x_ + j * axis_y_);
      const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
      if (x < 0 || y < 0 || x >= rgb.width() || y >= rgb.height()) continue;
      const uint8_t* c = rgb.row(y) + 3 * x;
      sum += Eigen::Vector3f(c[0], c[1], c[2]);
      ++n;
    }
  }
  return n > 0 ? Eigen::Vector3f(sum / static_cast<float>(n)) : sum;
}

}  // namespace reconar
