#pragma once
// Registrations on weak evidence are provisional. A pose from fewer inliers than
// MapperOptions::registration_min_inliers (image_registration.h), or from a registered neighbour's
// two-view geometry and a few points (neighbour_registration.h), registers only when it is
// verified at once: its inliers are at least half of the image's 2D-3D correspondences and spread
// over the image, and its matches to registered images on tracks without a point lie on their
// epipolar lines. It stays only while the adjusted model still holds it: after every global
// adjustment the pose is checked again by the same rule (but the epipolar test), against the points that other views
// determine (seen by at least two other registered images, so that the points it made itself do
// not vouch for it), and an image that fails is taken out again with the reason.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/math/rigid3.h"
#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

// How a provisional image was registered: the rule it must keep meeting.
enum class WeakEvidence {
  kFewInliers,  // an absolute pose from registration_min_verified_inliers or more inliers
  kNeighbour,   // a neighbour's two-view geometry and registration_min_baseline_points points
};

struct ProvisionalImage {
  int image = -1;
  WeakEvidence evidence = WeakEvidence::kFewInliers;
  int inliers = 0;        // at registration
  int registered_at = 0;  // images registered, this one included, when it registered
};

// A pose of `image` and what supports it.
struct WeakPose {
  Rigid3 cam_from_world;
  double focal = 0.0;                             // the focal the pose was found with
  int num_correspondences = 0;                    // the image's 2D-3D correspondences
  std::vector<Eigen::Vector2d> inlier_pixels;     // the inliers among them
};

// The share of the image the inliers span: the geometric mean of their extents along their two
// principal axes (each between the 10th and 90th percentiles), over the image's shorter side.
// Points in a small patch or along a line fix a pose poorly; a band across the image is fine.
double InlierSpread(const std::vector<Eigen::Vector2d>& pixels, int width, int height);

// Empty when `pose` meets the rule of `evidence` for `image` (the header's rule; the inlier
// bound is registration_min_verified_inliers for kFewInliers, registration_min_baseline_points
// for kNeighbour), otherwise why not. With check_two_view, the matches on tracks without a point
// must lie on their epipolar lines too: at registration they are the image's new tracks; once the
// image is in the model, the consistent ones have become points and the rest are a biased sample.
std::string CheckWeakPose(const MapperModel& model, int image, WeakEvidence evidence, const WeakPose& pose,
                          const MapperOptions& options, bool check_two_view = true);

// The provisional image's pose as the adjusted model has it, against the points other views
// determine, checked by CheckWeakPose; empty when it still holds.
std::string ReviewProvisionalImage(const MapperModel& model, const ProvisionalImage& provisional,
                                   const MapperOptions& options);

// Takes a registered image out of the model: its observations are removed, and a point left with
// fewer than two views, or under the triangulation angle, is deleted.
void DeregisterImage(MapperModel* model, int image, const MapperOptions& options);

}  // namespace reconar
