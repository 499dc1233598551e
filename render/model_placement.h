#pragma once
// ModelPlacement: where a reconstructed model sits on a tag, as the similarity tag_from_model
// X_tag = scale * rotation * X_model + offset (the model's units become metres in the tag frame).
// cam_from_model = cam_from_tag * tag_from_model.
// Tag frame (shared with tracker and tools): origin at the tag centre, x right, y up, z out of the
// printed tag toward the viewer; the tag's corners are (+-s/2, +-s/2, 0).
#include <Eigen/Core>

#include "core/base/status.h"
#include "core/math/rigid3.h"
#include "core/mesh/mesh.h"

namespace reconar {

struct ModelPlacement {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // metres, in the tag frame

  // 4x4 homogeneous tag_from_model.
  Eigen::Matrix4d TagFromModel() const;

  // The model standing on the tag: its `model_up` axis along the tag's z, uniformly scaled so its
  // extent along that axis is `height_m`, the centre of its bounding box (in the tag's x-y) over
  // the tag centre and its lowest point on the tag plane. The same mesh at height 0.1 is cup-sized,
  // at 1.7 human-sized. InvalidArgument for an empty mesh, a flat one (no extent along model_up),
  // a zero model_up or a height that is not positive.
  static Result<ModelPlacement> StandingOnTag(const Mesh& mesh, double height_m,
                                              const Eigen::Vector3d& model_up = Eigen::Vector3d::UnitY());
  // A fixed scale (model units to metres, 1 for a metric model) with the model's `model_up` axis
  // along the tag's z, the model's origin on the tag centre.
  static ModelPlacement Scaled(double scale, const Eigen::Vector3d& model_up = Eigen::Vector3d::UnitY());

  // This placement turned by `degrees` about the tag's z axis (its offset with it), then moved by
  // `shift` (metres, in the tag frame).
  ModelPlacement Turned(double degrees, const Eigen::Vector3d& shift = Eigen::Vector3d::Zero()) const;
};

// cam_from_tag * tag_from_model as a 4x4 similarity.
Eigen::Matrix4d CamFromModel(const Rigid3& cam_from_tag, const ModelPlacement& placement);

}  // namespace reconar
