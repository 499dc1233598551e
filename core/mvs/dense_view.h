#pragma once
// DenseView: one registered image as the dense stage sees it, after undistortion (core/mvs/undistort.h):
// a pinhole camera with no distortion, at the chosen resolution level.
// Conventions (DESIGN.md): the centre of the top-left pixel is (0, 0), x right, y down; the pose is
// cam_from_world (X_cam = R X_world + t), the camera looks down +z.
#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "core/base/image.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

struct DenseView {
  std::string name;             // the SfmImage name
  int image_id = -1;            // index into Reconstruction::images
  int level = 0;                // 0 full resolution, 1 half, 2 quarter
  Image<uint8_t> rgb;           // width x height x 3, undistorted
  Image<uint8_t> gray;          // width x height x 1, same pixels as rgb
  double fx = 0.0, fy = 0.0;    // pixels, at this level
  double cx = 0.0, cy = 0.0;
  Rigid3 cam_from_world;

  int width() const { return gray.width(); }
  int height() const { return gray.height(); }
  Eigen::Vector3d Center() const { return CameraCenterInWorld(cam_from_world); }
  // The viewing ray direction of the optical axis in world coordinates.
  Eigen::Vector3d OpticalAxis() const { return cam_from_world.rotation.row(2).transpose(); }
  Eigen::Vector2d Project(const Eigen::Vector3d& world_point) const {
    const Eigen::Vector3d cam = cam_from_world * world_point;
    return Eigen::Vector2d(fx * cam.x() / cam.z() + cx, fy * cam.y() / cam.z() + cy);
  }
  double Depth(const Eigen::Vector3d& world_point) const { return (cam_from_world * world_point).z(); }
  // 3x4 projection matrix K [R | t].
  Eigen::Matrix<double, 3, 4> ProjectionMatrix() const {
    Eigen::Matrix3d k;
    k << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
    Eigen::Matrix<double, 3, 4> rt;
    rt << cam_from_world.rotation, cam_from_world.translation;
    return k * rt;
  }
};

}  // namespace reconar
