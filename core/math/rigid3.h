#pragma once
// Rigid3: a rotation and a translation joining two named frames, X_a = R X_b + t for a_from_b.
// Used where poses cross module boundaries as plain data (tracker → tools → render).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/math/rotation.h"

namespace reconar {

struct Rigid3 {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  static Rigid3 Identity() { return Rigid3(); }

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const { return rotation * point + translation; }
  // (a_from_b * b_from_c) = a_from_c.
  Rigid3 operator*(const Rigid3& b_from_c) const {
    return Rigid3{rotation * b_from_c.rotation, rotation * b_from_c.translation + translation};
  }
  Rigid3 Inverse() const {
    const Eigen::Matrix3d rt = rotation.transpose();
    return Rigid3{rt, -(rt * translation)};
  }
  Eigen::Matrix4d Matrix() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = rotation;
    m.topRightCorner<3, 1>() = translation;
    return m;
  }
};

// The projection centre of a camera in world coordinates, -R^T t (world_from_cam's translation).
inline Eigen::Vector3d CameraCenterInWorld(const Rigid3& cam_from_world) {
  return -cam_from_world.rotation.transpose() * cam_from_world.translation;
}

// cam_from_world of a camera at `center` looking at `target` (+z), its image y axis pointing down
// along -up (x = z cross up; any x orthogonal to z when up is parallel to the view).
inline Rigid3 CamFromWorldLookingAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                                    const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - center).normalized();
  Eigen::Vector3d x = z.cross(up);
  x = x.norm() < 1e-9 ? Eigen::Vector3d(z.unitOrthogonal()) : Eigen::Vector3d(x.normalized());
  const Eigen::Vector3d y = z.cross(x);
  Rigid3 cam_from_world;
  cam_from_world.rotation.row(0) = x.transpose();
  cam_from_world.rotation.row(1) = y.transpose();
  cam_from_world.rotation.row(2) = z.transpose();
  cam_from_world.translation = -(cam_from_world.rotation * center);
  return cam_from_world;
}

}  // namespace reconar
