#pragma once
// Registration of an image by the tags the model already holds: the path the mapper takes when an
// image with tags (MapperImage::tags) fails the ordinary registration (image_registration.h), e.g.
// a photo of a white wall whose few SIFT matches are far below MapperOptions::registration_min_inliers.
//
// A tag is known to the model when its corners are there: the points of its corner tracks, a
// fourth corner completing the parallelogram of three, or, for a tag only one registered image
// sees (no track triangulated yet), the tag's pose in that image (P3P on its four corners, scaled
// by the edge of the tags the model holds in full: all tags of a project share one size). A tag of
// known size fixes a pose on its own, up to the planar flip of a small tag; so the image needs
// every corner of every known tag it sees within MapperOptions::registration_max_error_px of the
// pose, their root mean square error at most registration_max_tag_rms_px, and at least two such
// tags, or one and registration_min_tag_point_inliers other inliers.
// A known tag that does not fit the pose refuses it (a wrongly placed tag or a wrong pose).
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

struct KnownTag {
  int tag_id = -1;
  int first_keypoint = -1;                       // the image's keypoint of corner 0
  std::array<Eigen::Vector3d, 4> corners;        // model frame
  std::array<int, 4> points = {-1, -1, -1, -1};  // each corner's model point; -1 when derived
};

// The tags `image` sees whose four corners the model holds (see above), in the order of
// images[image].tags. Tags whose keypoints lie outside the image's keypoints are skipped.
std::vector<KnownTag> KnownTags(const MapperModel& model, const std::vector<MapperImage>& images, int image,
                                const MapperOptions& options);

// Whether `known_tags` and `other_points` further 2D-3D correspondences can meet the tag rule.
bool TagsCanRegister(int known_tags, int other_points, const MapperOptions& options);

// Registers `image` by its known tags and its other 2D-3D correspondences. Needs the image's
// camera focal confirmed (three registered images, or MapperOptions::refine_focal off). False,
// with the reason in *reason, when no pose meets the tag rule.
bool RegisterImageByTags(MapperModel* model, const std::vector<MapperImage>& images, int image,
                         const MapperOptions& options, std::string* reason);

}  // namespace reconar
