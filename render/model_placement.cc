#include "render/model_placement.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <string>

namespace reconar {

Eigen::Matrix4d ModelPlacement::TagFromModel() const {
  Eigen::Matrix4d tag_from_model = Eigen::Matrix4d::Identity();
  tag_from_model.topLeftCorner<3, 3>() = scale * rotation;
  tag_from_model.topRightCorner<3, 1>() = offset;
  return tag_from_model;
}

Result<ModelPlacement> ModelPlacement::StandingOnTag(const Mesh& mesh, double height_m,
                                                     const Eigen::Vector3d& model_up) {
  if (mesh.positions.empty()) return InvalidArgument("ModelPlacement::StandingOnTag: the mesh has no vertices");
  if (!(height_m > 0.0 && std::isfinite(height_m))) {
    return InvalidArgument("ModelPlacement::StandingOnTag: height must be positive, got " + std::to_string(height_m));
  }
  if (!(model_up.norm() > 0.0)) return InvalidArgument("ModelPlacement::StandingOnTag: model_up is zero");
  ModelPlacement placement;
  placement.rotation = Eigen::Quaterniond::FromTwoVectors(model_up.normalized(), Eigen::Vector3d::UnitZ())
                           .normalized()
                           .toRotationMatrix();
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const Eigen::Vector3f& position : mesh.positions) {
    const Eigen::Vector3d rotated = placement.rotation * position.cast<double>();
    low = low.cwiseMin(rotated);
    high = high.cwiseMax(rotated);
  }
  const double extent = high.z() - low.z();
  // Rounding of the rotation leaves ~1e-16 of extent on a flat model: compare with its size.
  if (!(extent > 1e-9 * (high - low).norm() && std::isfinite(extent))) {
    return InvalidArgument("ModelPlacement::StandingOnTag: the mesh has no extent along model_up");
  }
  placement.scale = height_m / extent;
  const Eigen::Vector3d base(0.5 * (low.x() + high.x()), 0.5 * (low.y() + high.y()), low.z());
  placement.offset = -placement.scale * base;
  return placement;
}

ModelPlacement ModelPlacement::Scaled(double scale, const Eigen::Vector3d& model_up) {
  ModelPlacement placement;
  placement.scale = scale;
  placement.rotation = Eigen::Quaterniond::FromTwoVectors(model_up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return placement;
}

ModelPlacement ModelPlacement::Turned(double degrees, const Eigen::Vector3d& shift) const {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(degrees * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  ModelPlacement turned = *this;
  turned.rotation = turn * rotation;
  turned.offset = turn * offset;
  turned.offset += shift;
  return turned;
}

Eigen::Matrix4d CamFromModel(const Rigid3& cam_from_tag, const ModelPlacement& placement) {
  return cam_from_tag.Matrix() * placement.TagFromModel();
}

}  // namespace reconar
