#pragma once
// A check of a candidate pose against the view graph: the image's matches to registered images on
// tracks that have no point yet must lie near their epipolar lines under the pose. Registrations
// that rest on few 2D-3D correspondences (by tags, tag_image_registration.h; from few points or a
// neighbour's two-view geometry, image_registration.h, neighbour_registration.h) use it to tell a
// right pose from one that merely fits a handful of points.
#include <Eigen/Core>
#include <vector>

#include "core/math/rigid3.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

struct TwoViewMatch {
  Eigen::Vector2d here, there;  // undistorted normalised coordinates in the image and the other
  int image = -1;               // the other, registered image
};

// At most this many two-view matches are gathered.
constexpr size_t kMaxTwoViewMatches = 2000;

// The matches of `image`'s keypoints (those with skip_keypoint[kp] == 0, when given) to registered
// images, on tracks without a point.
std::vector<TwoViewMatch> GatherTwoViewMatches(const MapperModel& model, int image,
                                               const std::vector<char>* skip_keypoint = nullptr);

// How many of `matches` lie within bound_px (at `focal`) of their epipolar line, by the Sampson
// distance under the essential matrix between cam_from_world and each other image's pose.
int CountEpipolarConsistent(const MapperModel& model, const std::vector<TwoViewMatch>& matches,
                            const Rigid3& cam_from_world, double focal, double bound_px);

}  // namespace reconar
