#pragma once
// Patch: PMVS's surface element (Furukawa & Ponce 2010, sec. 2.1): a small plane with centre c and
// unit normal n (towards its reference camera R), seen by the images T(p) whose NCC with R passes
// the photometric threshold. Stored in floats; ~40 bytes plus the image list.
#include <Eigen/Core>
#include <vector>

namespace reconar {

struct Patch {
  Eigen::Vector3f center = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  int reference = -1;       // R(p): index into the views
  float score = 0.0f;       // mean NCC with R over the other images of `images`
  std::vector<int> images;  // T(p): the reference first, then the supporting images
};

}  // namespace reconar
