#pragma once
// Rigid3: a rotation and a translation joining two named frames, X_a = R X_b + t for a_from_b.
// Used where poses cross module boundaries as plain data (tracker → tools → render).
#include <Eigen/Core>
#include <Eigen/Geometry>

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

// Angle of the rotation between a and b, in radians; accurate for small angles too.
inline double RotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(Eigen::Quaterniond(a.transpose() * b).normalized()).angle();
}

}  // namespace reconar
