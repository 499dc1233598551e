#pragma once
// The covariance of a project's sparse model as its last global adjustment left it
// (core/optim/adjustment_covariance.h), read from the project alone, with no adjustment re-run:
// the model (sparse/, in the world frame), each observation weighted as the mapper weighted it
// (SIFT keypoints by their detection scale from the feature files; tag corners, the keypoints past
// the feature file's count, by kTagCornerWeight), every registered image's pose free, the
// intrinsics shared per camera with the focal free and the distortion and principal point free as
// sparse/report.json says the final adjustment had them.
#include <map>
#include <utility>
#include <vector>

#include "core/base/status.h"
#include "core/optim/adjustment_covariance.h"
#include "core/pipeline/project.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

// A tag corner in the registered photos.
struct TagCornerInModel {
  int point = -1;  // the covariance's point of the adjusted track that holds it; -1: none
  std::vector<BalObservation> observations;  // in the registered photos that saw it (point unset)
};

struct ProjectCovariance {
  Reconstruction model;
  AdjustmentCovariance covariance;
  std::vector<int> problem_camera;  // per model image: its camera in the covariance, -1 if not registered
  std::vector<int> problem_point;   // per model point: its point in the covariance, -1 if deleted
  std::map<std::pair<int, int>, TagCornerInModel> tag_corners;  // by (tag id, corner 0..3)
  int observations = 0, tag_corner_observations = 0;
  bool distortion_free = false, principal_point_free = false;
};

// NotFound / CorruptData naming the file for a project without a readable sparse model or feature
// files; FailedPrecondition when the model leaves no redundancy.
Result<ProjectCovariance> ComputeProjectCovariance(const Project& project);

}  // namespace reconar
