#pragma once
// PmvsView: what the patch stages read of a DenseView, precomputed once: the projection matrix,
// the camera centre, the inverse intrinsics for back-projection and a borrowed grey image.
// The DenseView must outlive the PmvsView.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/mvs/dense_view.h"

namespace reconar {

struct PmvsView {
  const DenseView* source = nullptr;
  int width = 0, height = 0;
  // Grey levels as floats, width x height, row stride = width: the bilinear sampling of the
  // patch grids, the hot loop, then needs no integer conversion.
  std::vector<float> gray;
  Eigen::Matrix<double, 3, 4> projection;  // K [R | t]
  Eigen::Matrix3d world_from_cam_rotation;  // R^T
  Eigen::Vector3d center;
  Eigen::Vector3d optical_axis;  // world direction of +z_cam
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;

  explicit PmvsView(const DenseView& view);

  // Homogeneous image coordinates K [R | t] X; the third is the depth.
  Eigen::Vector3d ProjectHomogeneous(const Eigen::Vector3d& x) const {
    return projection.leftCols<3>() * x + projection.col(3);
  }
  Eigen::Vector2d Project(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d h = ProjectHomogeneous(x);
    return h.head<2>() / h.z();
  }
  double Depth(const Eigen::Vector3d& x) const { return projection.row(2).head<3>().dot(x) + projection(2, 3); }
  // World direction (not normalised) of the ray through pixel (u, v), with unit depth.
  Eigen::Vector3d RayDirection(double u, double v) const {
    return world_from_cam_rotation * Eigen::Vector3d((u - cx) / fx, (v - cy) / fy, 1.0);
  }
  // World size of one pixel at the given depth (mean over both axes).
  double PixelFootprint(double depth) const { return depth * 2.0 / (fx + fy); }
  bool Inside(const Eigen::Vector2d& p, double margin) const {
    return p.x() >= margin && p.y() >= margin && p.x() <= width - 1 - margin && p.y() <= height - 1 - margin;
  }
};

// For every view, the other views whose optical axes lie within max_angle of its own, the
// candidates for epipolar matching (PMVS uses 60 degrees).
std::vector<std::vector<int>> NeighbourViews(const std::vector<PmvsView>& views, double max_angle);

}  // namespace reconar
